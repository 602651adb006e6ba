"""The public generic LCP solver: nonsmooth_rod.solvers.lcp.lemke on textbook problems."""
from __future__ import annotations

import numpy as np
import pytest

from nonsmooth_rod.solvers import lcp
from nonsmooth_rod.validation import InputError

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)


@pytest.mark.parametrize("M, q, z_exact", [
    # symmetric positive definite: both unknowns active, M z = −q
    ([[2.0, 1.0], [1.0, 2.0]], [-5.0, -6.0], [4.0 / 3.0, 7.0 / 3.0]),
    # non-symmetric P-matrix (principal minors 1, 1, 2): z = (1, 2), w = 0
    ([[1.0, -1.0], [1.0, 1.0]], [1.0, -3.0], [1.0, 2.0]),
    # Murty's lower-triangular P-matrix: z = (8, 0, 0), w = (0, 4, 2)
    ([[1.0, 0.0, 0.0], [2.0, 1.0, 0.0], [2.0, 2.0, 1.0]], [-8.0, -12.0, -14.0], [8.0, 0.0, 0.0]),
    # only the second unknown active: z2 = 3/4, w1 = 1 − 3/4·1
    ([[3.0, 1.0], [1.0, 4.0]], [1.0, -3.0], [0.0, 0.75]),
])
def test_p_matrix_lcps_with_known_solution(M, q, z_exact):
    result = lcp.lemke(M, q)
    assert result.status == "solved" and result.success
    # a few hundred ulps of the problem's scale: its largest z, q and M z
    scale = max(np.max(np.abs(z_exact)), np.max(np.abs(q)), np.max(np.abs(np.array(M) @ z_exact)))
    roundoff = 500 * np.finfo(float).eps * scale
    np.testing.assert_allclose(result.z, z_exact, rtol=0, atol=roundoff)
    np.testing.assert_allclose(result.w, np.array(M) @ z_exact + np.array(q), rtol=0, atol=roundoff)
    assert result.w.min() >= -roundoff and abs(result.z @ result.w) <= roundoff * scale


def test_nonnegative_q_needs_no_pivot():
    result = lcp.lemke(np.eye(3), [1.0, 0.0, 2.0])
    assert result.success and result.pivots == 0 and np.all(result.z == 0.0)
    np.testing.assert_array_equal(result.w, [1.0, 0.0, 2.0])


@pytest.mark.parametrize("M, q", [
    ([[-1.0]], [-1.0]),  # w = −z − 1 < 0 for all z ≥ 0
    ([[-1.0, 1.0], [1.0, -1.0]], [-1.0, -1.0]),  # w1 + w2 = −2: infeasible
])
def test_infeasible_lcp_reports_a_secondary_ray(M, q):
    result = lcp.lemke(M, q)
    assert result.status == "ray" and not result.success


def test_pivot_limit_is_reported():
    M = [[1.0, 2.0, 0.0], [0.0, 1.0, 2.0], [2.0, 0.0, 1.0]]
    result = lcp.lemke(M, -np.ones(3), max_pivots=1)
    assert result.status == "pivot-limit" and result.pivots == 1
    assert lcp.lemke(M, -np.ones(3)).success


@pytest.mark.parametrize("M, q, name", [
    ([[np.nan, 1.0], [1.0, 2.0]], [-1.0, -1.0], "M"),
    ([[2.0, 1.0], [1.0, np.inf]], [-1.0, -1.0], "M"),
    ([[2.0, 1.0], [1.0, 2.0]], [-np.inf, -1.0], "q"),
    ([[2.0, 1.0], [1.0, 2.0]], [-1.0, np.nan], "q"),
])
def test_non_finite_data_refused_naming_the_argument(M, q, name):
    with pytest.raises(InputError, match=rf"^lemke: {name} must be finite, got (nan|inf|-inf) at index"):
        lcp.lemke(M, q)


def test_malformed_input_refused():
    with pytest.raises(InputError, match="M must be 2×2 for q of length 2"):
        lcp.lemke(np.eye(3), [1.0, 2.0])
    with pytest.raises(InputError, match="M must be an array of numbers"):
        lcp.lemke("x", [1.0])
    with pytest.raises(InputError, match="max_pivots must be a whole number in \\[0, "):
        lcp.lemke(np.eye(2), [1.0, 2.0], max_pivots=2.5)


def test_reachable_from_the_package():
    import nonsmooth_rod.solvers as solvers

    assert solvers.lcp.lemke is lcp.lemke


@pytest.mark.parametrize("diagonal, q", [
    ([1.0, 1e-9], [-1.0, -1.0]),
    ([1e-200, 1.0, 1e200], [-1.0, -1.0, -1.0]),
    ([1e-200, 1.0, 1e200], [-1.0, 2.0, -1e100]),
])
def test_badly_scaled_p_matrices_are_solved(diagonal, q):
    # a diagonal P-matrix: z_i = max(−q_i, 0)/d_i exactly, whatever the scales
    result = lcp.lemke(np.diag(diagonal), q)
    z_exact = np.maximum(-np.array(q), 0.0) / np.array(diagonal)
    assert result.status == "solved"
    np.testing.assert_allclose(result.z, z_exact, rtol=1e-12, atol=0)


def test_badly_scaled_dense_p_matrix_is_solved():
    # D A D with A positive definite and D from 1e-150 to 1e150: the LCP of D A D, q = D q_A
    # has the solution z = D⁻¹ z_A of (A, q_A), which the well-scaled problem gives.
    A = np.array([[4.0, 1.0, 0.5], [1.0, 3.0, 1.0], [0.5, 1.0, 5.0]])
    q_A = np.array([-1.0, 0.5, -2.0])
    D = np.array([1e-150, 1.0, 1e150])
    reference = lcp.lemke(A, q_A)
    result = lcp.lemke(D[:, None] * A * D[None, :], D * q_A)
    assert reference.success and result.status == "solved"
    np.testing.assert_allclose(result.z * D, reference.z, rtol=1e-12, atol=1e-15)


def test_a_solution_beyond_float64_is_overflow_not_solved():
    result = lcp.lemke([[1e-300]], [-1e300])
    assert result.status == "overflow" and not result.success


def test_a_huge_but_representable_solution_is_solved():
    result = lcp.lemke(np.eye(2), [-1e308, -1e308])
    assert result.status == "solved"
    np.testing.assert_array_equal(result.z, [1e308, 1e308])


def test_time_limit_ends_with_its_status():
    rng = np.random.default_rng(3)
    n = 400
    A = rng.standard_normal((n, n))
    M, q = A @ A.T + n * np.eye(n), -np.abs(rng.standard_normal(n))
    result = lcp.lemke(M, q, time_limit=1e-3)
    assert result.status == "time-limit" and not result.success and result.pivots < n


@pytest.mark.parametrize("M, q, max_pivots, message", [
    (np.zeros((0, 0)), [], None, "empty"),
    ([], [], None, "M must be 0×0"),
    (np.eye(2), [-1.0, -1.0], 10**30, "max_pivots must be a whole number"),
    (np.eye(2), [-1.0, -1.0], True, "max_pivots must be a whole number"),
    (np.ones((2, 3)), [-1.0, -1.0], None, "M must be 2×2"),
    (np.eye(2), ["a", "b"], None, "q must be an array of numbers"),
])
def test_raw_errors_are_input_errors(M, q, max_pivots, message):
    with pytest.raises(InputError, match=message):
        lcp.lemke(M, q, max_pivots=max_pivots)
