"""Lemke's complementary pivoting, for a general LCP and for the step's friction problem.

General LCP:  w = M z + q,  0 ≤ w ⊥ z ≥ 0.

Friction step as an LCP (``lemke_friction``). Per contact i the unknowns are
z_i = (p_N, β, σ) with β = p_T − lo·p_N the tangential impulse measured from the lower end
of the friction interval and σ ≥ 0 a slack that carries the magnitude of a negative slip::

    w_i = ( u_N,                  ⊥  p_N ≥ 0
            u_T + σ,              ⊥  β   ≥ 0
            (hi − lo)·p_N − β )   ⊥  σ   ≥ 0

With u = W p + q and p_T = lo·p_N + β, contact j's columns of W enter as
(W_·N + lo_j W_·T, W_·T), which gives per block (i row, j column)::

    M_ij = [[W_NN + lo_j W_NT, W_NT, 0     ],
            [W_TN + lo_j W_TT, W_TT, δ_ij  ],
            [δ_ij (hi_i − lo_i), −δ_ij, 0  ]],     q_i = (q_N, q_T, 0).

Why this is the step law (hi > lo; for hi = lo, β = 0 and p_T = lo·p_N is forced):
β = 0 ⇒ p_T = lo·p_N; σ > 0 would need β = (hi − lo)p_N = 0 i.e. p_N = 0, so for p_N > 0
σ = 0 and u_T ≥ 0 (slip "+", or rest at the edge). β = (hi − lo)p_N > 0 ⇒ p_T = hi·p_N
and u_T = −σ ≤ 0 (slip "−"). 0 < β < (hi − lo)p_N ⇒ σ = 0 and u_T = −σ = 0 (stick).

Second formulation ("cone", Anitescu–Potra): z_i = (p_N, b_hi, b_lo, λ) with
p_T = hi·b_hi + lo·b_lo and w_i = (u_N, λ + hi·u_T, λ + lo·u_T, p_N − b_hi − b_lo). Its matrix
is copositive (zᵀMz = pᵀWp + Σ λ p_N); the interval one is not (zᵀMz = pᵀWp + Σ |lo| p_N u_T
+ Σ (hi − lo) σ p_N, and u_T may be negative), so Lemke has no processing guarantee for it.

Robustness in practice: two contacts on a 3-DOF body always make W singular, and on such
steps Lemke could reach z0 ≈ 1e-16 on a degenerate pivot without z0 being chosen to leave,
then stop on a "ray" (or pivot on a round-off entry of 1e-11 and blow the tableau up).
Both are handled: a pivot must exceed PIVOT_TOL (relative), and a ray whose point already
solves the step (z0 ≤ ZERO_Z0_TOL, or a friction residual within RESIDUAL_TOL: wedged
contacts stop with z0 ~ 1e-11) is accepted. Before these rules ~1e-4 of random 2-contact
steps failed (interval 7, cone 3 per 1e5). After them, in 1.2·10^6 random 1–2 contact steps
with μ up to 5: the cone LCP never failed, the interval LCP once (a near-jammed stick–stick
step with impulses 40× the free velocity: a genuine secondary ray of the non-copositive
matrix), which the cone LCP then solved. Hence ``lemke_friction`` falls back to the other
formulation when one fails.

The pivoting kernels are written once, as float loops over numpy arrays, and decorated with
`nonsmooth_rod._jit.jit`: compiled by numba when it is installed, the same source interpreted
otherwise (``jit=False`` runs it interpreted even where numba is present). The compiled
Moreau–Jean loop reaches them through `kernels.solve_interval`.
"""
from __future__ import annotations

import time

import numpy as np

from .._jit import ENABLED as HAVE_NUMBA
from .._jit import jit, jit_borrowing, jit_inline
from ..validation import InputError, quoted, require_integer, require_positive
from ._common import RESIDUAL_FLOOR, interpreted, loop_array, require_finite_array
from .kernel_base import (carve, carve_matrix, lu_factor, lu_solve, problem_scale, solver_floats, solver_ints,
                          step_residual)
from .problem import (
    ContactSolution,
    NoConvergence,
    PlanarFrictionProblem,
    RayTermination,
    SolverError,
    classify_contacts,
)

# Kernel status codes (the generic LCP adds TIME_LIMIT, OVERFLOW, INACCURATE, decided in Python).
SOLVED, RAY, PIVOT_LIMIT, TIME_LIMIT, OVERFLOW, INACCURATE = 0, 1, 2, 3, 4, 5
MAX_PIVOTS = 10**12  # a pivot limit beyond this is no limit (and must fit the kernels' int64)
EQUILIBRATION_SWEEPS = 64  # Ruiz sweeps: each halves the binary exponents, 1e±308 needs ~11
ACCURACY = 1e-9  # a generic LCP's solution: w ≥ 0 and z·w = 0 to this, relative to each row's scale
ROUNDOFF_FLOOR = 1e-12  # ... or to this relative to the whole problem's (ties are 1e-14 apart)
CHUNK_WORK = 2e7  # flops of pivoting between two readings of the clock (~10 ms compiled)
# Friction LCP formulations.
INTERVAL, CONE = 0, 1
FORMULATIONS = {"interval": INTERVAL, "cone": CONE}

# Tolerances of the pivoting, in the units of the normalised data (max |entry| of M and q = 1).
PIVOT_TOL = 1e-9  # a column entry must exceed this (times the column's max, ≥ 1) to be a pivot
ZERO_Z0_TOL = 1e-12  # an artificial z0 this small counts as zero (the basis then solves the LCP)
# Relative tolerance under which two ratios count as tied: round-off ties only. A looser one
# lets a row with a ratio larger by ~TIE_TOL leave, which puts the true minimum row at
# −TIE_TOL, and the cone LCP's hi², lo² entries magnify that (1e-12 gave 1e-9 errors in p).
TIE_TOL = 1e-14

# Accept a friction solution when complementarity_residual ≤ RESIDUAL_TOL · residual_scale.
RESIDUAL_TOL = 1e-9

# The warm start (warm_interval_answer): a tangential impulse within this fraction of the friction
# interval's reach (max(|lo|, |hi|) p_N) of one of its ends counts as at that end.
WARM_BOUND_TOL = 1e-9


# The pivoting and its helpers are compiled without reference counting (_jit.jit_borrowing): they
# take arrays and return numbers, so any caller may call them, and the row views they take in
# their loops (a pivot touches every row) count nothing.
@jit_borrowing
def _fill_tableau(T, M, q, n):
    """T = [I | −M | −d | q] with covering vector d = (1, …, 1); T must be zero on entry."""
    for i in range(n):
        row = T[i]
        row[i] = 1.0
        Mi = M[i]
        for j in range(n):
            row[n + j] = -Mi[j]
        row[2 * n] = -1.0
        row[2 * n + 1] = q[i]


@jit_borrowing
def _pivot(T, r, e):
    """Gauss–Jordan pivot of tableau T on row r, column e, in place."""
    n_cols = T.shape[1]
    row = T[r]
    inverse = 1.0 / row[e]
    for j in range(n_cols):
        row[j] *= inverse
    row[e] = 1.0
    for i in range(T.shape[0]):
        if i != r:
            other = T[i]
            factor = other[e]
            if factor != 0.0:
                for j in range(n_cols):
                    other[j] -= factor * row[j]
                other[e] = 0.0


@jit_borrowing
def _lex_smaller(T, i, k, e, n):
    """Is row i's (rhs, B⁻¹ row)/T[i, e] lexicographically smaller than row k's?

    B⁻¹ sits in the first n columns (the w columns, the identity at the start). Rows of
    B⁻¹ are independent, so in exact arithmetic two rows are never lexicographically equal:
    this is what makes the minimum-ratio choice unique and rules out cycling.
    """
    a_i = T[i, e]
    a_k = T[k, e]
    x = T[i, 2 * n + 1] / a_i
    y = T[k, 2 * n + 1] / a_k
    tol = TIE_TOL * (1.0 + abs(x) + abs(y))
    if x < y - tol:
        return True
    if x > y + tol:
        return False
    for j in range(n):
        x = T[i, j] / a_i
        y = T[k, j] / a_k
        tol = TIE_TOL * (1.0 + abs(x) + abs(y))
        if x < y - tol:
            return True
        if x > y + tol:
            return False
    return False


@jit_borrowing
def _first_leaving_row(T, n, rhs):
    """Entering z0 drives w up by z0·d; the row that leaves is the lexicographic minimum of
    (q_i, e_i): the most negative q_i, ties to the LARGEST index (e_i is lexicographically
    smaller for larger i). −1 when q ≥ 0 (z = 0 solves the LCP)."""
    r = np.int64(-1)  # not a literal: numba would compile the callees for the literal −1 too
    q_min = 0.0
    for i in range(n):
        value = T[i, rhs]
        if value < 0.0:
            if r < 0 or value <= q_min + TIE_TOL * (1.0 + abs(q_min)):
                r = i
                q_min = min(q_min, value)
    return r


@jit_borrowing
def _prefer_z0(T, r, z0_row, entering, rhs, pivot_tol):
    """If z0 ties for leaving, let it leave: that ends the method with a solution."""
    a0 = T[z0_row, entering]
    if r != z0_row and a0 > pivot_tol:
        ratio0 = T[z0_row, rhs] / a0
        ratio = T[r, rhs] / T[r, entering]
        if ratio0 <= ratio + TIE_TOL * (1.0 + abs(ratio)):
            return z0_row
    return r


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _complementary_pivoting(T, basis, n, max_pivots):
    """Lemke's method on tableau T = [I | −M | −d | q]; basis[i] is the variable of row i.

    Variables are numbered w_0..w_{n−1} = 0..n−1, z_0..z_{n−1} = n..2n−1, z0 (artificial) = 2n.
    Returns (status, pivots, last entering variable). On SOLVED the basic variables are in
    basis/T[:, rhs]; q ≥ 0 returns SOLVED after 0 pivots (z = 0). On PIVOT_LIMIT (with
    pivots ≥ 1) `_resume_pivoting` continues where it stopped.
    """
    z0 = 2 * n
    rhs = 2 * n + 1
    r = _first_leaving_row(T, n, rhs)
    if r < 0:
        return SOLVED, 0, -1
    if max_pivots < 1:
        return PIVOT_LIMIT, 0, z0
    _pivot(T, r, z0)
    leaving = basis[r]
    basis[r] = z0
    return _resume_pivoting(T, basis, n, leaving + n, 1, max_pivots)


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _resume_pivoting(T, basis, n, entering, pivots, max_pivots):
    """The pivoting loop from `entering` (the complement of the variable that left last), after
    `pivots` pivots, up to max_pivots in all: (status, pivots, entering)."""
    z0 = 2 * n
    rhs = 2 * n + 1
    z0_row = np.int64(0)
    for i in range(n):
        if basis[i] == z0:
            z0_row = i
    while True:
        column_max = 1.0
        for i in range(n):
            column_max = max(column_max, abs(T[i, entering]))
        pivot_tol = PIVOT_TOL * column_max
        r = np.int64(-1)
        for i in range(n):
            if T[i, entering] > pivot_tol and (r < 0 or _lex_smaller(T, i, r, entering, n)):
                r = i
        if r < 0:
            # A secondary ray — unless z0 already sits at (round-off) zero, in which case the
            # current complementary basis solves the LCP (singular W makes this happen: z0
            # reaches 0 on a degenerate pivot without being chosen to leave).
            if T[z0_row, rhs] <= ZERO_Z0_TOL:
                return SOLVED, pivots, entering
            return RAY, pivots, entering
        r = _prefer_z0(T, r, z0_row, entering, rhs, pivot_tol)
        if pivots >= max_pivots:
            return PIVOT_LIMIT, pivots, entering
        _pivot(T, r, entering)
        pivots += 1
        leaving = basis[r]
        basis[r] = entering
        if leaving == z0:
            return SOLVED, pivots, entering
        entering = leaving + n if leaving < n else leaving - n


@jit_borrowing
def _basic_solution(T, basis, M, q, n, z, residual):
    """z from the final basis, with one step of iterative refinement against the original M, q
    (`residual`: n floats of scratch).

    The basic values x satisfy B x = q with B's columns e_v (w_v), −M[:, c] (z_c) and −d (z0);
    the tableau's w columns hold B⁻¹, so x += B⁻¹ (q − B x) removes most of the round-off the
    pivots accumulated. Tiny negative values of round-off size are clipped to 0.
    """
    rhs = 2 * n + 1
    for k in range(n):
        residual[k] = q[k]
    for i in range(n):
        v = basis[i]
        x = T[i, rhs]
        if v < n:
            residual[v] -= x
        elif v < 2 * n:
            c = v - n
            for k in range(n):
                residual[k] += M[k][c] * x
        else:
            for k in range(n):
                residual[k] += x
    for j in range(n):
        z[j] = 0.0
    for i in range(n):
        v = basis[i]
        if n <= v < 2 * n:
            row = T[i]
            x = row[rhs]
            for k in range(n):
                x += row[k] * residual[k]
            z[v - n] = max(x, 0.0)


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _lemke_kernel(M, q, max_pivots, T, basis, z, residual):
    """Lemke on (M, q) given as rows/vector, in the caller's scratch (T: n × (2n + 2), basis,
    z, residual: n); fills z, returns (status, pivots, last entering)."""
    n = len(q)
    for i in range(n):
        for j in range(T.shape[1]):
            T[i, j] = 0.0
    _fill_tableau(T, M, q, n)
    for i in range(n):
        basis[i] = i
    status, pivots, entering = _complementary_pivoting(T, basis, n, max_pivots)
    for j in range(n):
        z[j] = 0.0
    if status == SOLVED or status == RAY:  # at a ray z is the last point of the path
        _basic_solution(T, basis, M, q, n, z, residual)
    return status, pivots, entering


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _fill_interval_lcp(M, qq, W, q, lo, hi, w_scale, q_scale):
    """The 3-per-contact LCP of the module docstring, from W / w_scale and q / q_scale."""
    n_c = len(lo)
    for i in range(n_c):
        row_n = M[3 * i]
        row_t = M[3 * i + 1]
        W_n = W[2 * i]
        W_t = W[2 * i + 1]
        for j in range(n_c):
            row_n[3 * j] = (W_n[2 * j] + lo[j] * W_n[2 * j + 1]) / w_scale
            row_n[3 * j + 1] = W_n[2 * j + 1] / w_scale
            row_t[3 * j] = (W_t[2 * j] + lo[j] * W_t[2 * j + 1]) / w_scale
            row_t[3 * j + 1] = W_t[2 * j + 1] / w_scale
        row_t[3 * i + 2] = 1.0
        M[3 * i + 2][3 * i] = hi[i] - lo[i]
        M[3 * i + 2][3 * i + 1] = -1.0
        qq[3 * i] = q[2 * i] / q_scale
        qq[3 * i + 1] = q[2 * i + 1] / q_scale


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _fill_cone_lcp(M, qq, W, q, lo, hi, w_scale, q_scale):
    """The 4-per-contact (Anitescu–Potra) LCP of the module docstring, scaled likewise."""
    n_c = len(lo)
    for i in range(n_c):
        row_n = M[4 * i]
        row_hi = M[4 * i + 1]
        row_lo = M[4 * i + 2]
        W_n = W[2 * i]
        W_t = W[2 * i + 1]
        for j in range(n_c):
            # columns of z_j = (p_N, b_hi, b_lo, λ) in u-space: W_·N, hi_j W_·T, lo_j W_·T, 0
            row_n[4 * j] = W_n[2 * j] / w_scale
            row_n[4 * j + 1] = hi[j] * W_n[2 * j + 1] / w_scale
            row_n[4 * j + 2] = lo[j] * W_n[2 * j + 1] / w_scale
            u_t_pn = W_t[2 * j] / w_scale
            u_t_pt = W_t[2 * j + 1] / w_scale
            row_hi[4 * j] = hi[i] * u_t_pn
            row_hi[4 * j + 1] = hi[i] * hi[j] * u_t_pt
            row_hi[4 * j + 2] = hi[i] * lo[j] * u_t_pt
            row_lo[4 * j] = lo[i] * u_t_pn
            row_lo[4 * j + 1] = lo[i] * hi[j] * u_t_pt
            row_lo[4 * j + 2] = lo[i] * lo[j] * u_t_pt
        row_hi[4 * i + 3] = 1.0
        row_lo[4 * i + 3] = 1.0
        row_gap = M[4 * i + 3]
        row_gap[4 * i] = 1.0
        row_gap[4 * i + 1] = -1.0
        row_gap[4 * i + 2] = -1.0
        qq[4 * i] = q[2 * i] / q_scale
        qq[4 * i + 1] = hi[i] * q[2 * i + 1] / q_scale
        qq[4 * i + 2] = lo[i] * q[2 * i + 1] / q_scale


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _contact_scales(W, n_c, d):
    """d: per contact the power of two nearest 1/√max(W_NN, W_TT) (1 for a zero block)."""
    for c in range(n_c):
        d[c] = 1.0
        diagonal = max(abs(W[2 * c][2 * c]), abs(W[2 * c + 1][2 * c + 1]))
        if diagonal > 0.0:
            d[c] = 2.0 ** (-np.round(0.5 * np.log2(diagonal)))


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _scaled_step(W, q, d, Ws, qs):
    """Ws = D W D, qs = D q; returns (max|W|, max|q|, max|Ws| or 1, max|qs| or 1)."""
    W_norm, q_norm, ws_norm, qs_norm = 0.0, 0.0, 0.0, 0.0
    for i in range(q.shape[0]):
        q_norm = max(q_norm, abs(q[i]))
        qs[i] = q[i] * d[i // 2]
        qs_norm = max(qs_norm, abs(qs[i]))
        for j in range(q.shape[0]):
            W_norm = max(W_norm, abs(W[i][j]))
            Ws[i][j] = W[i][j] * d[i // 2] * d[j // 2]
            ws_norm = max(ws_norm, abs(Ws[i][j]))
    return W_norm, q_norm, (ws_norm if ws_norm > 0.0 else 1.0), (qs_norm if qs_norm > 0.0 else 1.0)


@jit_borrowing
def _lemke_friction_into(W, q, lo, hi, max_pivots, formulation, floats, ints, p, u):
    """Friction step → lifted LCP → Lemke → p, u (2 len(lo) each, written) and (residual,
    status, pivots, ‖q‖∞, max|W|, max(‖p‖∞, ‖u‖∞, ‖q‖∞)) — the norms for the acceptance test
    and the contact states (computed here, they cost nothing; in Python after the call,
    microseconds). Every temporary is carved from the scratch (floats, ints:
    kernel_base.solver_scratch of ≥ len(lo) contacts). Compiled without reference counting
    (the step's hot path): it allocates nothing and returns no array.

    ``formulation``: INTERVAL (3 unknowns per contact) or CONE (4 per contact). The LCP is
    built from D W D and D q, D = diag(d_c) per contact (both rows of a contact alike, which
    leaves its friction interval as it is; d_c a power of two near 1/√W_cc: exact), then
    divided by max|D W D| and max|D q|, so that the pivoting tolerances act on O(1) numbers
    even when the contacts' W blocks differ by 1e12 (a heavy and a light body); p = D p̃ ·
    max|D q| / max|D W D| undoes it exactly. (The step's warm start, `warm_interval_answer`, is
    tried before it, on W itself.)
    """
    n_c = len(lo)
    per_contact = 3 if formulation == INTERVAL else 4
    n = per_contact * n_c
    d, at = carve(floats, 0, n_c)
    Ws, at = carve_matrix(floats, at, 2 * n_c, 2 * n_c)
    qs, at = carve(floats, at, 2 * n_c)
    M, at = carve_matrix(floats, at, n, n)
    qq, at = carve(floats, at, n)
    T, at = carve_matrix(floats, at, n, 2 * n + 2)
    z, at = carve(floats, at, n)
    refine, at = carve(floats, at, n)
    _contact_scales(W, n_c, d)
    W_norm, q_norm, w_scale, q_scale = _scaled_step(W, q, d, Ws, qs)
    for i in range(n):
        qq[i] = 0.0
        for j in range(n):
            M[i, j] = 0.0
    if formulation == INTERVAL:
        _fill_interval_lcp(M, qq, Ws, qs, lo, hi, w_scale, q_scale)
    else:
        _fill_cone_lcp(M, qq, Ws, qs, lo, hi, w_scale, q_scale)
    status, pivots, _ = _lemke_kernel(M, qq, max_pivots, T, ints[:n], z, refine)  # (z = 0 unless solved)
    residual, scale = _impulses_of(z, d, q_scale / w_scale, formulation, W, q, lo, hi, q_norm, p, u)
    if status == RAY:
        # Wedged contacts (two normals nearly opposed, W singular) make the solution set
        # unbounded, and Lemke may leave on a ray with z0 ~ 1e-11 instead of 0: the point it
        # stops at then already solves the step to round-off, and is accepted as such.
        if residual <= RESIDUAL_TOL * (scale if scale > 0.0 else 1.0):
            status = SOLVED
    return residual, status, pivots, q_norm, W_norm, scale


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _impulses_of(z, d, to_units, formulation, W, q, lo, hi, q_norm, p, u):
    """p from the LCP's z (per contact d_c · to_units undoes the scaling), u = W p + q:
    (residual, max(‖q‖∞, ‖p‖∞, ‖u‖∞)). z = 0 gives p = 0, u = q."""
    per_contact = 3 if formulation == INTERVAL else 4
    for j in range(len(lo)):
        to_impulse = d[j] * to_units
        k = per_contact * j
        p[2 * j] = z[k] * to_impulse
        if formulation == INTERVAL:
            p[2 * j + 1] = (lo[j] * z[k] + z[k + 1]) * to_impulse
        else:
            p[2 * j + 1] = (hi[j] * z[k + 1] + lo[j] * z[k + 2]) * to_impulse
    residual = step_residual(W, q, lo, hi, p, u)  # u = W p + q, problem.py's residual
    return residual, max(q_norm, _max_abs(p), _max_abs(u))


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _warm_basis(p, lo, hi, basic):
    """The complementary basis of the interval LCP that the impulses p sit at: basic[k] = 1
    when z_k is basic (else its w_k is). Per contact (p_N, β, σ): p_N basic when p_N > 0; β
    basic unless p_T is at the interval's low end (β = 0); σ basic when p_T is at its high end
    (slip −, or a stick there). A non-finite or non-positive p_N: the contact open, all w basic."""
    for j in range(len(lo)):
        k = 3 * j
        p_n, p_t = p[2 * j], p[2 * j + 1]
        basic[k], basic[k + 1], basic[k + 2] = 0, 0, 0
        if not (p_n > 0.0 and np.isfinite(p_n) and np.isfinite(p_t)):
            continue
        basic[k] = 1
        tol = WARM_BOUND_TOL * max(abs(lo[j]), abs(hi[j])) * p_n
        beta, width = p_t - lo[j] * p_n, (hi[j] - lo[j]) * p_n
        if beta > tol:
            basic[k + 1] = 1
            if beta >= width - tol:
                basic[k + 2] = 1


@jit_borrowing
def warm_interval_answer(W, q, lo, hi, p, u, rtol, room, support):
    """The step's answer at the basis its warm start p sits at, or −1 (p, u then garbage: the caller
    pivots from scratch). p on entry: the previous step's impulses of the contacts that stay closed,
    or the sign iteration's previous solve. The interval LCP's basic set S of p (_warm_basis) is
    solved alone — M_SS z_S = −q_S, its entries read from W (`_interval_entry`, unscaled), LU with
    partial pivoting and one step of iterative refinement (without it a held ladder's round-off
    wandered in a cycle of four steps, which the loop's exact-rest test does not take) — and its
    p, u = W p + q are returned (the residual) when they pass Lemke's own acceptance, the
    residual ≤ rtol · max(‖q‖∞, ‖p‖∞, ‖u‖∞): no tableau, no scaling, no pivot. −1 when M_SS is
    singular (a pivot ≤ PIVOT_TOL · max|M_SS|: both corners of a block strictly inside their
    intervals, the segment's interior) or the answer misses the law (the basis is infeasible now).
    room: n² + 2n floats, support: 2n ints, n = 3 len(lo). Borrowing: it allocates nothing."""
    n = 3 * lo.shape[0]
    _warm_basis(p, lo, hi, support)
    m = 0
    for k in range(n):
        if support[k]:
            support[m] = k
            m += 1
    A = room[:m * m].reshape((m, m))
    x, correction, rows = room[m * m:m * m + m], room[m * m + m:m * m + 2 * m], support[n:n + m]
    largest = 0.0
    for a in range(m):
        x[a] = -_interval_q(q, support[a])
        for b in range(m):
            A[a, b] = _interval_entry(W, lo, hi, support[a], support[b])
            largest = max(largest, abs(A[a, b]))
    if not lu_factor(A, m, rows, PIVOT_TOL * largest):
        return -1.0
    lu_solve(A, m, rows, x)
    for a in range(m):  # the refinement: the residual of the original rows, solved again
        value = -_interval_q(q, support[a])
        for b in range(m):
            value -= _interval_entry(W, lo, hi, support[a], support[b]) * x[b]
        correction[a] = value
    lu_solve(A, m, rows, correction)
    for r in range(2 * lo.shape[0]):
        p[r] = 0.0
    for a in range(m):
        k = support[a]
        value = x[a] + correction[a]
        if k % 3 == 0:
            p[2 * (k // 3)] += value
            p[2 * (k // 3) + 1] += lo[k // 3] * value
        elif k % 3 == 1:
            p[2 * (k // 3) + 1] += value
    residual = step_residual(W, q, lo, hi, p, u)
    return residual if residual <= rtol * problem_scale(q, p, u) else -1.0


@jit_borrowing
def _interval_q(q, r):
    """Entry r of the interval LCP's q (unscaled): (q_N, q_T, 0) per contact."""
    return q[2 * (r // 3) + r % 3] if r % 3 < 2 else 0.0


@jit_borrowing
def _interval_entry(W, lo, hi, r, c):
    """Entry (r, c) of the interval LCP's M (module docstring), unscaled, read from W."""
    i, row_kind, j, column_kind = r // 3, r % 3, c // 3, c % 3
    if row_kind == 2:  # (hi − lo) p_N − β
        if i != j:
            return 0.0
        return hi[i] - lo[i] if column_kind == 0 else (-1.0 if column_kind == 1 else 0.0)
    if column_kind == 2:  # σ enters u_T + σ of its own contact
        return 1.0 if row_kind == 1 and i == j else 0.0
    row = 2 * i + row_kind
    if column_kind == 0:
        return W[row, 2 * j] + lo[j] * W[row, 2 * j + 1]
    return W[row, 2 * j + 1]


@jit_borrowing
def _max_abs(values):
    largest = 0.0
    for value in values:
        largest = max(largest, abs(value))
    return largest


def _default_max_pivots(n):
    # Lemke typically needs O(n) pivots; exponential worst cases do not occur at n ≤ 12.
    return 50 + 20 * n


default_max_pivots = jit(_default_max_pivots)  # for the compiled callers


def _variable_name(index: int, n: int) -> str:
    if index < 0:
        return "none"
    if index < n:
        return f"w[{index}]"
    if index < 2 * n:
        return f"z[{index - n}]"
    return "the artificial z0"


def lemke(M, q, max_pivots: int | None = None, *, jit: bool | None = None):
    """Solve w = M z + q, 0 ≤ w ⊥ z ≥ 0 by Lemke's method; return (z, pivots).

    Covering vector d = (1, …, 1); lexicographic minimum-ratio rule (no cycling on degenerate
    problems); q ≥ 0 returns z = 0 after 0 pivots. M and q are normalised to max|entry| = 1
    before pivoting (the solution scales back exactly). ``jit``: use the numba kernel (default:
    when numba is installed); False runs the same source interpreted.

    Raises InputError for M, q of inconsistent shapes or with NaN/inf entries,
    RayTermination on a secondary ray (no solution found by complementary pivoting: the LCP
    may be infeasible, or M outside the classes Lemke is guaranteed to process) and
    NoConvergence when ``max_pivots`` (default 50 + 20 n) is reached.
    `nonsmooth_rod.solvers.lcp.lemke` is the same method reporting failure as a status.
    """
    z, _, status, pivots, entering, max_pivots = run_lemke(M, q, max_pivots, jit)
    n = z.shape[0]
    if status == RAY:
        raise RayTermination(
            f"lemke: secondary ray after {pivots} pivots (entering {_variable_name(entering, n)} "
            f"has no positive entry in its column) on an LCP of size {n}: no solution reached"
        )
    if status == PIVOT_LIMIT:
        raise NoConvergence(f"lemke: pivot limit {max_pivots} reached on an LCP of size {n}")
    if status == INACCURATE:
        raise NoConvergence(f"lemke: no solution of the LCP of size {n} accurate to {ACCURACY:g} was reached")
    if status == OVERFLOW:
        raise NoConvergence(f"lemke: the solution of the LCP of size {n} overflows float64 (|z| > 1.8e308)")
    return z, pivots


def run_lemke(M, q, max_pivots: int | None, jit: bool | None, time_limit: float | None = None):
    """Validate (M, q), equilibrate, pivot: (z, w, status, pivots, last entering, max_pivots used).

    The LCP solved is an equilibrated one, D_r M D_c z' + D_r q (D_r, D_c positive diagonal,
    powers of two: exact), whose solution gives z = D_c z'. First D_r, D_c balance M's rows
    and columns; if that solution fails `_accurate` (or ends on a ray), a second pass takes
    D_r from q (every nonzero q_i of size one) and D_c from the columns: a P-matrix with
    entries from 1e-200 to 1e200 then solves as the identity does. The pivots run in chunks
    so that `time_limit` (wall seconds) is read between them (TIME_LIMIT). A solution beyond
    float64 (a tiny M with a huge q) is OVERFLOW; one that fails `_accurate` both ways INACCURATE.
    """
    M, q = _checked_lcp(M, q)
    n = q.shape[0]
    max_pivots = _default_max_pivots(n) if max_pivots is None else require_integer(
        "lemke: max_pivots", max_pivots, 0, MAX_PIVOTS)
    if time_limit is not None:
        time_limit = require_positive("lemke: time_limit", time_limit)
    deadline = None if time_limit is None else time.monotonic() + time_limit
    first = _scaled_solve(M, q, False, max_pivots, deadline, _use_jit(jit))
    if first[2] in (SOLVED, RAY) and not _accurate(M, q, first[0], first[1]):
        second = _scaled_solve(M, q, True, max_pivots, deadline, _use_jit(jit))
        if second[2] == SOLVED and _accurate(M, q, second[0], second[1]):
            return (*second, max_pivots)
        if first[2] == SOLVED and np.all(np.isfinite(first[0])):
            first = (*first[:2], INACCURATE, *first[3:])
    return (*first, max_pivots)


def _scaled_solve(M, q, by_q: bool, max_pivots, deadline, compiled):
    """(z, w, status, pivots, entering) of Lemke on the equilibrated LCP, in M and q's units."""
    row, col, q_unit = _equilibration(M, q, by_q)
    status, pivots, entering, z_scaled = _pivot_in_chunks(row[:, None] * M * col[None, :], row * (q / q_unit),
                                                          max_pivots, deadline, compiled)
    with np.errstate(all="ignore"):
        z = col * z_scaled * q_unit
        w = M @ z + q
    if status == SOLVED and not (np.all(np.isfinite(z)) and np.all(np.isfinite(w))):
        status = OVERFLOW
    return z, w, status, pivots, entering


def _accurate(M, q, z, w) -> bool:
    """Does z solve the LCP to ACCURACY relative to each row's own scale |q_i| + Σ|M_ij z_j|,
    or to round-off (ROUNDOFF_FLOOR) of the whole problem's scale?"""
    with np.errstate(all="ignore"):
        scale = np.abs(q) + np.abs(M) @ np.abs(z)
        violation = np.maximum(-w, 0.0) + np.where(z > 0.0, np.abs(w), 0.0)
        allowed = ACCURACY * scale + ROUNDOFF_FLOOR * np.max(scale)
        return bool(np.all(np.isfinite(z)) and np.all(violation <= allowed))


def _checked_lcp(M, q):
    """M (n × n) and q (n), n ≥ 1, finite floats, or InputError naming the argument."""
    M = _float_array("M", M, 2)
    q = _float_array("q", q, 1)
    n = q.shape[0]
    if q.ndim != 1 or M.shape != (n, n):
        raise InputError(f"lemke: M must be {n}×{n} for q of length {n}, got M {M.shape}, q {q.shape}")
    if n == 0:
        raise InputError("lemke: M and q are empty: an LCP needs at least one unknown")
    require_finite_array("M", M, "lemke")
    require_finite_array("q", q, "lemke")
    return M, q


def _equilibration(M, q, by_q: bool = False):
    """(row, col, q_unit), row and col powers of two. By M (Ruiz's alternating square-root
    scaling): every row and column of row·|M|·col of max in [½, 2); by q: row_i = 1/|q_i| (to
    a power of two; rows with q_i = 0 keep M's scaling), then the columns of max in [½, 2).
    q_unit: the power of two that brings row·q to size one. Zero rows and columns stay 1."""
    n = q.shape[0]
    row, col = np.ones(n), np.ones(n)
    magnitude = np.abs(M)
    for _ in range(EQUILIBRATION_SWEEPS):
        row_shift = _half_exponent((magnitude * row[:, None] * col[None, :]).max(axis=1))
        row = np.ldexp(row, row_shift)
        col_shift = _half_exponent((magnitude * row[:, None] * col[None, :]).max(axis=0))
        col = np.ldexp(col, col_shift)
        if not (row_shift.any() or col_shift.any()):
            break
    if by_q:
        nonzero = q != 0.0
        row[nonzero] = np.ldexp(1.0, -np.frexp(np.abs(q[nonzero]))[1])
        col = np.ones(n)
        col_shift = 2 * _half_exponent((magnitude * row[:, None]).max(axis=0))
        col = np.ldexp(col, col_shift)
    with np.errstate(all="ignore"):
        q_max = float(np.max(np.abs(row * q)))
    if not np.isfinite(q_max):  # row·q overflows: bring q down first
        return row, col, float(np.ldexp(1.0, np.frexp(np.max(np.abs(q)))[1]))
    return row, col, (float(np.ldexp(0.5, np.frexp(q_max)[1])) if q_max > 0.0 else 1.0)


def _half_exponent(maxima):
    """−(binary exponent)/2 of each positive maximum (0 for zero, or when already in [½, 2))."""
    exponent = np.frexp(maxima)[1].astype(np.int64)
    return np.where(maxima > 0.0, -(exponent // 2), 0)


def _pivot_in_chunks(M, q, max_pivots, deadline, compiled):
    """Lemke on (M, q) in chunks of about CHUNK_WORK flops (compiled; a hundredth of that
    interpreted), the clock read between chunks: (status, pivots, entering, z)."""
    kernels = [k if compiled else interpreted(k) for k in (_fill_tableau, _complementary_pivoting,
                                                          _resume_pivoting, _basic_solution)]
    fill, start, resume, basic_solution = kernels
    n = q.shape[0]
    T = np.zeros((n, 2 * n + 2))
    fill(T, M, q, n)
    basis = np.arange(n)
    chunk = max(1, int(CHUNK_WORK / (1 if compiled else 100) / (n * (2 * n + 2))))
    status, pivots, entering = start(T, basis, n, min(chunk, max_pivots))
    while status == PIVOT_LIMIT and 0 < pivots < max_pivots:
        if deadline is not None and time.monotonic() > deadline:
            status = TIME_LIMIT
            break
        status, pivots, entering = resume(T, basis, n, entering, pivots, min(pivots + chunk, max_pivots))
    z = np.zeros(n)
    if status == SOLVED or status == RAY:  # at a ray z is the last point of the path
        basic_solution(T, basis, M, q, n, z, np.zeros(n))
    return int(status), int(pivots), int(entering), z


def _float_array(name, values, ndmin):
    try:
        return np.array(values, dtype=float, ndmin=ndmin)
    except (TypeError, ValueError):
        raise InputError(f"lemke: {name} must be an array of numbers, got {quoted(values)}") from None


def _use_jit(jit: bool | None) -> bool:
    if jit is None:
        return HAVE_NUMBA
    if jit and not HAVE_NUMBA:
        raise InputError("jit=True needs numba, which is not installed")
    return jit


def _run_friction_kernel(problem, formulation, max_pivots, jit):
    code = FORMULATIONS[formulation]
    if max_pivots is None:
        max_pivots = _default_max_pivots((3 if code == INTERVAL else 4) * problem.n_contacts)
    kernel = _lemke_friction_into if jit else interpreted(_lemke_friction_into)
    n = problem.n_contacts  # (the loop's kernel, its scratch and p, u allocated here: _common.loop_array)
    p, u = np.empty(2 * n), np.empty(2 * n)
    residual, status, pivots, q_norm, W_norm, scale = kernel(
        loop_array(problem.W), loop_array(problem.q), loop_array(problem.lo), loop_array(problem.hi), int(max_pivots),
        code, np.empty(solver_floats(n)), np.empty(solver_ints(n), dtype=np.int64), p, u)
    return p, u, residual, status, pivots, (q_norm, W_norm, scale)


def _attempt(problem, formulation, max_pivots, tol, jit):
    """One Lemke solve of the friction LCP: (p, u, residual, pivots, norms) or the SolverError."""
    n_c = problem.n_contacts
    p, u, residual, status, pivots, norms = _run_friction_kernel(problem, formulation, max_pivots, jit)
    size = (3 if formulation == "interval" else 4) * n_c
    if status == RAY:
        return RayTermination(
            f"lemke: secondary ray after {pivots} pivots on the {formulation} friction LCP of "
            f"{n_c} contact(s) (size {size}): no solution reached"
        )
    if status == PIVOT_LIMIT:
        return NoConvergence(
            f"lemke: pivot limit {pivots} reached on the {formulation} friction LCP of {n_c} contact(s)"
        )
    scale = norms[2] if norms[2] > 0.0 else 1.0  # = problem.residual_scale(problem, p, u)
    if not residual <= tol * scale + RESIDUAL_FLOOR:
        return NoConvergence(
            f"lemke: {formulation} LCP solution after {pivots} pivots misses the step law, "
            f"residual {residual:.3e} > {tol:.0e} × scale {scale:.3e}"
        )
    return p, u, residual, pivots, norms


def lemke_friction(
    problem: PlanarFrictionProblem,
    *,
    formulation: str = "interval",
    fallback: bool = True,
    max_pivots: int | None = None,
    tol: float = RESIDUAL_TOL,
    jit: bool | None = None,
):
    """Solve the step's friction problem exactly as a lifted LCP (module docstring) by Lemke.

    ``formulation``: "interval" (3 unknowns per contact, the default) or "cone" (4 per
    contact). Neither LCP matrix is copositive-plus for a singular W, so neither is
    guaranteed to be processed by Lemke in floating point; with ``fallback`` a failure of one
    formulation is retried with the other (their failures are rare and, in random sweeps,
    never coincide). info["formulation"] says which one produced the solution.

    Returns a ContactSolution (iterations = pivots of the successful formulation). Raises RayTermination /
    NoConvergence as ``lemke`` does (the first formulation's error, naming the second's), and
    NoConvergence if the recovered impulses miss the step law: complementarity_residual >
    tol · residual_scale (round-off only, normally ~1e-15).
    """
    if formulation not in FORMULATIONS:
        raise InputError(f"lemke: unknown formulation {formulation!r}; choose from {sorted(FORMULATIONS)}")
    jit = _use_jit(jit)
    result = _attempt(problem, formulation, max_pivots, tol, jit)
    used = formulation
    if isinstance(result, SolverError) and fallback:
        first_error = result
        used = "cone" if formulation == "interval" else "interval"
        result = _attempt(problem, used, max_pivots, tol, jit)
        if isinstance(result, SolverError):
            raise type(first_error)(f"{first_error.base_message}; fallback: {result.base_message}")
    if isinstance(result, SolverError):
        raise result
    p, u, residual, pivots, (q_norm, W_norm, _) = result
    p, u = np.asarray(p, dtype=float), np.asarray(u, dtype=float)
    states = classify_contacts(p.tolist(), u.tolist(), q_norm, W_norm)
    return ContactSolution(p, u, "lemke", pivots, residual, {"formulation": used, "states": states})


__all__ = ["lemke", "lemke_friction", "HAVE_NUMBA"]
