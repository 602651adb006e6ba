"""The compiled solver kernels behind one interface: solve_interval, pgs_block, dense_to_blocks."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings

from nonsmooth_rod.solvers import kernels
from nonsmooth_rod.solvers._common import interpreted
from nonsmooth_rod.solvers.kernels import (
    KERNEL_NONFINITE,
    KERNEL_SOLVED,
    KERNEL_TOO_LARGE,
    SOLVER_ENUM,
    SOLVER_LEMKE,
    SOLVER_PGS,
    dense_to_blocks,
    pgs_block,
    solve_interval,
    solve_interval_into,
    solver_floats,
    solver_ints,
)
from nonsmooth_rod.solvers.lemke import HAVE_NUMBA, lemke_friction
from nonsmooth_rod.solvers.problem import PlanarFrictionProblem, complementarity_residual, residual_scale
from solver_cases import block_on_incline, friction_steps, random_step

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

SOLVER_CODES = [SOLVER_LEMKE, SOLVER_PGS, SOLVER_ENUM]


def run(code, problem, rtol=0.0, max_iter=0, kernel=solve_interval):
    p = np.zeros_like(problem.q)
    u = np.zeros_like(problem.q)
    status, iterations, residual = kernel(code, problem.W, problem.q, problem.lo, problem.hi, p, u,
                                          rtol, max_iter)
    return int(status), int(iterations), float(residual), p, u


@pytest.mark.parametrize("code", SOLVER_CODES)
@settings(max_examples=60, deadline=None, derandomize=True)
@given(problem=friction_steps())
def test_every_kernel_solves_the_step_law(code, problem):
    status, iterations, residual, p, u = run(code, problem, max_iter=20000)
    if code == SOLVER_PGS and status != KERNEL_SOLVED:
        return  # NSGS has no convergence guarantee with friction (wedged contacts)
    assert status == KERNEL_SOLVED
    scale = residual_scale(problem, p, u)
    np.testing.assert_allclose(u, problem.W @ p + problem.q, rtol=0, atol=1e-13 * scale)
    assert residual == pytest.approx(complementarity_residual(problem, p), abs=1e-13 * scale)
    assert residual <= kernels.DEFAULT_RTOL * scale


@settings(max_examples=60, deadline=None, derandomize=True)
@given(problem=friction_steps())
def test_lemke_kernel_is_lemke_friction(problem):
    status, pivots, residual, p, u = run(SOLVER_LEMKE, problem)
    reference = lemke_friction(problem)
    assert status == KERNEL_SOLVED
    if pivots == 0 and reference.iterations > 0:
        # the warm start p = 0 (every contact open) answered: u = q solves the law within its acceptance
        assert np.all(p == 0.0) and residual <= kernels.DEFAULT_RTOL * residual_scale(problem, p, u)
        return
    assert pivots == reference.iterations
    # the same pivots; compiled and interpreted arithmetic may differ by FMA and summation order
    scale = residual_scale(problem, reference.p, reference.u)
    np.testing.assert_allclose(p, reference.p, rtol=0, atol=500 * np.finfo(float).eps * scale)


@pytest.mark.parametrize("code", SOLVER_CODES)
@pytest.mark.parametrize("argument", ["W", "q", "lo", "hi"])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_data_return_kernel_nonfinite(code, argument, bad):
    problem = block_on_incline(0.3, 0.5)
    data = {name: getattr(problem, name).copy() for name in ("W", "q", "lo", "hi")}
    data[argument].flat[1] = bad
    p, u = np.ones(4), np.zeros(4)
    status, iterations, residual = solve_interval(code, data["W"], data["q"], data["lo"], data["hi"], p, u,
                                                  0.0, 0)
    assert status == KERNEL_NONFINITE and iterations == 0
    assert np.all(p == 0.0)
    np.testing.assert_array_equal(u, data["q"])


def test_enum_beyond_its_limit_is_too_large():
    n = 10  # 5 contacts
    problem = PlanarFrictionProblem(np.eye(n), -np.ones(n), -np.ones(5), np.ones(5))
    assert run(SOLVER_ENUM, problem)[0] == KERNEL_TOO_LARGE
    # the same problem is fine for the other kernels: p = −q sticks every contact
    for code in (SOLVER_LEMKE, SOLVER_PGS):
        status, _, _, p, _ = run(code, problem)
        assert status == KERNEL_SOLVED and np.allclose(p, np.ones(n), rtol=1e-14)


def test_pgs_warm_start_from_the_solution_takes_one_sweep():
    problem = block_on_incline(0.3, 0.5)
    status, sweeps, _, p, u = run(SOLVER_PGS, problem)
    assert status == KERNEL_SOLVED and sweeps > 1
    status, sweeps, _ = solve_interval(SOLVER_PGS, problem.W, problem.q, problem.lo, problem.hi, p, u, 0.0, 0)
    assert status == KERNEL_SOLVED and sweeps == 1


def test_dense_to_blocks_round_trip_and_sparsity():
    rng = np.random.default_rng(3)
    W = rng.normal(size=(8, 8))
    W[0:2, 4:6] = 0.0  # contact 0 does not see contact 2
    W[6:8, 6:8] = 0.0  # a zero diagonal block is still stored
    indptr, indices, blocks = dense_to_blocks(W)
    assert indptr.tolist() == [0, 3, 7, 11, 15] and indices[:3].tolist() == [0, 1, 3]
    rebuilt = np.zeros_like(W)
    for i in range(4):
        for k in range(indptr[i], indptr[i + 1]):
            j = indices[k]
            rebuilt[2 * i:2 * i + 2, 2 * j:2 * j + 2] = blocks[k]
    np.testing.assert_array_equal(rebuilt, W)


def test_pgs_block_equals_pgs_on_the_dense_matrix():
    problem = random_step(np.random.default_rng(8), 2, kind="disk", mu_max=0.5)
    status_dense, sweeps_dense, _, p_dense, _ = run(SOLVER_PGS, problem)
    p, u = np.zeros(4), np.zeros(4)
    status, sweeps, _ = pgs_block(*dense_to_blocks(problem.W), problem.q, problem.lo, problem.hi, p, u, 0.0, 0)
    assert status == status_dense == KERNEL_SOLVED and sweeps == sweeps_dense
    scale = residual_scale(problem, p_dense, u)  # the same sweeps over differently stored blocks
    np.testing.assert_allclose(p, p_dense, rtol=0, atol=500 * np.finfo(float).eps * scale)


@pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed: only the interpreted kernels exist")
@pytest.mark.parametrize("code", SOLVER_CODES)
def test_compiled_and_interpreted_kernels_agree(code):
    """Same source both ways: the same status and iterations, p to a few hundred ulps."""
    rng = np.random.default_rng(11)
    into = interpreted(solve_interval_into)  # (solve_interval runs the compiled one, its scratch made in Python)

    def python_kernel(code, W, q, lo, hi, p, u, rtol, max_iter):
        n = lo.shape[0]
        return into(code, W, q, lo, hi, p, u, rtol, max_iter, np.empty(solver_floats(n)),
                    np.empty(solver_ints(n), dtype=np.int64))
    for k in range(20):
        problem = random_step(rng, 1 + k % 2, kind=("disk", "corner")[k % 2])
        compiled = run(code, problem)
        python = run(code, problem, kernel=python_kernel)
        assert compiled[:2] == python[:2]
        scale = residual_scale(problem, compiled[3], compiled[4])
        np.testing.assert_allclose(python[3], compiled[3], rtol=0, atol=500 * np.finfo(float).eps * scale)
