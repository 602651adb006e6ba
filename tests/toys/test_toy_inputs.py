"""Bad toy parameters end in one-line InputErrors, not in a run of nonsense."""
import math

import pytest

from nonsmooth_rod import toys
from nonsmooth_rod.toys import stacks
from nonsmooth_rod.validation import InputError

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

BAD = [
    (lambda: toys.BouncingBall(restitution=1.0), "restitution"),  # e = 1 never comes to rest
    (lambda: toys.BlockOnIncline(mu_s=0.2, mu_d=0.3), "mu_d = 0.3 exceeds mu_s = 0.2"),
    (lambda: toys.BlockOnIncline(v0=-1.0), "v0"),
    (lambda: toys.DiskOnIncline(angle=math.pi / 2), "incline angle"),
    (lambda: toys.BeltOscillator(mu_s=0.4, mu_d=0.4), "mu_s > mu_d"),
    (lambda: toys.RockingBlock(tilt=math.radians(30.0)), "tilt"),  # beyond α = 18.4°: it topples
    (lambda: toys.BallRow(masses=(1.0,), radii=(0.1,), gaps=(), velocities=(1.0,)), "n ≥ 2"),
    (lambda: toys.BallRow(gaps=(-0.1,)), "non-negative"),
    (lambda: toys.BallRow.cradle(4).simultaneous_outcome(), "three equal balls"),
    (lambda: toys.run(toys.BouncingBall(), "runge-kutta"), "unknown method"),
    (lambda: stacks.ball_row(0), "n (balls) must be a whole number ≥ 1"),
    (lambda: stacks.ball_row(2.5), "n (balls)"),
    (lambda: stacks.ball_row(3, radius=-0.05), "radius"),
    (lambda: stacks.disk_pile(0), "rows must be a whole number ≥ 1"),
    (lambda: stacks.disk_pile(3, mass=float("nan")), "mass"),
]


@pytest.mark.parametrize("make, words", BAD)
def test_bad_input_is_one_line_error(make, words):
    with pytest.raises(InputError) as info:
        make()
    message = str(info.value)
    assert words in message and "\n" not in message
