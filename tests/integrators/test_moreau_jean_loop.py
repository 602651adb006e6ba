"""The compiled loop's per-run scratch: a pgs step allocates nothing, and a dense W larger than the
scratch is grown between steps (moreau_jean_loop.step_scratch, RUN_SCRATCH_SHORT); the rest check
reads every contact's memory."""
import numpy as np
import pytest

from nonsmooth_rod import _jit
from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.integrators.moreau_jean_loop import SCRATCH_W_CONTACTS
from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.toys import stacks

G = 9.81


def test_a_row_at_rest_beyond_the_dense_scratch_holds_with_lemke():
    """70 balls apart on the floor (70 active contacts: more than the dense W's scratch holds) stay
    at rest, each floor contact carrying its ball's weight m g, no friction."""
    n = 70
    assert n > SCRATCH_W_CONTACTS
    scene, q0, v0 = stacks.ball_row(n, speed=0.0)
    h, steps = 1e-3, 5
    run = MoreauJean(MoreauJeanOptions(h=h, solver="lemke", repeat_rest=False)).run(scene, q0, v0, h * steps)
    assert run.status == "ok" and run.steps == steps, run.message
    assert np.max(np.abs(run.trajectory.q - q0)) <= 1e-15
    floor = [scene.contacts.index(c) for c in scene.contacts if c.name.startswith("floor")]
    weight = stacks.BALL_MASS * G
    assert run.trajectory.normal_force.shape[0] == steps + 1  # the start, then each step's force
    assert np.allclose(run.trajectory.normal_force[1:, floor], weight, rtol=1e-12, atol=0.0)
    assert np.max(np.abs(run.trajectory.tangential_force[1:])) <= 1e-12 * weight


def _rod():
    rod = RodProblem.paper(2)
    return (rod.scene(), *rod.initial_state()), 1e-4, 1500  # through ball A's impact


def _resting_row():
    return stacks.ball_row(8, speed=0.0), 1e-3, 100  # 8 loaded floor contacts, 7 pairs apart


def _resting_pile():
    """The 4-row pile at rest: pgs leaves some of its statically indeterminate contacts unloaded
    ("open", touching); the hold search, which they once started every step (26 allocations a
    step), has nothing to decide there (two_coefficient.hold_decision_pending)."""
    return stacks.disk_pile(4), 1e-3, 100


@pytest.mark.skipif(not _jit.ENABLED, reason="numba's allocation counters: the compiled loop")
@pytest.mark.parametrize("case", [_rod, _resting_row, _resting_pile])
def test_a_pgs_step_allocates_nothing(case):
    """A run of 2n pgs steps allocates exactly what a run of n steps does — the per-run scratch
    and records, nothing per step — where neither the hold search nor pgs's mode polish runs (they
    allocate, docs/solvers.md): the paper's rod, a row of balls at rest, a pile at rest."""
    from numba.core.runtime import _nrt_python as nrt_stats, rtsys

    (scene, q0, v0), h, steps = case()
    solver = MoreauJean(MoreauJeanOptions(h=h, solver="pgs", repeat_rest=False))
    assert solver.run(scene, q0, v0, h * steps).stats["compiled"]  # compiled, warm
    nrt_stats.memsys_enable_stats()
    try:
        counts = []
        for n in (steps, 2 * steps):
            before = rtsys.get_allocation_stats().alloc
            run = solver.run(scene, q0, v0, h * n)
            assert run.status == "ok" and run.steps == n
            counts.append(rtsys.get_allocation_stats().alloc - before)
    finally:
        nrt_stats.memsys_disable_stats()
    assert counts[0] == counts[1], counts


def test_a_rest_is_not_repeated_while_a_contact_without_a_record_column_changes_its_memory():
    """The rest check (_fixed_period) compares every contact's memory (closed, grazing, slip sign),
    not only the contacts with a column of the records (fewer than the contacts: new_records):
    a state the step leaves unchanged but for one contact's memory is not a rest."""
    from nonsmooth_rod.integrators.moreau_jean_loop import _fixed_period

    k, n_contacts, columns = 5, 6, 2
    q, v = np.ones((k + 2, 3)), np.zeros((k + 2, 3))
    p_normal, p_tangent = np.full((k + 1, columns), 0.5), np.zeros((k + 1, columns))
    memory = np.zeros((3, 3, n_contacts))
    assert _fixed_period(k, k, q, v, p_normal, p_tangent, memory) == 1  # a rest: everything repeats
    memory[k % 3, 1, n_contacts - 1] = 1.0  # the last contact starts grazing at step k
    assert _fixed_period(k, k, q, v, p_normal, p_tangent, memory) == 0
