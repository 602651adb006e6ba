"""Nonsmooth Gauss–Seidel: tolerance, warm start, iteration limit, exact local solves."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings

from nonsmooth_rod.solvers.gauss_seidel import projected_gauss_seidel, solve_contact
from nonsmooth_rod.solvers.problem import (
    NoConvergence,
    PlanarFrictionProblem,
    complementarity_residual,
    residual_scale,
)
from solver_cases import block_on_incline, friction_steps


@settings(max_examples=150, deadline=None, derandomize=True)
@given(problem=friction_steps(n_contacts=1))
def test_one_contact_is_exact_after_one_sweep(problem):
    solution = projected_gauss_seidel(problem)
    assert solution.iterations == 1
    assert solution.residual <= 1e-12 * residual_scale(problem, solution.p, solution.u)


@settings(max_examples=100, deadline=None, derandomize=True)
@given(problem=friction_steps(n_contacts=2))
def test_two_contacts_within_tolerance(problem):
    tol = 1e-10
    try:
        solution = projected_gauss_seidel(problem, tol=tol, max_iter=20000)
    except NoConvergence as error:  # NSGS has no convergence guarantee with friction
        assert "pgs: no convergence after 20000 sweeps, residual" in str(error)
        return
    scale = residual_scale(problem, solution.p, solution.u)
    assert complementarity_residual(problem, solution.p) <= tol * scale
    # same formula, evaluated in float loops: equal up to round-off of W p
    assert solution.residual == pytest.approx(complementarity_residual(problem, solution.p), abs=1e-12 * scale)


def test_singular_block_converges_and_warm_start_finishes_at_once():
    problem = block_on_incline(0.3, 0.5)
    solution = projected_gauss_seidel(problem)
    assert solution.info["states"] == ["stick", "stick"]
    assert solution.residual <= 1e-12 * residual_scale(problem, solution.p, solution.u)
    warm = projected_gauss_seidel(problem, p0=solution.p)
    assert warm.iterations == 1


def test_iteration_limit_raises_with_sweeps_and_residual():
    problem = block_on_incline(0.3, 0.5)
    with pytest.raises(NoConvergence, match=r"pgs: no convergence after 2 sweeps, residual \d\.\d{3}e[-+]\d+ > tol"):
        projected_gauss_seidel(problem, max_iter=2)


def test_warm_start_size_is_checked():
    with pytest.raises(ValueError, match="warm start has 3 entries"):
        projected_gauss_seidel(block_on_incline(0.3, 0.5), p0=[0.0, 0.0, 0.0])


def test_local_solver_cases():
    a, b, c = 2.0, 0.5, 3.0
    assert solve_contact(a, b, c, 1.0, -5.0, -0.5, 0.5) == (0.0, 0.0)  # separating: open
    p_n, p_t = solve_contact(a, b, c, -1.0, 0.1, -0.5, 0.5)  # sticks
    assert np.allclose(np.array([[a, b], [b, c]]) @ [p_n, p_t] + [-1.0, 0.1], 0.0)
    p_n, p_t = solve_contact(a, b, c, -1.0, 5.0, -0.5, 0.5)  # slides forward: p_T = lo·p_N
    assert p_t == pytest.approx(-0.5 * p_n) and a * p_n + b * p_t - 1.0 == pytest.approx(0.0)
    assert (b * p_n + c * p_t + 5.0) > 0.0


def test_local_solver_with_rank_one_block():
    # W_ii = g gᵀ, g = (1, 1): the stick system is singular; the slip cases still solve it
    a = b = c = 1.0
    p_n, p_t = solve_contact(a, b, c, -1.0, -1.0, -0.5, 0.5)
    u = np.array([[a, b], [b, c]]) @ [p_n, p_t] + [-1.0, -1.0]
    problem = PlanarFrictionProblem(np.ones((2, 2)), [-1.0, -1.0], [-0.5], [0.5])
    assert complementarity_residual(problem, [p_n, p_t]) <= 1e-15
    assert u[0] == pytest.approx(0.0, abs=1e-15)
