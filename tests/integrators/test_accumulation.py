"""integrators/accumulation.py: the one rule that says which impacts of an accumulation are
resolved, against the bouncing ball's closed forms (apex heights h0 e^2k, accumulation time
t_1 (1 + e)/(1 − e)) for the event-driven reference, the hybrid method and Moreau–Jean alike."""
import math

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod import toys
from nonsmooth_rod.integrators import accumulation
from nonsmooth_rod.validation import InputError

BALL = toys.BouncingBall(drop_height=1.0, restitution=0.5)
RESOLUTION = 1e-6  # m


def _resolved_count(ball, resolution) -> int:
    """Impacts whose flight rose above the resolution: impact k ends the fall from apex k − 1."""
    return sum(1 for k in range(200) if ball.apex_height(k) > resolution)


def test_the_floor_is_the_speed_of_a_fall_from_the_resolution():
    q0, _ = BALL.initial_state()
    floor = accumulation.speed_floor(BALL.scene(), 0.0, q0, RESOLUTION)
    assert floor == pytest.approx(math.sqrt(2 * BALL.g * RESOLUTION), rel=1e-12)
    assert accumulation.speed_floor(BALL.scene(), 0.0, q0, 0.0) == 0.0
    assert accumulation.resolved(floor * 1.001, floor) and not accumulation.resolved(floor * 0.999, floor)


@pytest.mark.parametrize("method, options", [("event-driven", {}), ("hybrid", {"h": 1e-2})])
def test_the_reference_sums_the_unresolved_impacts_to_the_accumulation_time(method, options):
    q0, v0 = BALL.initial_state()
    run = nr.simulate(BALL.scene(), q0, v0, 2.0, method, resolution=RESOLUTION, **options)
    assert run.status == "ok", run.message  # past the accumulation (without resolution: a "zeno" stop)
    n = _resolved_count(BALL, RESOLUTION)
    assert n == 10 and len(run.impacts) == n
    np.testing.assert_allclose([imp.t for imp in run.impacts], BALL.impact_times(n), rtol=0, atol=1e-8)
    (acc,) = [e for e in run.events if e.kind == "accumulation"]
    assert abs(acc.t - BALL.zeno_time) <= 1e-8  # the geometric series is exact for the ball
    after = run.trajectory.t > acc.t
    assert after.any() and np.all(run.trajectory.v[after] == 0.0)
    assert np.all(np.abs(run.trajectory.q[after, 1] - BALL.radius) <= 1e-12)


def test_moreau_jean_reports_the_same_impacts():
    q0, v0 = BALL.initial_state()
    run = nr.simulate(BALL.scene(), q0, v0, BALL.zeno_time + 0.1, "moreau-jean", h=1e-4, resolution=RESOLUTION)
    plain = nr.simulate(BALL.scene(), q0, v0, BALL.zeno_time + 0.1, "moreau-jean", h=1e-4)
    n = _resolved_count(BALL, RESOLUTION)
    assert len(run.impacts) == n < len(plain.impacts)
    assert run.stats["unresolved_impacts"] == len(plain.impacts) - n
    # the same impacts, each within its steps' first-order error (measured ≤ 5e-4 s: it grows hop by hop)
    np.testing.assert_allclose([imp.t for imp in run.impacts], BALL.impact_times(n), rtol=0, atol=1e-3)


def test_a_negative_resolution_is_refused():
    q0, v0 = BALL.initial_state()
    with pytest.raises(InputError, match="resolution"):
        nr.simulate(BALL.scene(), q0, v0, 1.0, "event-driven", resolution=-1.0)
