"""Mode enumeration, checked against Lemke."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings

from nonsmooth_rod.solvers.enumeration import enumerate_modes, mode_solutions
from nonsmooth_rod.solvers.lemke import lemke_friction
from nonsmooth_rod.solvers.problem import (
    InfeasibleProblem,
    PlanarFrictionProblem,
    complementarity_residual,
    residual_scale,
)
from solver_cases import block_on_incline, friction_steps

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)


def close(a, b, rtol=1e-8):
    return np.abs(a - b).max() <= rtol * max(1.0, np.abs(a).max(), np.abs(b).max())


@settings(max_examples=200, deadline=None, derandomize=True)
@given(problem=friction_steps())
def test_enum_satisfies_law_and_agrees_with_lemke(problem):
    solution = enumerate_modes(problem)
    scale = residual_scale(problem, solution.p, solution.u)
    assert complementarity_residual(problem, solution.p) <= 1e-10 * scale
    reference = lemke_friction(problem)
    candidates = mode_solutions(problem)
    distinct_u = [u for _, _, u in candidates if not close(u, candidates[0][2])]
    if not distinct_u:  # velocities unique (among all mode solutions): Lemke must find them
        assert close(solution.u, reference.u)
        distinct_p = [p for _, p, _ in candidates if not close(p, candidates[0][1])]
        singular = np.linalg.matrix_rank(problem.W) < problem.W.shape[0]
        if not distinct_p and not singular:  # impulses unique too
            assert close(solution.p, reference.p)
    else:  # Coulomb friction may have several solutions; Lemke's must be one of them
        assert any(close(reference.u, u) for _, _, u in candidates)


def test_statically_indeterminate_block_gets_least_norm_split():
    problem = block_on_incline(0.3, 0.5)
    solution = enumerate_modes(problem)
    assert solution.info["states"] == ["stick", "stick"]
    scale = residual_scale(problem, solution.p, problem.W @ solution.p + problem.q)
    assert complementarity_residual(problem, solution.p) <= 500 * np.finfo(float).eps * scale
    # least norm: the indeterminate internal force (equal and opposite p_T) is zero, so
    # the tangential impulses are equal
    assert solution.tangential_impulse[0] == pytest.approx(solution.tangential_impulse[1], rel=1e-10)
    assert close(solution.u, lemke_friction(problem).u, rtol=1e-12)


def test_no_solution_raises_infeasible():
    # u_N = q_N < 0 whatever p: W has no normal coupling at all
    problem = PlanarFrictionProblem(np.diag([0.0, 1.0]), [-1.0, 0.0], [-0.5], [0.5])
    with pytest.raises(InfeasibleProblem, match="enum: none of the 4 mode combinations satisfies"):
        enumerate_modes(problem)


def test_too_many_contacts_rejected():
    problem = PlanarFrictionProblem(np.eye(10), np.ones(10), -np.ones(5), np.ones(5))
    with pytest.raises(ValueError, match="5 contacts exceed the enumeration limit of 4"):
        enumerate_modes(problem)
