"""The compiled Moreau–Jean loop is the general one, step for step."""
import math

import numpy as np
import pytest

from nonsmooth_rod.integrators import fast_moreau_jean
from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.rod.problem import RodProblem

from test_moreau_jean import _block_on_incline

pytestmark = pytest.mark.skipif(not fast_moreau_jean.AVAILABLE, reason="numba not installed")


def _both(scene, q0, v0, t_end, **options):
    fast = MoreauJean(MoreauJeanOptions(fast=True, **options)).run(scene, q0, v0, t_end)
    slow = MoreauJean(MoreauJeanOptions(fast=False, **options)).run(scene, q0, v0, t_end)
    assert fast.stats["compiled"] and not slow.stats["compiled"]
    return fast, slow


def _assert_same(fast, slow):
    assert fast.status == slow.status and fast.steps == slow.steps
    assert np.max(np.abs(fast.trajectory.q - slow.trajectory.q)) < 1e-13
    assert np.max(np.abs(fast.trajectory.v - slow.trajectory.v)) < 1e-11
    assert (fast.trajectory.modes == slow.trajectory.modes).all()
    assert [i.contact for i in fast.impacts] == [i.contact for i in slow.impacts]
    for a, b in zip(fast.impacts, slow.impacts):
        assert a.t == pytest.approx(b.t, abs=1e-14)


@pytest.mark.parametrize("case", [1, 2, 3])
def test_rod_cases_through_the_impact(case):
    p = RodProblem.paper(case, restitution=0.2)
    q0, v0 = p.initial_state()
    _assert_same(*_both(p.scene(), q0, v0, 0.6, h=5e-4))


def test_block_with_two_corners_stopping_on_an_incline():
    scene, q0, t_dir, _ = _block_on_incline(math.radians(25.0), 0.5, 0.3)
    _assert_same(*_both(scene, q0, np.r_[t_dir, 0.0], 0.4, h=1.3e-3))


def test_ineligible_scenes_take_the_general_path():
    p = RodProblem.paper(2)
    assert fast_moreau_jean.eligible(p.scene(), "lemke")
    assert not fast_moreau_jean.eligible(p.scene(), "pgs")
    scene = p.scene()
    scene.applied_force = lambda t, q, v: np.zeros(3)
    assert not fast_moreau_jean.eligible(scene, "lemke")
