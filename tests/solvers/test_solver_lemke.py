"""Lemke: general LCPs (P-matrices, ray, degenerate/cycling) and the friction-step LCP."""
from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from nonsmooth_rod.solvers import lemke as lemke_module
from nonsmooth_rod.solvers.lemke import HAVE_NUMBA, lemke, lemke_friction
from nonsmooth_rod.solvers.problem import (
    NoConvergence,
    PlanarFrictionProblem,
    RayTermination,
    complementarity_residual,
    residual_scale,
)
from solver_cases import block_on_incline, friction_steps, random_step

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

JIT_MODES = [False, True] if HAVE_NUMBA else [False]
TOL = 1e-10

finite = dict(allow_nan=False, allow_infinity=False, allow_subnormal=False)


def assert_lcp_solution(M, q, z, tol=TOL):
    """z ≥ 0, w = Mz + q ≥ 0 and z·w = 0, relative to the size of the data."""
    w = M @ z + q
    scale = max(1.0, np.abs(q).max(), np.abs(M).max() * np.abs(z).max())
    assert z.min() >= -tol * scale
    assert w.min() >= -tol * scale
    assert np.max(np.abs(z * w)) <= tol * scale * max(1.0, np.abs(z).max())


def brute_force_lcp(M, q):
    """All complementary bases (reference for tiny P-matrix LCPs, whose solution is unique)."""
    n = len(q)
    for support in itertools.product([False, True], repeat=n):
        idx = np.flatnonzero(support)
        z = np.zeros(n)
        if idx.size:
            z[idx] = np.linalg.solve(M[np.ix_(idx, idx)], -q[idx])
        w = M @ z + q
        slack = 1e-12 * (np.abs(q).max() + np.abs(M) @ np.abs(z))
        if np.all(z >= -slack) and np.all(w >= -slack):
            return z
    raise AssertionError("no complementary solution")


@st.composite
def p_matrix_lcps(draw):
    n = draw(st.integers(1, 6))
    q = draw(arrays(float, n, elements=st.floats(-10, 10, **finite)))
    if draw(st.booleans()):
        A = draw(arrays(float, (n, n), elements=st.floats(-3, 3, **finite)))
        M = A @ A.T + draw(st.floats(1e-3, 2.0)) * np.eye(n)
    else:  # row diagonally dominant, not symmetric
        M = draw(arrays(float, (n, n), elements=st.floats(-3, 3, **finite)))
        np.fill_diagonal(M, 0.0)
        M += np.diag(np.abs(M).sum(axis=1) + draw(st.floats(1e-2, 2.0)))
    return M, q


@pytest.mark.parametrize("jit", JIT_MODES)
@settings(max_examples=150, deadline=None, derandomize=True)
@given(lcp=p_matrix_lcps())
def test_p_matrix_lcp_solved_and_unique(jit, lcp):
    M, q = lcp
    z, pivots = lemke(M, q, jit=jit)
    assert_lcp_solution(M, q, z)
    if len(q) <= 4:
        assert np.allclose(z, brute_force_lcp(M, q), atol=1e-8 * max(1.0, np.abs(z).max()))


def test_nonnegative_q_is_solved_without_pivots():
    z, pivots = lemke(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([1.0, 0.0]))
    assert pivots == 0 and np.all(z == 0.0)


@pytest.mark.parametrize("jit", JIT_MODES)
def test_infeasible_lcp_ends_on_a_ray(jit):
    # w = −z − 1 < 0 for every z ≥ 0: provably infeasible.
    with pytest.raises(RayTermination, match=r"lemke: secondary ray after 1 pivots .*size 1"):
        lemke(np.array([[-1.0]]), np.array([-1.0]), jit=jit)
    # 2×2: w1 = −z1 + z2 − 1, w2 = z1 − z2 − 1 sum to −2 < 0, so w ≥ 0 is impossible.
    with pytest.raises(RayTermination, match="secondary ray"):
        lemke(np.array([[-1.0, 1.0], [1.0, -1.0]]), np.array([-1.0, -1.0]), jit=jit)


def test_pivot_limit_raises_no_convergence():
    M = np.array([[1.0, 2.0, 0.0], [0.0, 1.0, 2.0], [2.0, 0.0, 1.0]])
    with pytest.raises(NoConvergence, match="pivot limit 1 reached"):
        lemke(M, -np.ones(3), max_pivots=1)


def naive_lemke_cycles(M, q, max_pivots=100):
    """Lemke with the plain minimum-ratio rule, ties to the FIRST row: does it cycle?"""
    n = len(q)
    T = np.hstack([np.eye(n), -M, -np.ones((n, 1)), q[:, None]])
    basis = list(range(n))

    def pivot(r, e):
        T[r] /= T[r, e]
        for i in range(n):
            if i != r:
                T[i] -= T[i, e] * T[r]

    r = int(np.argmin(q))
    pivot(r, 2 * n)
    leaving, basis[r] = basis[r], 2 * n
    entering = leaving + n
    for _ in range(max_pivots):
        column = T[:, entering]
        rows = [i for i in range(n) if column[i] > 1e-12]
        ratios = [T[i, -1] / column[i] for i in rows]
        r = rows[int(np.argmin(ratios))]
        pivot(r, entering)
        leaving, basis[r] = basis[r], entering
        if leaving == 2 * n:
            return False
        entering = leaving + n if leaving < n else leaving - n
    return True


# Degenerate LCPs (ties in every ratio test) on which the plain rule cycles forever.
CYCLING_LCPS = [
    ([[1.0, -1.0, 2.0], [2.0, -2.0, 1.0], [-1.0, -2.0, 1.0]], [-1.0, -1.0, -1.0]),
    ([[0.0, 2.0, 2.0, -1.0], [2.0, -1.0, -2.0, 2.0], [-2.0, 0.0, -2.0, 2.0], [0.0, -2.0, -1.0, 1.0]],
     [-1.0, -1.0, -1.0, -1.0]),
    ([[1.0, 2.0, 0.0, 2.0], [2.0, 1.0, 1.0, -2.0], [0.0, 2.0, 1.0, -1.0], [-1.0, 0.0, -1.0, 0.0]],
     [-1.0, -1.0, -1.0, 0.0]),
]


@pytest.mark.parametrize("jit", JIT_MODES)
@pytest.mark.parametrize("M, q", CYCLING_LCPS)
def test_lexicographic_rule_solves_lcps_on_which_plain_rule_cycles(jit, M, q):
    M, q = np.array(M), np.array(q)
    assert naive_lemke_cycles(M, q)
    z, pivots = lemke(M, q, jit=jit)
    assert_lcp_solution(M, q, z, tol=1e-12)


def assert_step_solution(problem, solution, tol=TOL):
    assert np.allclose(solution.u, problem.W @ solution.p + problem.q, atol=1e-12 * residual_scale(
        problem, solution.p, solution.u))
    scale = residual_scale(problem, solution.p, solution.u)
    assert complementarity_residual(problem, solution.p) <= tol * scale
    assert solution.residual <= tol * scale
    assert abs(solution.residual - complementarity_residual(problem, solution.p)) <= 500 * np.finfo(float).eps * scale


@pytest.mark.parametrize("formulation", ["interval", "cone"])
@settings(max_examples=200, deadline=None, derandomize=True)
@given(problem=friction_steps())
def test_friction_step_solved_to_round_off(formulation, problem):
    if formulation == "cone":
        # the cone LCP has entries ~ hi², lo²: with a tiny nonzero interval end it is
        # ill-scaled (one reason it is only the fallback)
        ends = np.abs(np.concatenate([problem.lo, problem.hi]))
        assume(np.all((ends == 0.0) | (ends >= 1e-3)))
    solution = lemke_friction(problem, formulation=formulation)
    assert_step_solution(problem, solution)
    pN, pT = solution.normal_impulse, solution.tangential_impulse
    scale = residual_scale(problem, solution.p, solution.u)
    assert pN.min() >= -TOL * scale
    assert np.all(pT >= problem.lo * pN - TOL * scale) and np.all(pT <= problem.hi * pN + TOL * scale)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(problem=friction_steps())
def test_python_kernel_matches_numba_kernel(problem):
    if not HAVE_NUMBA:
        pytest.skip("numba not installed")
    compiled = lemke_friction(problem, jit=True)
    python = lemke_friction(problem, jit=False)
    assert np.allclose(compiled.p, python.p, rtol=0, atol=1e-12 * max(1.0, np.abs(compiled.p).max()))
    assert compiled.iterations == python.iterations


def test_many_random_steps_all_solved():
    """A sweep over the generator family, including μ up to 5 (where the interval LCP alone
    occasionally ray-terminates and the cone fallback takes over)."""
    rng = np.random.default_rng(20240611)
    for k in range(1500):
        problem = random_step(rng, 1 + k % 2, kind=("disk", "corner")[k % 3 == 0], mu_max=(0.5, 2, 5)[k % 3])
        assert_step_solution(problem, lemke_friction(problem))


@pytest.mark.parametrize("jit", JIT_MODES)
@pytest.mark.parametrize("formulation", ["interval", "cone"])
@pytest.mark.parametrize("angle, mu, states", [
    (0.0, 0.5, ["stick", "stick"]),      # flat: W singular, tangential split indeterminate
    (0.3, 0.5, ["stick", "stick"]),      # incline below the friction angle: sticks
    (0.6, 0.5, ["slip+", "slip+"]),      # beyond it: both slide down (the tangent points downhill)
])
def test_block_with_two_corners_on_incline(jit, formulation, angle, mu, states):
    problem = block_on_incline(angle, mu)
    assert np.linalg.matrix_rank(problem.W) == 3
    solution = lemke_friction(problem, formulation=formulation, fallback=False, jit=jit)
    assert_step_solution(problem, solution)
    assert solution.info["states"] == states
    # the resultant is determined even though the split is not: total normal impulse
    # balances gravity's normal component, total tangential its slope component (sticking)
    normal_total = solution.normal_impulse.sum()
    assert normal_total == pytest.approx(0.0981 * np.cos(angle), rel=1e-9)
    if states[0] == "stick":
        assert solution.tangential_impulse.sum() == pytest.approx(-0.0981 * np.sin(angle), rel=1e-9,
                                                                  abs=500 * np.finfo(float).eps * normal_total)


def test_degenerate_step_with_zero_free_velocity_components():
    # resting block, nothing moving: q has exact zeros (ties in the first ratio test)
    problem = block_on_incline(0.0, 0.3, gravity_impulse=0.0)
    solution = lemke_friction(problem)
    assert solution.iterations == 0 and np.all(solution.p == 0.0)
    problem = PlanarFrictionProblem.coulomb(
        block_on_incline(0.0, 0.3).W, np.array([-1.0, 0.0, -1.0, 0.0]), [0.3, 0.3]
    )
    assert_step_solution(problem, lemke_friction(problem))


def test_unknown_formulation_is_rejected():
    problem = block_on_incline(0.0, 0.3)
    with pytest.raises(ValueError, match="unknown formulation 'x'"):
        lemke_friction(problem, formulation="x")


def test_failure_message_names_both_formulations(monkeypatch):
    problem = block_on_incline(0.0, 0.3)
    monkeypatch.setattr(lemke_module, "_default_max_pivots", lambda n: 1)
    with pytest.raises(NoConvergence, match=r"pivot limit 1 .*interval.*; fallback: .*pivot limit 1 .*cone"):
        lemke_friction(problem)


@pytest.mark.parametrize("ratio", [1e-9, 1e-12])
def test_contacts_of_very_different_stiffness_are_solved(ratio):
    # A light and a heavy body (W blocks 1 and `ratio`), both pushed into contact, no tangential
    # drive: p_N = −q_N / W_NN and p_T = 0 exactly. Global scaling alone made the heavy contact's
    # block look like round-off (a wrong impulse accepted with residual 1, or a ray).
    from nonsmooth_rod.solvers import PlanarFrictionProblem, solve

    W = np.diag([1.0, 1.0, ratio, ratio])
    problem = PlanarFrictionProblem(W, np.array([-1.0, 0.0, -1.0, 0.0]), np.array([-0.3, -0.3]), np.array([0.3, 0.3]))
    solution = solve(problem, "lemke")
    np.testing.assert_allclose(solution.p, [1.0, 0.0, 1.0 / ratio, 0.0], rtol=1e-12, atol=1e-12)


# ---------------------------------------------------------------- the warm start (kernels.lemke_interval)
def _kernel_solve(problem, p_start):
    """The compiled step's Lemke (kernels.solve_interval, its default acceptance) from warm start p_start:
    (status, pivots, residual, p, u)."""
    from nonsmooth_rod.solvers.kernels import SOLVER_LEMKE, solve_interval

    p, u = np.array(p_start, dtype=float), np.zeros_like(problem.q)
    status, pivots, residual = solve_interval(SOLVER_LEMKE, problem.W, problem.q, problem.lo, problem.hi, p, u,
                                              0.0, 0)
    return int(status), int(pivots), float(residual), p, u


def test_a_warm_start_at_the_answer_takes_no_pivot_and_gives_the_same_answer():
    """Started from the cold answer's impulses (as a step at rest is from the previous step's), the
    kernel takes the basis they sit at: zero pivots on every random 1–2 contact step, the same
    answer (the basis is the same, so is its solution), within the solver's own acceptance."""
    from nonsmooth_rod.solvers.kernels import DEFAULT_RTOL, KERNEL_SOLVED

    rng = np.random.default_rng(25)
    warm = 0
    for trial in range(400):
        problem = random_step(rng, 1 + trial % 2)
        cold = lemke_friction(problem, fallback=False)
        status, pivots, residual, p, u = _kernel_solve(problem, cold.p)
        scale = residual_scale(problem, p, u)
        assert status == KERNEL_SOLVED
        assert residual == pytest.approx(complementarity_residual(problem, p), abs=1e-13 * scale)
        assert residual <= DEFAULT_RTOL * scale
        np.testing.assert_allclose(u, problem.W @ p + problem.q, rtol=0, atol=1e-13 * scale)
        if pivots == 0 and cold.iterations > 0:
            warm += 1
            np.testing.assert_allclose(p, cold.p, rtol=0, atol=1e-9 * scale)
            np.testing.assert_allclose(u, cold.u, rtol=0, atol=1e-9 * scale)
    assert warm >= 330  # (342 of 400: the other 58 have q ≥ 0, which the cold pivoting answers with none too)


def test_a_warm_start_that_no_longer_holds_falls_back_to_pivoting():
    """The block sticks on both corners at 10° with μ = 0.5; at 40° it slides: the stuck basis is
    infeasible for the steeper problem (its tangential impulse beyond μ p_N), so Lemke pivots from
    scratch and gives the cold answer exactly."""
    from nonsmooth_rod.solvers.kernels import KERNEL_SOLVED

    stuck = lemke_friction(block_on_incline(np.radians(10.0), 0.5))
    assert stuck.info["states"] == ["stick", "stick"]
    steep = block_on_incline(np.radians(40.0), 0.5)
    cold = lemke_friction(steep, fallback=False)
    status, pivots, _, p, u = _kernel_solve(steep, stuck.p)
    assert status == KERNEL_SOLVED and pivots == cold.iterations > 0
    scale = residual_scale(steep, p, u)
    np.testing.assert_allclose(p, cold.p, rtol=0, atol=1e-12 * scale)
    assert cold.info["states"] == ["slip-", "slip-"] or cold.info["states"] == ["slip+", "slip+"]


def test_a_stuck_block_warm_started_from_its_own_vertex_keeps_it():
    """Both corners stuck: the answers are a segment (W d = 0 along d = (0, 1, 0, −1)). Lemke's
    answer is an end of it (one corner's tangential impulse at a friction bound); the warm start
    from it stays at that end, with no pivot, and every answer has the same velocities u."""
    problem = block_on_incline(np.radians(10.0), 0.5)
    cold = lemke_friction(problem, fallback=False)
    status, pivots, _, p, u = _kernel_solve(problem, cold.p)
    assert pivots == 0 < cold.iterations
    scale = residual_scale(problem, p, u)
    np.testing.assert_allclose(p, cold.p, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(u, cold.u, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(u[1::2], 0.0, atol=1e-12 * scale)  # stuck
