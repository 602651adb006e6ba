"""A pgs step that Gauss–Seidel cannot finish is solved again by Lemke on the dense W.

Gauss–Seidel drifts along the null space of a singular W and can stall just above its
acceptance (a pile of disks: tens of coupled, statically indeterminate contacts). Such a step,
with at most MAX_LEMKE_FALLBACK contacts, is handed to Lemke; the run counts it in
stats["solver_fallbacks"] and goes on. A user who set pgs's own sweep limit or tolerance gets
pgs alone (its failure is reported: tests/integrators/test_solver_failure_report.py).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.solvers.delassus import dense_to_blocks
from nonsmooth_rod.solvers.kernels import KERNEL_NO_CONVERGENCE, KERNEL_SOLVED, pgs_block
from nonsmooth_rod.solvers.problem import PlanarFrictionProblem, complementarity_residual, residual_scale
from nonsmooth_rod.solvers.two_coefficient import MAX_DENSE_HOLD, MAX_LEMKE_FALLBACK, pgs_or_lemke
from nonsmooth_rod.toys.stacks import disk_pile
from solver_cases import block_on_incline
from scripts import load_script

ROOT = Path(__file__).resolve().parents[2]


def test_a_step_one_sweep_leaves_unsolved_is_solved_by_the_fallback():
    problem = block_on_incline(0.3, 0.5)  # two corners: W of rank 3
    indptr, indices, blocks = dense_to_blocks(problem.W)
    p, u = np.zeros(4), problem.q.copy()
    assert pgs_block(indptr, indices, blocks, problem.q, problem.lo, problem.hi, p, u, 0.0, 1)[0] \
        == KERNEL_NO_CONVERGENCE
    p, u = np.zeros(4), problem.q.copy()
    status, iterations, residual, fell_back = pgs_or_lemke(indptr, indices, blocks, problem.q, problem.lo,
                                                           problem.hi, p, u, 0.0, 1, True)
    assert (status, fell_back) == (KERNEL_SOLVED, 1)
    # the sweep, and Lemke's pivots — none here: Lemke's warm start, the basis pgs's iterate sits at, already
    # solves the step (its answer is checked below as any other)
    assert iterations >= 1
    scale = residual_scale(problem, p, u)
    assert complementarity_residual(problem, p) <= 1e-12 * scale
    np.testing.assert_allclose(u, problem.W @ p + problem.q, rtol=0, atol=1e-13 * scale)


def test_a_step_of_more_than_64_contacts_falls_back_too():
    """40 blocks on inclines at once (80 contacts, beyond the hold search's 64): one sweep leaves
    them unsolved and Lemke on the whole dense W solves them (the heap of 50 boxes stopped on such
    a step, seed 1 at t = 0.261 s, while the fallback stopped at 64)."""
    from scipy.linalg import block_diag

    one = block_on_incline(0.3, 0.5)
    n = 40
    W, q = block_diag(*[one.W] * n), np.tile(one.q, n)
    lo, hi = np.tile(one.lo, n), np.tile(one.hi, n)
    assert MAX_DENSE_HOLD < 2 * n <= MAX_LEMKE_FALLBACK
    indptr, indices, blocks = dense_to_blocks(W)
    p, u = np.zeros(q.size), q.copy()
    status, _, _, fell_back = pgs_or_lemke(indptr, indices, blocks, q, lo, hi, p, u, 0.0, 1, True)
    assert (status, fell_back) == (KERNEL_SOLVED, 1)
    p_one, u_one = np.zeros(4), one.q.copy()
    pgs_or_lemke(*dense_to_blocks(one.W), one.q, one.lo, one.hi, p_one, u_one, 0.0, 1, True)
    scale = float(np.max(np.abs(np.r_[p, u, q])))
    np.testing.assert_allclose(p, np.tile(p_one, n), rtol=0, atol=1e-12 * scale)  # each block's own answer
    np.testing.assert_allclose(u, W @ p + q, rtol=0, atol=1e-13 * scale)


def test_a_converged_pgs_step_does_not_fall_back():
    problem = block_on_incline(0.3, 0.5)
    indptr, indices, blocks = dense_to_blocks(problem.W)
    p, u = np.zeros(4), problem.q.copy()
    status, _, _, fell_back = pgs_or_lemke(indptr, indices, blocks, problem.q, problem.lo, problem.hi, p, u, 0.0, 0,
                                           True)
    assert (status, fell_back) == (KERNEL_SOLVED, 0)
    # without the fallback (the user set pgs's own sweep limit or tolerance) the failure stands
    p, u = np.zeros(4), problem.q.copy()
    assert pgs_or_lemke(indptr, indices, blocks, problem.q, problem.lo, problem.hi, p, u, 0.0, 1, False)[::3] \
        == (KERNEL_NO_CONVERGENCE, 0)


@pytest.fixture(scope="module")
def pile_run():
    scene, q0, v0 = disk_pile(7, walls=False)  # 28 disks on a floor, no walls: it spreads
    run = MoreauJean(MoreauJeanOptions(h=1e-3, solver="pgs")).run(scene, q0, v0, 0.25)
    return scene, run


def test_the_pile_runs_with_pgs_through_its_stalled_steps(pile_run):
    scene, run = pile_run
    assert run.status == "ok", run.message
    # (with every pair declared and the mode polish, pgs now finishes the pile's steps itself:
    # the fallback is exercised by the two tests above)
    assert run.stats["compiled"]
    assert run.t[-1] == pytest.approx(0.25, rel=1e-12)


def test_the_pile_obeys_the_law_and_gains_no_more_energy_than_the_start_work(pile_run):
    scene, run = pile_run
    traj = run.trajectory
    N, T = traj.normal_force[1:], traj.tangential_force[1:]
    scale = np.max(N)
    assert np.all(N >= 0.0)
    mu_s = np.array([c.law.friction.mu_s for c in scene.contacts])
    assert np.all(np.abs(T) <= mu_s * N + 1e-9 * scale)
    # θ = ½, e = 0: a step gains at most the work of its impulses on its start velocity
    # (docs/friction.md, "Energy"), and the energy balance holds to round-off
    figures = _bench_energy().check(scene, run)
    assert figures["balance"] and figures["end"] and figures["bound"], figures
    radius = scene.contacts[0].radius
    assert np.min(traj.q[:, 1::3]) >= radius - 1e-6 * radius  # no disk through the floor


def _bench_energy():
    return load_script(ROOT / "benchmarks" / "bench_energy.py")
