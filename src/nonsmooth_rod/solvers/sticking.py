"""Sticking preference of the Moreau–Jean step: a contact at rest slides only if no admissible split holds it.

Two or more contacts on one body make the step statically indeterminate: the Delassus matrix W is
singular, the end-of-step velocities of a mode (which contacts stick, which slide which way) are
unique, but the impulses are not — any split p + Z z with Z spanning the null space of the
mode's equations gives the same motion. An LCP solver returns one vertex of that set, and with
it possibly a sliding solution although another admissible split would keep the contact at rest.

`prefer_sticking` runs after the two-coefficient sign iteration has a consistent solution in
which a contact that started the step at rest (start guess 0) slides or lifts off. For the
contacts that started at rest and touch (u_N = 0), sticking or sliding, or lifted off, it asks the
event-driven integrator's question at impulse level (`model.dynamics._most_admissible_split`):
is there a split of the step's impulses that keeps a set of them sticking, the others released
(sliding their way, or open), every other closed contact in its state (sticking ones inside the
μs cone, sliding ones on the μd line with their slip direction kept), open contacts open, and
normal complementarity everywhere? The largest such set wins if it is the only one of its size;
tied sets (mirror images in a symmetric scene) are not broken by contact order: the search goes
on below their intersection. The split chosen is the one deepest inside every cone (maximal
smallest margin min(p_N, μs p_N − |p_T|)), found by a small dense simplex. See docs/friction.md.
`prefer_sticking_by_group` runs it on each group of coupled contacts alone (the step's problem is
block-diagonal over them).

Plain arrays and int64 state codes only, decorated with `_jit.jit`: the same source runs
compiled inside a numba loop and interpreted.
"""
from __future__ import annotations

import numpy as np

from .._jit import jit, jit_inline
from ._common import loop_array, python_body
from .delassus import coupled_components, group_matrix
from .kernel_base import carve, carve_matrix, lu_factor, lu_solve
from .problem import STATE_OPEN, STATE_SLIP_MINUS, STATE_SLIP_PLUS, STATE_STICK

MODE_OPEN, MODE_STICK, MODE_SLIDE = 0, 1, 2
# Touching, the impulse anywhere in the μs cone, any slip: sticking and sliding relaxed into one
# mode (the pruning test of prefer_sticking).
MODE_FREE = 3
# Touching or open — p_N ≥ 0, u_N ≥ 0, the impulse in the μs cone, without complementarity: the
# relaxation of an open candidate, which either separates or is held.
MODE_LOOSE = 4
MAX_CANDIDATES = 16  # contacts that survive the pruning considered for a held set (beyond: the first 16)
MAX_TRIALS = 64  # feasibility problems per step at most
BORDER_MAX = 2 * MAX_CANDIDATES  # entries a held-set trial adds to its base (two per candidate that lifts)
SPLIT_BOUND = 1e3  # |z| ≤ SPLIT_BOUND × the impulse scale, as the event-driven LP
PIVOT_TOL = 1e-11
DEGENERATE = 1e-14  # a pivot whose ratio is below this moves no vertex (the ratio test's tie width)
RANK_TOL = 1e-10  # singular values below RANK_TOL × the largest span the indeterminate splits
MARGIN_TOL = 1e-9  # a cone margin above −MARGIN_TOL × the impulse scale is admissible
# The LP keeps its hard rows (a slip direction, an open or loose contact's u_N) and its margin
# within LP_SHARE of the final check's tolerances (_split_obeys_law), so that every optimal vertex
# of the LP — whichever one the pivot rule returns — passes that check by the rest: the decision
# is the LP's optimum's, never round-off's (docs/solvers.md, "A decision round-off cannot flip").
LP_SHARE = 0.5
# The previous step's split is reused when it leaves velocities below REUSE_TOL × the slip
# tolerance (round-off: 1e-12 |q|), so that a held body does not creep at the tolerance.
REUSE_TOL = 1e-3


@jit
def _pivot(T, basis, r, j, cols, factors):
    """Gauss–Jordan pivot of the tableau on (row r, column j): variable j enters the basis in row r.
    T is stored by columns (T[column, row], simplex_tableau), in place. Only the columns where the
    pivot row is non-zero are divided and updated (their indices gathered in `cols`, int64 scratch
    of the tableau's width): elsewhere the division leaves a zero and the update subtracts an exact
    zero. Each such column is one contiguous axpy over the rows, column −= (its pivot-row entry) ×
    the pivot column saved before the update (`factors`, float scratch of the tableau's height; 0
    at row r, which keeps its divided entry): the same product and difference for every entry as
    the row-wise update — the same bits — but vectorised where the row-wise loop gathered 17
    scattered columns from each of ~80 rows (the hold search's LPs: ~83 × 108, issue 26). A row
    whose pivot-column entry is 0 subtracts an exact zero."""
    pivot = T[j, r]
    n_cols = 0
    for col in range(T.shape[0]):
        if T[col, r] != 0.0:
            T[col, r] /= pivot
            cols[n_cols] = col
            n_cols += 1
    height = T.shape[1]
    for i in range(height):
        factors[i] = T[j, i]
    factors[r] = 0.0
    for k in range(n_cols):  # indexed, not a view of the column: a view counts a reference (an atomic
        col = cols[k]         # increment and decrement, a third of the pivot's time)
        entry = T[col, r]
        for i in range(height):
            T[col, i] -= factors[i] * entry
    basis[r] = j


@jit
def _set_objective(T, basis, cost):
    """Objective row of the tableau (T by columns): reduced costs cost_j − c_Bᵀ T[:, j] (last entry
    −objective value), subtracted row by row in the basis' order — only the rows whose basic
    variable has a cost (one in phase 1, the margin's two in the hold search's phase 2)."""
    m = T.shape[1] - 1
    for col in range(T.shape[0]):
        T[col, m] = cost[col] if col < cost.shape[0] else 0.0
    for i in range(m):
        cb = cost[basis[i]]
        if cb != 0.0:
            for col in range(T.shape[0]):
                T[col, m] -= cb * T[col, i]


@jit
def _run_simplex(T, basis, n_allowed, max_iter, cols, factors):
    """Maximise over the tableau (T by columns); columns ≥ n_allowed never enter. The entering
    column is Dantzig's (the largest reduced cost: about half the pivots of Bland's on the hold
    search's LPs, issue 26) except after a degenerate pivot (the ratio ≤ DEGENERATE), where it is
    Bland's (the lowest index) until the objective moves again: a cycle is made of degenerate pivots
    only, so each of its pivots would follow a degenerate one and be Bland's, which never cycles
    (from any basis). The leaving row: the least
    ratio, ties to the lowest basic index. Returns 0 optimal, 1 unbounded, 2 iteration limit."""
    m = T.shape[1] - 1
    rhs = T.shape[0] - 1  # the right-hand side's column
    bland = False
    for _ in range(max_iter):
        j = -1
        largest = PIVOT_TOL
        for col in range(n_allowed):
            if T[col, m] > largest:
                j = col
                if bland:
                    break
                largest = T[col, m]
        if j < 0:
            return 0
        r = np.int64(-1)  # not a literal: numba would compile _pivot for the literal −1 too
        best = np.inf
        for i in range(m):
            if T[j, i] > PIVOT_TOL:
                ratio = T[rhs, i] / T[j, i]
                if ratio < best - 1e-14 or (ratio <= best + 1e-14 and r >= 0 and basis[i] < basis[r]):
                    best = ratio
                    r = i
        if r < 0:
            return 1
        _pivot(T, basis, r, j, cols, factors)
        bland = best <= DEGENERATE
    return 2


@jit
def simplex_floats(m, n):
    """Floats simplex_in takes for m constraints on n unknowns: its tableau, cost row, c and the
    pivot's saved column."""
    return (m + 1) * (n + m + 2) + (n + m + 1) + n + (m + 1)


@jit
def simplex_ints(m, n):
    """int64s simplex_in takes: the basis and the pivot's column list."""
    return m + (n + m + 2)


@jit
def simplex_tableau(floats, ints, m, n):
    """(T, basis, cols, cost, c, factors) carved from scratch (simplex_floats, simplex_ints) for m
    constraints on n unknowns. T is stored by columns — T[column, row], n + m + 2 columns (the
    unknowns, the phase-1 column, the slacks, the right-hand side) of m + 1 rows (the constraints,
    the objective) — so that a pivot updates whole contiguous columns (_pivot). T is zero but for
    the phase-1 column (−1) and the slacks' identity, every slack basic; the caller writes G and h
    (T[:n, i], T[−1, i] for constraint i) and c."""
    T, at = carve_matrix(floats, 0, n + m + 2, m + 1)
    cost, at = carve(floats, at, n + m + 1)
    c, at = carve(floats, at, n)
    factors, at = carve(floats, at, m + 1)
    basis, at_int = carve(ints, 0, m)
    cols, at_int = carve(ints, at_int, n + m + 2)
    T[:, :] = 0.0
    for i in range(m):
        T[n, i] = -1.0
        T[n + 1 + i, i] = 1.0
        basis[i] = n + 1 + i
    return T, basis, cols, cost, c, factors


@jit
def simplex_max(c, G, h, x):
    """max cᵀx subject to G x ≤ h, x ≥ 0 (dense two-phase simplex, Dantzig's rule, Bland's after a
    degenerate pivot: _run_simplex).

    Phase 1 adds one auxiliary variable x_a (G x − x_a ≤ h, max −x_a) entered at the most
    violated row. Fills x; returns 0 optimal, 1 unbounded, 2 iteration limit, 3 infeasible.
    """
    m, n = G.shape
    floats, ints = np.empty(simplex_floats(m, n)), np.empty(simplex_ints(m, n), dtype=np.int64)
    T, basis, cols, cost, c_in, factors = simplex_tableau(floats, ints, m, n)
    h_largest = 0.0
    for i in range(m):
        for j in range(n):
            T[j, i] = G[i, j]
        T[n + m + 1, i] = h[i]
        h_largest = max(h_largest, abs(h[i]))
    c_in[:] = c
    return simplex_in(T, basis, cols, cost, c_in, factors, h_largest, x)


@jit
def simplex_in(T, basis, cols, cost, c, factors, h_largest, x):
    """simplex_max on a tableau simplex_tableau carved (T by columns) and the caller filled with G
    and h (h_largest: max |h|, for the phase-1 test). Allocates nothing."""
    m = T.shape[1] - 1
    n = c.shape[0]
    rhs = T[T.shape[0] - 1]
    max_iter = 50 * (n + m + 2)
    worst = np.int64(0)
    for i in range(m):
        if rhs[i] < rhs[worst]:
            worst = i
    cost[:] = 0.0
    if m > 0 and rhs[worst] < 0.0:
        cost[n] = -1.0
        _pivot(T, basis, worst, n, cols, factors)
        _set_objective(T, basis, cost)
        if _run_simplex(T, basis, n + m + 1, max_iter, cols, factors) != 0 or -rhs[m] < -1e-10 * (1.0 + h_largest):
            return 3
        for i in range(m):
            if basis[i] == n:  # degenerate: x_a = 0 basic; swap it for any usable column
                for j in range(n + m + 1):
                    if j != n and abs(T[j, i]) > PIVOT_TOL:
                        _pivot(T, basis, i, j, cols, factors)
                        break
        cost[n] = 0.0
    T[n, :] = 0.0  # the auxiliary variable is done with (or was never needed)
    cost[:n] = c
    _set_objective(T, basis, cost)
    status = _run_simplex(T, basis, n + m + 1, max_iter, cols, factors)
    x[:] = 0.0
    for i in range(m):
        if basis[i] < n:
            x[basis[i]] = rhs[i]
    return status


@jit
def _unknowns(mode, sign, mu_d):
    """P with p = P x: x holds p_N of every closed contact and p_T of the sticking (and free,
    loose) ones; a sliding contact's p_T is −μd s p_N. Also the equality rows E of the mode
    (u_N = 0 of closed contacts but loose ones, u_T = 0 of sticking ones)."""
    na = mode.shape[0]
    n_x, n_rows = 0, 0
    for i in range(na):
        if mode[i] != MODE_OPEN:
            n_x += 1 if mode[i] == MODE_SLIDE else 2
            n_rows += 2 if mode[i] == MODE_STICK else (0 if mode[i] == MODE_LOOSE else 1)
    P = np.zeros((2 * na, n_x))
    rows = np.empty(n_rows, dtype=np.int64)
    k, r = 0, 0
    for i in range(na):
        if mode[i] == MODE_OPEN:
            continue
        P[2 * i, k] = 1.0
        if mode[i] != MODE_LOOSE:
            rows[r] = 2 * i
            r += 1
        if mode[i] == MODE_SLIDE:
            P[2 * i + 1, k] = -mu_d[i] * sign[i]
            k += 1
            continue
        P[2 * i + 1, k + 1] = 1.0
        k += 2
        if mode[i] == MODE_STICK:
            rows[r] = 2 * i + 1
            r += 1
    return P, rows


@jit
def _frobenius(A):
    total = 0.0
    for i in range(A.shape[0]):
        for j in range(A.shape[1]):
            total += A[i, j] * A[i, j]
    return np.sqrt(total)


@jit
def _upper_inverse(R):
    """Inverse of the upper-triangular R by back substitution (entries below the diagonal are
    ignored); a zero pivot gives infinities, which fail the rank certificate."""
    m = R.shape[0]
    inv = np.zeros((m, m))
    for i in range(m):
        if not R[i, i] != 0.0:  # singular (or NaN): no inverse to form
            inv[:, :] = np.inf
            return inv
    for j in range(m):
        for i in range(j, -1, -1):
            total = 1.0 if i == j else 0.0
            for k in range(i + 1, j + 1):
                total -= R[i, k] * inv[k, j]
            inv[i, j] = total / R[i, i]
    return inv


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _full_row_rank_solution(A, b):
    """x0 and Z of _particular_and_null without the SVD, when A (m × n, m ≤ n) certainly has full row
    rank at RANK_TOL: (True, x0, Z), else (False, ·, ·) and the caller takes the SVD.

    Householder QR (LAPACK's, which never fails) of Aᵀ beside the identity, [Aᵀ | I] = Q [R₁₁ ·; 0 ·]:
    Aᵀ = Q₁ R₁₁ with Q₁ the first m columns of Q, and the last n − m columns of Q span A's null
    space (none for a square A: a mode that fixes the split, a row of balls). The certificate:
    σ_min(R₁₁) ≥ 1/‖R₁₁⁻¹‖_F and σ_max(R₁₁) ≤ ‖R₁₁‖_F, so ‖R₁₁‖_F ‖R₁₁⁻¹‖_F < 1/RANK_TOL means
    every singular value of A is above RANK_TOL × the largest — the SVD's rank would be m too. Then
    x0 = Q₁ R₁₁⁻ᵀ b is the SVD's minimum-norm solution to round-off, and Z spans the same null
    space in another orthonormal basis. A QR and a triangular inverse cost a fraction of LAPACK's
    SVD, which was 45 % of a row of 16's CPU (one per LP of the hold search)."""
    certain, Q1, R_inv_T, Z, sigma_min = _full_row_rank_parts(A)
    if not certain:
        return False, np.zeros(A.shape[1]), np.zeros((A.shape[1], 0))
    return True, Q1 @ (R_inv_T @ b), Z


@jit
def _full_row_rank_parts(A):
    """_full_row_rank_solution's factors: (certain, Q₁, R₁₁⁻ᵀ, Z, σ) with x0 = Q₁ (R₁₁⁻ᵀ b) for any b
    and σ = 1/‖R₁₁⁻¹‖_F ≤ σ_min(A) (the pruning LPs bound a bordered A's smallest singular value
    with it, `_pruning_split`)."""
    m, n = A.shape
    if m == 0 or m > n:
        return False, np.zeros((n, m)), np.zeros((m, m)), np.zeros((n, 0)), 0.0
    M = np.zeros((n, m + n))
    M[:, :m] = A.T
    for j in range(n):
        M[j, m + j] = 1.0
    Q, R = np.linalg.qr(M)
    R_inv = _upper_inverse(R[:m, :m])
    inverse_norm = _frobenius(R_inv)
    if not (_frobenius(R[:m, :m]) * inverse_norm < 1.0 / RANK_TOL):
        return False, np.zeros((n, m)), np.zeros((m, m)), np.zeros((n, 0)), 0.0
    return (True, np.ascontiguousarray(Q[:, :m]), np.ascontiguousarray(R_inv.T), np.ascontiguousarray(Q[:, m:]),
            1.0 / inverse_norm)


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _particular_and_null(A, b):
    """Least-squares x0 of A x = b (minimum norm) and an orthonormal basis Z of the null space of A
    (_full_row_rank_solution when it can vouch for A's rank, else the SVD)."""
    certain, x0, Z = _full_row_rank_solution(A, b)
    if certain:
        return x0, Z
    U, s, Vt = np.linalg.svd(A)
    n = A.shape[1]
    rank = 0
    for i in range(s.shape[0]):
        if s[i] > RANK_TOL * s[0]:
            rank += 1
    x0 = np.zeros(n)
    for i in range(rank):
        coef = 0.0
        for r in range(A.shape[0]):
            coef += U[r, i] * b[r]
        x0 += (coef / s[i]) * Vt[i, :]
    Z = np.ascontiguousarray(Vt[rank:, :].T)
    return x0, Z


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _admissible_constraints(u0, Wz, w_scale, mode, sign, mu_s, p0, Pz, velocity_tol, scale, G, h, weight):
    """Rows (G, h, weight) of  g0 + g·z ≥ weight·t  for every law the split must keep, in
    impulse units divided by `scale`: p_N ≥ t and μs p_N ∓ p_T ≥ t (weight 1, the margins);
    slip direction kept s u_T ≥ −tol/2 and open contacts u_N ≥ −tol/2 (weight 0, hard: LP_SHARE of
    the final check's tolerance, which an optimal vertex may sit on). u0 = W p0 + q,
    Wz = W Pz, w_scale = max |W|; written into G, h, weight (4 rows per contact at most), and
    returns how many rows."""
    na = mode.shape[0]
    k = Pz.shape[1]
    n = 0
    for i in range(na):
        if mode[i] == MODE_OPEN:  # velocities in impulse units: divided by max|W|
            _law_row(G, h, weight, n, Wz, 2 * i, 1.0, w_scale, u0[2 * i] + LP_SHARE * velocity_tol, 0.0)
            n += 1
            continue
        _law_row(G, h, weight, n, Pz, 2 * i, 1.0, 1.0, p0[2 * i], 1.0)
        n += 1
        if mode[i] == MODE_LOOSE:  # u_N ≥ −tol/2 in place of u_N = 0 (the margin pushes it to the
            # bound: LP_SHARE of it, so that round-off stays within the final check's)
            _law_row(G, h, weight, n, Wz, 2 * i, 1.0, w_scale, u0[2 * i] + LP_SHARE * velocity_tol, 0.0)
            n += 1
        if mode[i] == MODE_STICK or mode[i] == MODE_FREE or mode[i] == MODE_LOOSE:
            for side in (-1.0, 1.0):
                for j in range(k):
                    G[n, j] = mu_s[i] * Pz[2 * i, j] + side * Pz[2 * i + 1, j]
                h[n] = mu_s[i] * p0[2 * i] + side * p0[2 * i + 1]
                weight[n] = 1.0
                n += 1
        else:
            _law_row(G, h, weight, n, Wz, 2 * i + 1, sign[i], w_scale,
                     sign[i] * u0[2 * i + 1] + LP_SHARE * velocity_tol, 0.0)
            n += 1
    for r in range(n):
        for j in range(k):
            G[r, j] /= scale
        h[r] /= scale
    return n


@jit_inline
def _law_row(G, h, weight, n, rows, row, factor, divisor, value, row_weight):
    """Row n: G = factor · rows[row] / divisor (no product for a factor of 1), h = value / divisor."""
    for j in range(G.shape[1]):
        G[n, j] = (rows[row, j] if factor == 1.0 else factor * rows[row, j]) / divisor
    h[n] = value / divisor
    weight[n] = row_weight


@jit
def _fixed_split_margin(h, weight):
    """_deepest_split with no unknown z, in closed form: t = min(1, h_r / weight_r over the
    weighted rows), or −inf when a hard row (weight 0) is violated beyond simplex_max's phase-1
    tolerance 1e-10 (1 + max(|h|, 1)) — the optimum the simplex finds, without its tableau."""
    scale = 1.0
    for r in range(h.shape[0]):
        scale = max(scale, abs(h[r]))
    t = 1.0
    for r in range(h.shape[0]):
        if weight[r] > 0.0:
            t = min(t, h[r] / weight[r])
        elif h[r] < -1e-10 * (1.0 + scale):
            return -np.inf
    return t


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _deepest_split(G, h, weight, z, floats, ints):
    """max t subject to g0 + g·z ≥ weight·t, |z| ≤ SPLIT_BOUND, t ≤ 1 (z, t free; scaled units).
    Fills z and returns t (−inf when even the hard rows cannot hold). The LP's tableau is written
    straight into (floats, ints) when they hold it (lp_scratch), else into buffers of its own."""
    m, k = G.shape
    if k == 0:  # the mode fixes the split (a row of balls): no simplex (~0.6 ms on 54 rows)
        return _fixed_split_margin(h, weight)
    n = 2 * k + 2  # z = z⁺ − z⁻, t = t⁺ − t⁻
    rows = m + 2 * k + 1
    floats, ints = lp_scratch(floats, ints, rows, n)
    T, basis, cols, cost, c, factors = simplex_tableau(floats, ints, rows, n)  # T[column, row]
    rhs = T[n + rows + 1]
    h_largest = max(SPLIT_BOUND, 1.0)
    for r in range(m):  # −g·z + weight·t ≤ g0
        for j in range(k):
            T[j, r] = -G[r, j]
            T[k + j, r] = G[r, j]
        T[2 * k, r] = weight[r]
        T[2 * k + 1, r] = -weight[r]
        rhs[r] = h[r]
        h_largest = max(h_largest, abs(h[r]))
    for j in range(k):  # |z_j| ≤ SPLIT_BOUND: z⁺_j, z⁻_j ≤ SPLIT_BOUND
        T[j, m + 2 * j] = 1.0
        T[k + j, m + 2 * j + 1] = 1.0
        rhs[m + 2 * j] = SPLIT_BOUND
        rhs[m + 2 * j + 1] = SPLIT_BOUND
    T[2 * k, m + 2 * k] = 1.0  # t ≤ 1
    T[2 * k + 1, m + 2 * k] = -1.0
    rhs[m + 2 * k] = 1.0
    c[:] = 0.0
    c[2 * k] = 1.0
    c[2 * k + 1] = -1.0
    x, _ = carve(floats, simplex_floats(rows, n), n)
    if simplex_in(T, basis, cols, cost, c, factors, h_largest, x) != 0:
        return -np.inf
    for j in range(k):
        z[j] = x[j] - x[k + j]
    return x[2 * k] - x[2 * k + 1]


@jit
def lp_floats(rows, n):
    """Floats _deepest_split takes for an LP of `rows` constraints on n unknowns (the simplex's
    and the LP's solution)."""
    return simplex_floats(rows, n) + n


@jit
def lp_scratch(floats, ints, rows, n):
    """(floats, ints) when they hold _deepest_split's LP of `rows` constraints on n unknowns, else
    buffers of its own."""
    if floats.shape[0] >= lp_floats(rows, n) and ints.shape[0] >= simplex_ints(rows, n):
        return floats, ints
    return np.empty(lp_floats(rows, n)), np.empty(simplex_ints(rows, n), dtype=np.int64)


@jit
def _split_obeys_law(W, q, mode, sign, mu_s, p, u, velocity_tol, scale):
    """Does p (with u = W p + q) obey the mode within the tolerances? The final check, so that a
    split found along a nearly-null direction is never accepted on the LP's word alone."""
    p_tol = MARGIN_TOL * scale
    for i in range(mode.shape[0]):
        pn, pt, un, ut = p[2 * i], p[2 * i + 1], u[2 * i], u[2 * i + 1]
        if mode[i] == MODE_OPEN:
            if un < -velocity_tol:
                return False
            continue
        if pn < -p_tol or (un < -velocity_tol if mode[i] == MODE_LOOSE else abs(un) > velocity_tol):
            return False
        if mode[i] == MODE_STICK or mode[i] == MODE_FREE or mode[i] == MODE_LOOSE:
            if (mode[i] == MODE_STICK and abs(ut) > velocity_tol) or abs(pt) > mu_s[i] * pn + p_tol:
                return False
        elif sign[i] * ut < -velocity_tol:
            return False
    return True


def admissible_split(W, q, mu_s, mu_d, mode, sign, velocity_tol, scale, p_out):
    """The split of the step's impulses deepest inside every cone that keeps each contact in its
    mode (MODE_OPEN / MODE_STICK / MODE_SLIDE with slip sign `sign`), with normal
    complementarity (closed: u_N = 0, p_N ≥ 0; open: p = 0, u_N ≥ 0). Fills p_out and returns
    True when one exists within the tolerances, False otherwise (p_out then undefined).
    The search's compiled kernel with the loop's argument types, its scratch allocated here."""
    na = mode.shape[0]
    floats = np.empty(python_body(search_floats)(na))
    ints = np.empty(python_body(search_ints)(na), dtype=np.int64)
    return admissible_split_in(loop_array(W), loop_array(q), loop_array(mu_s), loop_array(mu_d),
                               loop_array(mode, np.int64), loop_array(sign), float(velocity_tol), float(scale), p_out,
                               floats, ints)


@jit
def admissible_split_in(W, q, mu_s, mu_d, mode, sign, velocity_tol, scale, p_out, floats, ints):
    """admissible_split with the LP's temporaries in (floats, ints) (search_scratch)."""
    P, rows = _unknowns(mode, sign, mu_d)
    if P.shape[1] == 0:
        return False
    A = np.ascontiguousarray((W @ P)[rows, :])
    b = -q[rows]
    x0, Z = _particular_and_null(A, b)
    return _deepest_admissible(W, q, mu_s, mode, sign, P @ x0, np.ascontiguousarray(P @ Z), velocity_tol, scale,
                               p_out, max(1e-300, _max_abs(W)), floats, ints)


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def search_floats(na):
    """Floats one hold search on na contacts takes (a held-set trial's own, then
    _deepest_admissible's with up to 2 na unknowns z): allocated once per search, carved by each LP."""
    return 3 * BORDER_MAX * BORDER_MAX + 2 * BORDER_MAX + 5 * 2 * na + _admissible_floats(na, 2 * na)


@jit
def _admissible_floats(na, k):
    """Floats _deepest_admissible carves for na contacts and k unknowns z (W p0 + q, W p + q, W Pz,
    the LP's rows G, h, weight, z, and the LP's own)."""
    return 4 * na + 2 * na * k + 4 * na * (k + 2) + k + lp_floats(4 * na + 2 * k + 1, 2 * k + 2)


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def search_ints(na):
    """int64s one hold search on na contacts takes (a trial's and the LP's)."""
    k = 2 * na
    return 2 * BORDER_MAX + simplex_ints(4 * na + 2 * k + 1, 2 * k + 2)


@jit
def search_scratch(na):
    """(floats, ints) for one hold search on na contacts."""
    return np.empty(search_floats(na)), np.empty(search_ints(na), dtype=np.int64)


@jit
def _deepest_admissible(W, q, mu_s, mode, sign, p0, Pz, velocity_tol, scale, p_out, w_scale, floats, ints):
    """admissible_split once the mode's equations are solved: the split p0 + Pz z deepest inside
    every cone (no simplex when Pz has no column), checked against the law. w_scale: max |W|, or
    1e-300 (the search's, computed once). Its temporaries are carved from (floats, ints)
    (search_scratch, or buffers of its own when they are too small)."""
    m2, k, na = W.shape[0], Pz.shape[1], mode.shape[0]
    if floats.shape[0] < _admissible_floats(na, k) or ints.shape[0] < simplex_ints(4 * na + 2 * k + 1, 2 * k + 2):
        floats = np.empty(_admissible_floats(na, k))
        ints = np.empty(simplex_ints(4 * na + 2 * k + 1, 2 * k + 2), dtype=np.int64)
    u0, at = carve(floats, 0, m2)
    u, at = carve(floats, at, m2)
    Wz, at = carve_matrix(floats, at, m2, k)
    G, at = carve_matrix(floats, at, 4 * na, k)
    h, at = carve(floats, at, 4 * na)
    weight, at = carve(floats, at, 4 * na)
    z, at = carve(floats, at, k)
    _matrix_vector(W, p0, q, u0)  # u0 = W p0 + q
    if k > 0:
        np.dot(W, Pz, Wz)
    n = _admissible_constraints(u0, Wz, w_scale, mode, sign, mu_s, p0, Pz, velocity_tol, scale, G, h, weight)
    margin = _deepest_split(G[:n], h[:n], weight[:n], z, floats[at:], ints)
    if margin < -LP_SHARE * MARGIN_TOL:
        return False
    if k == 0:  # the split is p0 itself, and u = W p0 + q is u0 (bit for bit: p0 + 0 is p0)
        for i in range(m2):
            p_out[i] = p0[i] + 0.0
        return _split_obeys_law(W, q, mode, sign, mu_s, p_out, u0, velocity_tol, scale)
    np.dot(Pz, z, u0)
    for i in range(m2):
        p_out[i] = p0[i] + u0[i]
    _matrix_vector(W, p_out, q, u)
    return _split_obeys_law(W, q, mode, sign, mu_s, p_out, u, velocity_tol, scale)


@jit
def _matrix_vector(A, x, b, out):
    """out = A x + b (A x by BLAS, as `A @ x + b`), allocating nothing."""
    np.dot(A, x, out)
    for i in range(out.shape[0]):
        out[i] += b[i]


@jit
def _max_abs(A):
    """max |A_ij| (np.max(np.abs(A)) without the temporary)."""
    largest = 0.0
    for i in range(A.shape[0]):
        for j in range(A.shape[1]):
            largest = max(largest, abs(A[i, j]))
    return largest


@jit
def _resting_contacts(start_guess, p, u, closing, states, velocity_tol, candidates, release, moving_only):
    """Contacts that started the step at rest (guess 0) and either touch at its end (u_N = 0, or u_N
    equal to the gap-closing velocity) or left it (open, u_N > 0): the step's choice among its
    admissible solutions is a choice of which of them stick. `release` gets what each does when not
    held: slide its own slip direction (±1), or for a sticking one the direction its friction
    opposes, or separate (0: an open one). A sticking contact with no friction has no direction
    and is not a candidate; `moving_only`: only the sliding ones (the search of a large group).
    Returns how many; 0 when all of them stick (the solver's answer holds them all)."""
    n, moving = 0, False
    for i in range(start_guess.shape[0]):
        if start_guess[i] != 0.0:
            continue
        touching = abs(u[2 * i]) <= velocity_tol or abs(u[2 * i] - closing[i]) <= velocity_tol
        if not touching and states[i] == STATE_OPEN and not moving_only:
            release[n] = 0.0
            moving = True
        elif not touching:
            continue
        elif abs(u[2 * i + 1]) > velocity_tol:
            release[n] = 1.0 if u[2 * i + 1] > 0.0 else -1.0
            moving = True
        elif p[2 * i + 1] != 0.0 and not moving_only:
            release[n] = -1.0 if p[2 * i + 1] > 0.0 else 1.0
        else:
            continue
        candidates[n] = i
        n += 1
    return n if moving else 0


@jit
def _modes_for(held_mask, candidates, release, n_candidates, u, states, mode, sign, others_free):
    """Mode of every contact when the candidates in `held_mask` stick and the others slide their
    `release` way or open (or, `others_free`, are free: MODE_FREE); the rest keep their state
    (stick, slide, open)."""
    for i in range(states.shape[0]):
        sign[i] = 0.0
        if states[i] == STATE_STICK:
            mode[i] = MODE_STICK
        elif states[i] == STATE_SLIP_PLUS or states[i] == STATE_SLIP_MINUS:
            mode[i] = MODE_SLIDE
            sign[i] = 1.0 if u[2 * i + 1] > 0.0 else -1.0
        else:
            mode[i] = MODE_OPEN
    for c in range(n_candidates):
        i = candidates[c]
        if (held_mask >> c) & 1:
            mode[i] = MODE_STICK
            sign[i] = 0.0
        elif others_free:
            mode[i] = MODE_LOOSE if release[c] == 0.0 else MODE_FREE
            sign[i] = 0.0
        elif release[c] == 0.0:
            mode[i] = MODE_OPEN
        else:
            mode[i] = MODE_SLIDE
            sign[i] = release[c]


@jit
def _binomial(n, k):
    """n choose k (n ≤ 62: the candidates' bit mask)."""
    value = 1
    for i in range(min(k, n - k)):
        value = value * (n - i) // (i + 1)
    return value


@jit
def _popcount(mask):
    count = 0
    while mask:
        count += mask & 1
        mask >>= 1
    return count


@jit
def _write_solution(W, q, mode, p_new, velocity_tol, p, u, states):
    """Overwrite p, u and the int64 state codes with the held solution."""
    p[:] = p_new
    u[:] = W @ p_new + q
    for i in range(mode.shape[0]):
        if mode[i] == MODE_OPEN:
            states[i] = STATE_OPEN
        elif mode[i] == MODE_STICK or abs(u[2 * i + 1]) <= velocity_tol:
            states[i] = STATE_STICK
        else:
            states[i] = STATE_SLIP_PLUS if u[2 * i + 1] > 0.0 else STATE_SLIP_MINUS


@jit
def _without_gap_closing(q, closing, mode, q_held):
    """q with the gap-closing part of the normal rows of closed contacts removed: a held body
    does not chase gaps of position round-off (they need not be mutually consistent)."""
    q_held[:] = q
    for i in range(mode.shape[0]):
        if mode[i] != MODE_OPEN:
            q_held[2 * i] -= closing[i]


def prefer_sticking(W, q, mu_s, mu_d, start_guess, velocity_tol, closing, p, u, states):
    """prefer_sticking_from without a previous split: Python runs the loop's compiled kernel with the
    loop's argument types (_common.loop_array; p, u, states are filled in place)."""
    return prefer_sticking_from(loop_array(W), loop_array(q), loop_array(mu_s), loop_array(mu_d),
                                loop_array(start_guess), float(velocity_tol), loop_array(closing), p, u, states,
                                np.zeros(0))


@jit
def prefer_sticking_from(W, q, mu_s, mu_d, start_guess, velocity_tol, closing, p, u, states, p_start):
    """Hold what μs can hold, and choose among the step's admissible solutions independently of
    the order of the contacts: overwrite p, u, states in place with the chosen solution and return
    True, or return False and leave the solver's answer.

    W (m×m), q (m,), p, u (m,) float64 with m = 2 na ordered (N, T) per contact; mu_s, mu_d,
    start_guess (na,) float64 — start_guess is the slip guess the step STARTED from (0 at rest,
    ±1 sliding), not the converged one; velocity_tol: the velocity below which a slip is zero
    (the sign iteration's); closing (na,) float64: the part g/h of q_N that asks a persistent
    contact to close an open gap (0 if none) — a held mode may instead leave it open;
    states (na,) int64: 0 open, 1 stick, 2 slip+, 3 slip−; p_start (m,) or empty: the previous
    step's impulses — when they still hold every candidate to round-off (a body held at rest:
    the same problem again) they are the answer, without an LP.

    Runs when a contact that started at rest slides or lifts off. Candidates: the contacts that
    started at rest and touch, or lifted off (`_resting_contacts`); S is admissible when a split
    sticks S and releases the others (admissible_split). All held first (`_all_held`); else each
    candidate is tried held with the others free (MODE_FREE, MODE_LOOSE: a relaxation of every
    mode that holds it; one that fails is in no held set and is dropped); then `held_set`: the
    largest admissible S if it is the only one of its size, else the search goes on below the tied
    sets' intersection — never contact order. At most MAX_TRIALS tries. No moving candidate left by the
    pruning: every held set is within the solver's own, whose answer stands without a search. Beyond MAX_CANDIDATES
    candidates (a large pile) only the sliding ones are searched (order-dependent, but no LPs on
    the whole group in every step where a contact lifts).
    """
    na = mu_s.shape[0]
    candidates = np.empty(na, dtype=np.int64)
    release = np.empty(na)
    n_c = _resting_contacts(start_guess, p, u, closing, states, velocity_tol, candidates, release, False)
    if n_c > MAX_CANDIDATES:  # too many for the whole choice: only hold what slides (order-dependent)
        n_c = _resting_contacts(start_guess, p, u, closing, states, velocity_tol, candidates, release, True)
    if n_c == 0:
        return False
    w_max = max(1e-300, np.max(np.abs(W)))
    scale = max(np.max(np.abs(p)), np.max(np.abs(q)) / w_max)
    if scale <= 0.0:
        return False
    mode, sign, p_new, q_held = np.zeros(na, dtype=np.int64), np.zeros(na), np.zeros(2 * na), np.empty(2 * na)
    floats, ints = search_scratch(na)  # every LP's temporaries, carved
    n_c = min(n_c, 62)  # a bit mask of the candidates
    if _all_held(W, q, q_held, closing, mu_s, mu_d, candidates, release, n_c, u, states, mode, sign, velocity_tol,
                 scale, p_start, p_new, floats, ints):
        _write_solution(W, q, mode, p_new, velocity_tol, p, u, states)
        return True
    if n_c == 1:  # the one candidate cannot be held: the only other set, none, is the solver's own
        return False
    relaxed = _relaxed_base(W, mu_d, candidates, release, n_c, u, states, mode, sign, floats, ints)
    kept = _prune(relaxed, W, q, q_held, closing, mu_s, mu_d, candidates, release, n_c, u, states, mode, sign,
                  velocity_tol, scale, p_new, floats, ints)
    if _sticking_mask(candidates, kept, states) == (1 << kept) - 1:
        return False  # no moving candidate can be held: every held set is within the solver's own
    n_c = min(kept, MAX_CANDIDATES)
    held = held_set(relaxed, W, q, q_held, closing, mu_s, mu_d, candidates, release, n_c, u, states, mode, sign,
                    velocity_tol, scale, p_new, floats, ints)
    if held < 0 or held == _sticking_mask(candidates, n_c, states):
        return False  # nothing admissible, or the solver's own mode (its velocities are the mode's)
    _write_solution(W, q, mode, p_new, velocity_tol, p, u, states)
    return True


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _all_held(W, q, q_held, closing, mu_s, mu_d, candidates, release, n_c, u, states, mode, sign, velocity_tol,
              scale, p_start, p_new, floats, ints):
    """Is every candidate held admissible (then the one largest set: the common step of a body at
    rest)? The previous step's split p_start, when it still holds them to round-off, is the answer
    without an LP. Fills mode, sign and p_new."""
    _modes_for((1 << n_c) - 1, candidates, release, n_c, u, states, mode, sign, False)
    if p_start.shape[0] == p_new.shape[0] and _split_obeys_law(W, q, mode, sign, mu_s, p_start, W @ p_start + q,
                                                               REUSE_TOL * velocity_tol, scale):
        p_new[:] = p_start
        return True
    return _admissible_either(W, q, q_held, closing, mu_s, mu_d, mode, sign, velocity_tol, scale, p_new, floats, ints)


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _prune(relaxed, W, q, q_held, closing, mu_s, mu_d, candidates, release, n_c, u, states, mode, sign, velocity_tol,
           scale, p_new, floats, ints):
    """Keep (moved to the front of candidates, release) the candidates that can be held with the
    other candidates free, and return how many: one the solver holds needs no test (its answer is
    a split of the relaxation, `relaxed`: _relaxed_base); each other costs one LP."""
    kept = 0
    no_trials = _no_trials()
    for c in range(n_c):
        _modes_for(1 << c, candidates, release, n_c, u, states, mode, sign, True)
        added = np.array([2 * candidates[c] + 1]) if release[c] != 0.0 else \
            np.array([2 * candidates[c], 2 * candidates[c] + 1])
        if states[candidates[c]] == STATE_STICK or _shared_either(
                relaxed, added, no_trials, -1, W, q, q_held, closing, mu_s, mu_d, mode, sign, velocity_tol, scale,
                p_new, floats, ints):
            candidates[kept], release[kept] = candidates[c], release[c]
            kept += 1
    return kept


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _relaxed_base(W, mu_d, candidates, release, n_c, u, states, mode, sign, floats, ints):
    """What the pruning LPs of one search share (issue 26: each was a QR of the whole group). The
    relaxation with every candidate free (MODE_FREE, MODE_LOOSE) has the unknowns of every pruning
    LP — holding candidate c only adds its rows u_T = 0 (and u_N = 0 for one that lifts) — so its
    equations A_f x = b_f are factored once: the solutions of a pruning LP's are x_f + Z_f w with
    R_c Z_f w = b_c − R_c x_f, R_c the added rows (1 or 2). Returns (certain, P, rows, W P, Q₁,
    R₁₁⁻ᵀ, Z_f, σ, ‖A_f‖²_F, max |W|, floats, ints) — certain False when A_f's full row rank is
    not vouched for; (floats, ints): the search's scratch (search_scratch), which its LPs carve."""
    _modes_for(0, candidates, release, n_c, u, states, mode, sign, True)
    P, rows = _unknowns(mode, sign, mu_d)
    WP = W @ P
    A = np.ascontiguousarray(WP[rows, :])
    certain, Q1, R_inv_T, Z, sigma_min = _full_row_rank_parts(A)
    return certain, P, rows, WP, Q1, R_inv_T, Z, sigma_min, np.sum(A ** 2), max(1e-300, _max_abs(W)), floats, ints


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _pruning_split(relaxed, added, W, q, mu_s, mode, sign, velocity_tol, scale, p_out):
    """admissible_split of a pruning LP (mode and sign its own: one candidate held, the others
    free) on the shared relaxation: 1 admissible, 0 not, −1 not vouched for (the caller takes
    admissible_split). With M = R_c Z_f of full row rank (its own QR certificate), the LP's matrix
    A_c = [A_f; R_c] has σ_min ≥ σ_M σ_f / (σ_f + ‖R_c‖_F + σ_M) (split a unit y into its parts on
    A_f's rows and R_c's), so ‖A_c‖_F over that bound below 1/RANK_TOL means the SVD would find
    A_c of full row rank too: both ways then have the same solutions x0 + Z z of the mode's
    equations (Z = Z_f N orthonormal, N spanning M's null space) and the same deepest margin."""
    certain, P, rows, WP, Q1, R_inv_T, Z_f, sigma_f, a_f2, w_scale, floats, ints = relaxed
    if not certain:
        return -1
    b_f = np.empty(rows.shape[0])
    for r in range(rows.shape[0]):
        b_f[r] = -q[rows[r]]
    x_f = Q1 @ (R_inv_T @ b_f)
    R = np.ascontiguousarray(WP[added, :])
    r_c = np.empty(added.shape[0])
    for a in range(added.shape[0]):
        r_c[a] = -q[added[a]] - np.dot(R[a, :], x_f)
    certain_m, Q1_m, R_inv_T_m, N, sigma_m = _full_row_rank_parts(np.ascontiguousarray(R @ Z_f))
    r_f = _frobenius(R)
    if not certain_m or not (np.sqrt(a_f2 + r_f * r_f) * (sigma_f + r_f + sigma_m) < sigma_m * sigma_f / RANK_TOL):
        return -1
    x0 = x_f + Z_f @ (Q1_m @ (R_inv_T_m @ r_c))
    Z = np.ascontiguousarray(Z_f @ N)
    return 1 if _deepest_admissible(W, q, mu_s, mode, sign, P @ x0, np.ascontiguousarray(P @ Z), velocity_tol,
                                    scale, p_out, w_scale, floats, ints) else 0


@jit
def _shared_either(relaxed, added, trials, held, W, q, q_held, closing, mu_s, mu_d, mode, sign, velocity_tol, scale,
                   p_new, floats, ints):
    """admissible_split of one LP of the search (mode and sign its own) through the factorization
    its search shares where that is vouched for, else the general way: a pruning LP (held < 0: the
    candidate whose rows are `added`, on the relaxation, _pruning_split) or a held-set trial (held:
    the mask of the held candidates, on the bordered base, _bordered_split). When the step's q
    admits no split, the same for q without its gap-closing part (_admissible_either's rule)."""
    for attempt in range(2):
        if attempt == 1:
            if np.max(closing) <= 0.0:
                return False
            _without_gap_closing(q, closing, mode, q_held)
        rhs = q if attempt == 0 else q_held
        if held < 0:
            found = _pruning_split(relaxed, added, W, rhs, mu_s, mode, sign, velocity_tol, scale, p_new)
        else:
            found = _bordered_split(trials, held, W, rhs, mu_s, mode, sign, velocity_tol, scale, p_new)
        if found < 0:
            found = 1 if admissible_split_in(W, rhs, mu_s, mu_d, mode, sign, velocity_tol, scale, p_new, floats,
                                             ints) else 0
        if found == 1:
            return True
    return False


@jit
def _sticking_mask(candidates, n_c, states):
    """The candidates the solver's answer holds, as a bit mask."""
    mask = 0
    for c in range(n_c):
        if states[candidates[c]] == STATE_STICK:
            mask |= 1 << c
    return mask


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def held_set(relaxed, W, q, q_held, closing, mu_s, mu_d, candidates, release, n_c, u, states, mode, sign,
             velocity_tol, scale, p_new, floats, ints):
    """The held set of prefer_sticking as a bit mask over the candidates (mode, sign and p_new
    filled for it), or −1 when none is admissible or the trials run out. Largest first; a size
    with one admissible set returns it; a size with several restricts the search to the subsets of
    their intersection (strictly smaller), so a tie is never broken by contact order. A size whose
    sets would not all fit in the trials left ends the search at once: it ran out within that size
    anyway (a size is decided only once all its sets are tried), so the answer is the same −1,
    without its LPs (the row of 16's wave: 8 candidates kept, 37 trials instead of 64)."""
    allowed = (1 << n_c) - 1
    trials = 0
    p_found = np.empty_like(p_new)
    shared = _bordered_trials(W, mu_d, candidates, release, n_c, u, states, mode, sign, floats, ints)
    added = np.zeros(0, dtype=np.int64)
    while True:
        found, n_found, common = -1, 0, allowed
        for size in range(_popcount(allowed), -1, -1):
            if trials + _binomial(_popcount(allowed), size) > MAX_TRIALS:
                return -1  # the trials would run out within this size: the same −1, without its LPs
            for held in range(allowed + 1):
                if held & ~allowed or _popcount(held) != size:
                    continue
                if trials == MAX_TRIALS:
                    return -1
                trials += 1
                _modes_for(held, candidates, release, n_c, u, states, mode, sign, False)
                if _shared_either(relaxed, added, shared, held, W, q, q_held, closing, mu_s, mu_d, mode, sign,
                                  velocity_tol, scale, p_new, floats, ints):
                    found, n_found, common = held, n_found + 1, common & held
                    p_found[:] = p_new
            if n_found > 0:
                break
        if n_found == 0:
            return -1
        if n_found == 1:
            _modes_for(found, candidates, release, n_c, u, states, mode, sign, False)
            p_new[:] = p_found
            return found
        allowed = common


@jit
def _small_inverse(S, s, LU, rows, inverse):
    """inverse = S⁻¹ of the leading s × s block of S (the package's LU, kernel_base.lu_factor: in
    LU and rows, scratch), allocating nothing; infinities when a pivot is zero (they fail the
    certificate of _bordered_split)."""
    for i in range(s):
        for j in range(s):
            LU[i, j] = S[i, j]
    if not lu_factor(LU, s, rows, 0.0):
        inverse[:, :] = np.inf
        return
    for j in range(s):
        column = inverse[j]  # row j of the inverse's transpose: the solution for the jth unit vector
        column[:] = 0.0
        column[j] = 1.0
        lu_solve(LU, s, rows, column)
    for i in range(s):  # transpose in place
        for j in range(i + 1, s):
            inverse[i, j], inverse[j, i] = inverse[j, i], inverse[i, j]


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _no_trials():
    """A _bordered_trials tuple that vouches for no trial (the pruning LPs' placeholder)."""
    empty, none = np.zeros((0, 0)), np.zeros(0, dtype=np.int64)
    return (False, empty, none, none, none, empty, empty, empty, empty, empty, empty, np.zeros(4), np.zeros(0), none)


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _inverse_by_qr(A):
    """A⁻¹ = R⁻¹ Qᵀ (LAPACK's QR, which never fails; infinities for a zero pivot of R)."""
    if A.shape[0] == 0:
        return np.zeros((0, 0))
    Q, R = np.linalg.qr(A)
    return _upper_inverse(R) @ np.ascontiguousarray(Q.T)


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _bordered_trials(W, mu_d, candidates, release, n_c, u, states, mode, sign, floats, ints):
    """What every held-set trial of one search shares, factored once (issue 26: the row of 16's
    trials were each a fresh QR of the whole mode, 80 % of their cost). The base is the mode with
    every candidate released; holding candidate c adds to it the unknown p_T of c (p_T = −μd s p_N
    + δ) and the row u_T = 0 (one that lifts: p_N and p_T, u_N = 0 and u_T = 0): a trial's
    equations are the base's bordered by its held candidates' entries `ext` (an unknown's entry of
    p and a row's of u — the same indices). So with A0 the base's square matrix, B its columns in the
    added directions, C the added rows and D their block, the trial solves through the Schur
    complement S = D − C A0⁻¹ B restricted to its entries (at most 2 × 16). Returns the tuple
    _bordered_split reads, the search's scratch (floats, ints: search_scratch) last; its first entry
    False when the base is not square (a base with freedom in its split: every trial goes the
    general way)."""
    _modes_for(0, candidates, release, n_c, u, states, mode, sign, False)
    P0, rows0 = _unknowns(mode, sign, mu_d)
    n_ext = 0
    for c in range(n_c):
        n_ext += 2 if release[c] == 0.0 else 1
    ext, owner = np.empty(n_ext, dtype=np.int64), np.empty(n_ext, dtype=np.int64)
    e = 0
    for c in range(n_c):
        if release[c] == 0.0:
            ext[e], owner[e] = 2 * candidates[c], c
            e += 1
        ext[e], owner[e] = 2 * candidates[c] + 1, c
        e += 1
    n0 = P0.shape[1]
    WP0 = W @ P0
    A0 = np.zeros((n0, n0))
    B = np.zeros((n0, n_ext))
    for r in range(min(n0, rows0.shape[0])):
        A0[r, :] = WP0[rows0[r], :]
        for e in range(n_ext):
            B[r, e] = W[rows0[r], ext[e]]
    C = np.zeros((n_ext, n0))
    D = np.zeros((n_ext, n_ext))
    for e in range(n_ext):
        C[e, :] = WP0[ext[e], :]
        for f in range(n_ext):
            D[e, f] = W[ext[e], ext[f]]
    A0_inv = _inverse_by_qr(A0)
    Y, X = A0_inv @ B, C @ A0_inv
    norms = np.zeros((4, n_ext))  # ‖B e‖², ‖C e‖², ‖Y e‖², ‖X e‖² of each added entry
    for e in range(n_ext):
        norms[0, e], norms[1, e] = np.sum(B[:, e] ** 2), np.sum(C[e, :] ** 2)
        norms[2, e], norms[3, e] = np.sum(Y[:, e] ** 2), np.sum(X[e, :] ** 2)
    ok = n0 > 0 and rows0.shape[0] == n0 and np.all(np.isfinite(A0_inv))
    return (ok, P0, rows0, ext, owner, A0_inv, Y, C, D - C @ Y, D, norms,
            np.array([np.sum(A0 ** 2), _frobenius(A0_inv), 1.5 * (1.0 + np.max(mu_d) ** 2), max(1e-300, _max_abs(W))]),
            floats, ints)


@jit
def _bordered_solve(trials, chosen, S_inv, minus_rhs, p_out, b0, y, r_e, delta, Py):
    """p_out += the solution of the trial's equations (rows of u = W p + q: base rows and `chosen`
    added entries) for the right-hand side −minus_rhs (an entry per row of u): y = A0⁻¹ b0,
    δ = S⁻¹ (b_e − C y), x = y − A0⁻¹B δ; p = P0 x + Σ δ_e at the added entries. b0, y, r_e,
    delta, Py: scratch (the base's rows, its unknowns, the chosen entries twice, p's length)."""
    P0, rows0, ext, A0_inv, Y, C = trials[1], trials[2], trials[3], trials[5], trials[6], trials[7]
    for r in range(rows0.shape[0]):
        b0[r] = -minus_rhs[rows0[r]]
    np.dot(A0_inv, b0, y)
    s = chosen.shape[0]
    for a in range(s):
        r_e[a] = -minus_rhs[ext[chosen[a]]] - np.dot(C[chosen[a], :], y)
    np.dot(S_inv, r_e, delta)
    for a in range(s):
        for i in range(y.shape[0]):
            y[i] -= delta[a] * Y[i, chosen[a]]
    np.dot(P0, y, Py)
    for i in range(Py.shape[0]):
        p_out[i] += Py[i]
    for a in range(s):
        p_out[ext[chosen[a]]] += delta[a]


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _bordered_split(trials, held, W, q, mu_s, mode, sign, velocity_tol, scale, p_out):
    """admissible_split of the trial holding the candidates in `held` (mode and sign already its
    own) through the shared factorization: 1 admissible, 0 not, −1 not certified (the caller
    takes admissible_split). Certified when ‖K‖_F ‖K⁻¹‖_F of the trial's bordered matrix K, the
    inverse bounded block by block (K⁻¹ = [A0⁻¹ + Y S⁻¹ X, −Y S⁻¹; −S⁻¹ X, S⁻¹], Y = A0⁻¹B,
    X = C A0⁻¹), times the change of basis from (p_N, p_T) to (p_N, δ) stays below 1/RANK_TOL: K
    then has full rank at the SVD's threshold in admissible_split's unknowns too, so the mode fixes
    the split and both ways find the same unique one, to round-off (one step of iterative
    refinement on the residual of its equations). Its temporaries come from the search's scratch."""
    ok, P0, rows0, ext, owner, A0_inv, Y, C, S_all, D, norms, scalars, floats, ints = trials
    if not ok:
        return -1
    m2, n0 = q.shape[0], A0_inv.shape[0]
    chosen_all, at_int = carve(ints, 0, BORDER_MAX)
    rows, at_int = carve(ints, at_int, BORDER_MAX)
    s = 0
    for e in range(owner.shape[0]):
        if (held >> owner[e]) & 1:
            chosen_all[s] = e
            s += 1
    chosen = chosen_all[:s]
    S, at = carve_matrix(floats, 0, s, s)
    LU, at = carve_matrix(floats, at, s, s)
    S_inv, at = carve_matrix(floats, at, s, s)
    r_e, at = carve(floats, at, s)
    delta, at = carve(floats, at, s)
    b0, at = carve(floats, at, n0)
    y, at = carve(floats, at, n0)
    p0, at = carve(floats, at, m2)
    residual, at = carve(floats, at, m2)
    work, at = carve(floats, at, m2)
    no_z, at = carve_matrix(floats, at, m2, 0)  # Pz of a mode that fixes the split: no column
    k2, y2, x2 = scalars[0], 0.0, 0.0
    for a in range(s):
        e = chosen[a]
        block = 0.0
        for b in range(s):
            S[a, b] = S_all[e, chosen[b]]
            block += D[e, chosen[b]] ** 2
        k2 += norms[0, e] + norms[1, e] + block
        y2, x2 = y2 + norms[2, e], x2 + norms[3, e]
    _small_inverse(S, s, LU, rows, S_inv)
    s_f = _frobenius(S_inv)
    inv_bound = scalars[1] + s_f * (np.sqrt(y2 * x2) + np.sqrt(y2) + np.sqrt(x2) + 1.0)
    if not (np.sqrt(k2) * inv_bound * scalars[2] < 1.0 / RANK_TOL):
        return -1
    p0[:] = 0.0
    _bordered_solve(trials, chosen, S_inv, q, p0, b0, y, r_e, delta, work)
    _matrix_vector(W, p0, q, residual)  # refinement: the residual's correction
    _bordered_solve(trials, chosen, S_inv, residual, p0, b0, y, r_e, delta, work)
    return 1 if _deepest_admissible(W, q, mu_s, mode, sign, p0, no_z, velocity_tol, scale, p_out, scalars[3],
                                    floats[at:], ints) else 0


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _admissible_either(W, q, q_held, closing, mu_s, mu_d, mode, sign, velocity_tol, scale, p_new, floats, ints):
    """admissible_split of the mode for the step's q, or else (a held body need not chase gaps of
    position round-off) for q without its gap-closing part."""
    if admissible_split_in(W, q, mu_s, mu_d, mode, sign, velocity_tol, scale, p_new, floats, ints):
        return True
    if np.max(closing) <= 0.0:
        return False
    _without_gap_closing(q, closing, mode, q_held)
    return admissible_split_in(W, q_held, mu_s, mu_d, mode, sign, velocity_tol, scale, p_new, floats, ints)


@jit
def gather_contacts(members, x, pairs):
    """x at the group's contacts (pairs: two entries per contact, N and T)."""
    out = np.empty(members.shape[0] * (2 if pairs else 1), dtype=x.dtype)
    for a in range(members.shape[0]):
        if pairs:
            out[2 * a], out[2 * a + 1] = x[2 * members[a]], x[2 * members[a] + 1]
        else:
            out[a] = x[members[a]]
    return out


@jit
def scatter_contacts(members, p_group, u_group, states_group, p, u, states):
    """Write a group's p, u (two entries per contact) and states back at its contacts."""
    for a in range(members.shape[0]):
        i = members[a]
        p[2 * i], p[2 * i + 1] = p_group[2 * a], p_group[2 * a + 1]
        u[2 * i], u[2 * i + 1] = u_group[2 * a], u_group[2 * a + 1]
        states[i] = states_group[a]


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def prefer_sticking_by_group(W, indptr, indices, blocks, q, mu_s, mu_d, start_guess, velocity_tol, closing, p, u,
                             states, max_group, p_start):
    """prefer_sticking on each group of coupled contacts alone (coupled_components). The step's
    problem is block-diagonal over the groups, so the largest held set of the whole step is the
    union of each group's, and each search is over its own candidates: 2^n_g small dense LPs
    rather than 2^(Σ n_g) large ones. Only groups with a contact that started at rest and does
    not stick (start_guess 0) are searched, and only those of at most `max_group` contacts.
    W is dense, or empty with its block-sparse form; p_start: the previous step's impulses, or
    empty. True when any p, u, states changed."""
    na = mu_s.shape[0]
    label = np.empty(na, dtype=np.int64)
    groups = coupled_components(indptr, indices, W, label)
    if groups == 1 and W.shape[0] > 0:  # one dense group (the common case): nothing to gather
        return na <= max_group and prefer_sticking_from(W, q, mu_s, mu_d, start_guess, velocity_tol, closing, p,
                                                        u, states, p_start)
    changed = False
    for g in range(groups):
        members = np.flatnonzero(label == g)
        wanted = False
        for i in members:
            wanted = wanted or (start_guess[i] == 0.0 and states[i] != STATE_STICK)
        if not wanted or members.shape[0] > max_group:
            continue
        pg, ug = gather_contacts(members, p, True), gather_contacts(members, u, True)
        states_g = gather_contacts(members, states, False)
        start_g = gather_contacts(members, p_start, True) if p_start.shape[0] == p.shape[0] else np.zeros(0)
        if prefer_sticking_from(group_matrix(members, W, indptr, indices, blocks), gather_contacts(members, q, True),
                                gather_contacts(members, mu_s, False), gather_contacts(members, mu_d, False),
                                gather_contacts(members, start_guess, False), velocity_tol,
                                gather_contacts(members, closing, False), pg, ug, states_g, start_g):
            scatter_contacts(members, pg, ug, states_g, p, u, states)
            changed = True
    return changed


__all__ = ["prefer_sticking", "prefer_sticking_from", "prefer_sticking_by_group", "gather_contacts",
           "scatter_contacts", "admissible_split", "simplex_max", "STATE_OPEN", "STATE_STICK", "STATE_SLIP_PLUS",
           "STATE_SLIP_MINUS", "MODE_OPEN", "MODE_STICK", "MODE_SLIDE", "MODE_FREE", "MODE_LOOSE"]
