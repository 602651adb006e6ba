"""Nonsmooth (projected) Gauss–Seidel on the contact impulses ("pgs").

A sweep visits the contacts in order and solves each contact's 2×2 local problem exactly,
the other contacts' impulses frozen at their latest values. Contact i sees

    u_i = W_ii p_i + v_i,    v_i = q_i + Σ_{j≠i} W_ij p_j,    W_ii = [[a, b], [b, c]],

and its exact local solution is the first consistent case of

    open   v_N ≥ 0                     → p_i = 0
    stick  p_i = −W_ii⁻¹ v_i           if p_N ≥ 0 and lo p_N ≤ p_T ≤ hi p_N
    slip   p_T = lo·p_N (needs u_T ≥ 0) or p_T = hi·p_N (needs u_T ≤ 0),
           p_N from the normal row u_N = 0: p_N = −v_N / (a + b·bound), needs a + b·bound > 0.

The Delassus matrix is held block-sparse (delassus.py's block layout),
so a sweep costs O(nonzero blocks), i.e. O(contacts) for a chain or a row of bodies.

Convergence is judged on the common residual relative to the problem's scale
max(‖q‖∞, ‖p‖∞, ‖u‖∞): stop when complementarity_residual ≤ rtol · scale. By default the
sweeps aim for PGS_RTOL, and when the residual stalls above it (it drops by less than
1 − STALL_FACTOR over STALL_SWEEPS sweeps) but is already within the acceptance every exact
solver uses (DEFAULT_RTOL, as Lemke's and enum's), they stop there and the answer is accepted: with a singular W and a q a little outside
its range (two contacts on one body, gap-keeping terms), the exact solution has a slip
velocity of ~1e-11 that Gauss–Seidel approaches by a drift along W's null space, 1e9 sweeps
away (the rod at ball B's impact, issue 9). With one contact the first sweep is exact.

Mode polish (issue 26). On a chain of touching bodies (a row of balls pushed together) the
sweeps converge like Gauss–Seidel on a discrete Laplacian, 1 − O(1/k²) per sweep for k contacts
in a chain: hundreds of sweeps, although the mode (which contacts are open, stick, slide which
way) is right after a few. So at sweeps POLISH_FIRST, 2·POLISH_FIRST, 4·POLISH_FIRST, … each
coupled group of at most POLISH_MAX_GROUP contacts whose own residual is still above the target
has the linear equations of the mode its iterate shows solved exactly (`solve_mode`: least
squares, minimum norm — a singular W gets its least-norm split), and the result is kept only if
the whole problem then meets the target on the same residual; otherwise the sweeps go on from
where they were. The stopping rule is unchanged: whatever is returned as solved has
complementarity_residual ≤ rtol · scale (or, stalled, ≤ DEFAULT_RTOL · scale).
"""
from __future__ import annotations

import numpy as np

from .._jit import jit, jit_borrowing, jit_inline
from ._common import loop_array, make_solution, python_body, require_finite_array
from ..validation import InputError
from .kernel_base import (
    DEFAULT_RTOL,
    KERNEL_NO_CONVERGENCE,
    KERNEL_NONFINITE,
    KERNEL_SOLVED,
    all_finite,
    carve,
    contact_residual,
    problem_scale,
)
from .problem import NoConvergence, PlanarFrictionProblem
from .delassus import count_blocks, coupled_components, fill_blocks, group_matrix
from .sticking import RANK_TOL, _frobenius, _upper_inverse, gather_contacts

# The local stick system counts as singular when det(W_ii) ≤ SINGULAR_DET · a·c. A disk or
# corner contact of a body with rotational inertia never gets there, but e.g. a contact on
# a body with a single translational DOF would (W_ii of rank one).
SINGULAR_DET = 1e-13
# Round-off slack of the local consistency tests (relative to the quantities compared).
LOCAL_SLACK = 1e-12
# Default target of the sweeps (relative) and sweep limit.
PGS_RTOL = 1e-12
PGS_MAX_SWEEPS = 10000
# Stall detection: over STALL_SWEEPS sweeps the residual fell by less than STALL_FACTOR.
# A linear rate that slow (ρ > 0.9998) would need > 3·10⁴ sweeps per factor 10³ anyway.
STALL_SWEEPS = 50
STALL_FACTOR = 0.99
# Mode polish (module docstring): first at this sweep, then at every doubling; groups of at most
# this many contacts (its least squares costs O(contacts³): a pile's cold first step of 94
# contacts is cheaper swept).
POLISH_FIRST = 4
POLISH_MAX_GROUP = 48


@jit
def local_contact_solve(a, b, c, v_n, v_t, lo, hi):
    """Exact solution of one contact's 2×2 problem: (found, p_N, p_T).

    The cases are tried in the order open, stick, slip at lo, slip at hi; the first that is
    consistent is returned (for an ill-posed local problem with several solutions this is
    the one Gauss–Seidel keeps). found is False when no case fits.
    """
    if v_n >= 0.0:
        return True, 0.0, 0.0
    det = a * c - b * b
    if det > SINGULAR_DET * a * c:
        p_n = (-c * v_n + b * v_t) / det
        p_t = (b * v_n - a * v_t) / det
        slack = LOCAL_SLACK * (abs(p_n) + abs(p_t))
        if p_n >= 0.0 and lo * p_n - slack <= p_t <= hi * p_n + slack:
            return True, p_n, min(max(p_t, lo * p_n), hi * p_n)
    for k in range(2):
        bound = lo if k == 0 else hi
        sign = 1.0 if k == 0 else -1.0
        normal_stiffness = a + b * bound
        if normal_stiffness > 0.0:
            p_n = -v_n / normal_stiffness
            u_t = (b + c * bound) * p_n + v_t
            if sign * u_t >= -LOCAL_SLACK * (abs(v_t) + abs((b + c * bound) * p_n)):
                return True, p_n, bound * p_n
    return False, 0.0, 0.0


def solve_contact(a, b, c, v_n, v_t, lo, hi):
    """`local_contact_solve` as (p_N, p_T), or None when no case fits."""
    found, p_n, p_t = local_contact_solve(float(a), float(b), float(c), float(v_n), float(v_t),
                                          float(lo), float(hi))
    return (float(p_n), float(p_t)) if found else None


@jit_borrowing
def block_velocities(indptr, indices, blocks, q, p, u):
    """u = W p + q for the block-sparse W, in place (O(nonzero blocks))."""
    for i in range(indptr.shape[0] - 1):
        u_n = q[2 * i]
        u_t = q[2 * i + 1]
        for k in range(indptr[i], indptr[i + 1]):
            j = indices[k]
            u_n += blocks[k, 0, 0] * p[2 * j] + blocks[k, 0, 1] * p[2 * j + 1]
            u_t += blocks[k, 1, 0] * p[2 * j] + blocks[k, 1, 1] * p[2 * j + 1]
        u[2 * i] = u_n
        u[2 * i + 1] = u_t


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _diagonal_positions(indptr, indices, diagonal):
    """diagonal[i]: the position in `blocks` of contact i's diagonal block (−1 if missing)."""
    for i in range(indptr.shape[0] - 1):
        diagonal[i] = -1
        for k in range(indptr[i], indptr[i + 1]):
            if indices[k] == i:
                diagonal[i] = k


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def pgs_sweep(indptr, indices, blocks, diagonal, q, lo, hi, p):
    """One Gauss–Seidel sweep over the contacts, updating p in place."""
    for i in range(indptr.shape[0] - 1):
        v_n = q[2 * i]
        v_t = q[2 * i + 1]
        for k in range(indptr[i], indptr[i + 1]):
            j = indices[k]
            if j != i:
                v_n += blocks[k, 0, 0] * p[2 * j] + blocks[k, 0, 1] * p[2 * j + 1]
                v_t += blocks[k, 1, 0] * p[2 * j] + blocks[k, 1, 1] * p[2 * j + 1]
        d = diagonal[i]
        found, p_n, p_t = local_contact_solve(blocks[d, 0, 0], blocks[d, 0, 1], blocks[d, 1, 1],
                                              v_n, v_t, lo[i], hi[i])
        if found:
            p[2 * i] = p_n
            p[2 * i + 1] = p_t


# pgs_block_into's scratch: STALL_SWEEPS floats (the residuals' history) and one int64 per contact
# (the diagonal blocks' positions); pgs_dense_into's adds the blocks of the dense W (below).
PGS_FLOATS = STALL_SWEEPS


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _finite_problem(blocks, q, lo, hi, p):
    """True when the blocks, q, lo, hi and the warm start p are all finite (loops: all_finite's
    ravel is not for a borrowing caller)."""
    finite = True
    for k in range(blocks.shape[0]):
        for r in range(2):
            for c in range(2):
                finite = finite and np.isfinite(blocks[k, r, c])
    for i in range(q.shape[0]):
        finite = finite and np.isfinite(q[i]) and np.isfinite(p[i])
    for i in range(lo.shape[0]):
        finite = finite and np.isfinite(lo[i]) and np.isfinite(hi[i])
    return finite


@jit_borrowing
def _unsolved(q, p, u):
    """p = 0, u = q: what a problem that cannot be solved leaves."""
    for i in range(q.shape[0]):
        p[i], u[i] = 0.0, q[i]


def pgs_block(indptr, indices, blocks, q, lo, hi, p, u, rtol, max_sweeps):
    """pgs_block_into with scratch of its own, allocated here (callers outside the step): the loop's
    compiled kernel with the loop's argument types (_common.loop_array; p, u filled in place)."""
    floats, ints = np.empty(PGS_FLOATS), np.empty(max(indptr.shape[0] - 1, 0), dtype=np.int64)
    return pgs_block_into(loop_array(indptr, np.int64), loop_array(indices, np.int64), loop_array(blocks),
                          loop_array(q), loop_array(lo), loop_array(hi), p, u, float(rtol), int(max_sweeps), floats,
                          ints)


@jit_borrowing
def pgs_block_into(indptr, indices, blocks, q, lo, hi, p, u, rtol, max_sweeps, floats, ints):
    """Nonsmooth Gauss–Seidel on a block-sparse Delassus; p is the warm start.

    Fills p, u in place; returns (status, sweeps, residual) with the `kernels` status codes.
    Stops at residual ≤ rtol·scale. rtol ≤ 0 is the default: aim for PGS_RTOL, and accept a
    stalled residual ≤ DEFAULT_RTOL·scale (module docstring). max_sweeps ≤ 0: PGS_MAX_SWEEPS.
    floats, ints: scratch of at least PGS_FLOATS and one per contact. Compiled without reference
    counting (the step's hot path): it allocates nothing (the mode polish, when it runs, does).
    """
    if not _finite_problem(blocks, q, lo, hi, p):
        _unsolved(q, p, u)
        return KERNEL_NONFINITE, 0, np.inf
    diagonal, _ = carve(ints, 0, indptr.shape[0] - 1)
    _diagonal_positions(indptr, indices, diagonal)
    for i in range(diagonal.shape[0]):
        if diagonal[i] < 0:  # the local solve needs W_ii: a malformed matrix cannot converge
            return KERNEL_NO_CONVERGENCE, 0, np.inf
    target = rtol if rtol > 0.0 else PGS_RTOL
    accept = rtol if rtol > 0.0 else DEFAULT_RTOL
    limit = max_sweeps if max_sweeps > 0 else PGS_MAX_SWEEPS
    history, _ = carve(floats, 0, STALL_SWEEPS)
    for s in range(STALL_SWEEPS):
        history[s] = np.inf
    residual = np.inf
    polish_at = POLISH_FIRST
    for sweep in range(1, limit + 1):
        pgs_sweep(indptr, indices, blocks, diagonal, q, lo, hi, p)
        block_velocities(indptr, indices, blocks, q, p, u)
        residual = contact_residual(lo, hi, p, u)
        scale = problem_scale(q, p, u)
        if residual <= target * scale + 1e-300:
            return KERNEL_SOLVED, sweep, residual
        if sweep == polish_at:
            polish_at *= 2
            if polish_modes(indptr, indices, blocks, q, lo, hi, p, u, target):
                return KERNEL_SOLVED, sweep, contact_residual(lo, hi, p, u)
        slot = sweep % STALL_SWEEPS
        stalled = residual > STALL_FACTOR * history[slot]
        history[slot] = residual
        if stalled and residual <= accept * scale:
            return KERNEL_SOLVED, sweep, residual
    return KERNEL_NO_CONVERGENCE, limit, residual


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _mode_solution(A, b):
    """lstsq's minimum-norm least-squares solution of A x = b. A square A (every mode of a row of
    balls) whose QR certifies it well conditioned — ‖R‖_F ‖R⁻¹‖_F < 1/RANK_TOL bounds σ_max/σ_min,
    the hold search's certificate — is solved through that QR (Aᵀ = QR, x = Q R⁻ᵀ b): the same
    unique solution to round-off, a fraction of lstsq's SVD (issue 26: the polish was ~15 µs of a
    row of 16's step). Either way the polish keeps it only if the whole problem then meets the
    residual target."""
    certain, x = _certified_square_solution(A, b)
    return x if certain else np.linalg.lstsq(A, b)[0]


@jit
def _certified_square_solution(A, b):
    """(True, A⁻¹ b) through the QR of Aᵀ when A is square and ‖R‖_F ‖R⁻¹‖_F < 1/RANK_TOL, else
    (False, ·)."""
    n = A.shape[0]
    if n == 0 or n != A.shape[1]:
        return False, np.zeros(A.shape[1])
    Q, R = np.linalg.qr(np.ascontiguousarray(A.T))
    R_inv = _upper_inverse(R)
    if not (_frobenius(R) * _frobenius(R_inv) < 1.0 / RANK_TOL):
        return False, np.zeros(n)
    return True, np.ascontiguousarray(Q) @ (np.ascontiguousarray(R_inv.T) @ b)


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def solve_mode(W, q, lo, hi, p, u):
    """Replace p, u (one group, dense W) by the exact solution of the mode p shows: a contact with
    p_N > 0 touches (u_N = 0) and sticks (u_T = 0) if p_T is strictly inside its interval, else
    slides at that end (p_T = end · p_N); the others carry nothing. Least squares, minimum norm.
    False when nothing is closed or the answer is not finite (p, u then unchanged)."""
    n = lo.shape[0]
    P = np.zeros((2 * n, 2 * n))
    rows = np.empty(2 * n, dtype=np.int64)
    k, r = 0, 0
    for i in range(n):
        p_n, p_t = p[2 * i], p[2 * i + 1]
        if p_n <= 0.0:
            continue
        P[2 * i, k] = 1.0
        rows[r] = 2 * i
        r += 1
        if p_t <= lo[i] * p_n or p_t >= hi[i] * p_n:
            P[2 * i + 1, k] = lo[i] if p_t <= lo[i] * p_n else hi[i]
            k += 1
            continue
        P[2 * i + 1, k + 1] = 1.0
        rows[r] = 2 * i + 1
        r += 1
        k += 2
    if k == 0:
        return False
    P = np.ascontiguousarray(P[:, :k])
    WP = W @ P
    A = np.empty((r, k))
    b = np.empty(r)
    for j in range(r):
        A[j, :] = WP[rows[j], :]
        b[j] = -q[rows[j]]
    x = _mode_solution(A, b)
    p_new = P @ x
    if not all_finite(p_new):
        return False
    p[:] = p_new
    u[:] = W @ p_new + q
    return True


@jit
def polish_modes(indptr, indices, blocks, q, lo, hi, p, u, rtol):
    """solve_mode on every coupled group of at most POLISH_MAX_GROUP contacts whose residual is
    above rtol × the problem's scale; kept (p, u replaced, True) only when the whole problem's
    residual is then within rtol × its scale, else p, u unchanged and False."""
    na = lo.shape[0]
    tolerance = rtol * problem_scale(q, p, u) + 1e-300
    label = np.empty(na, dtype=np.int64)
    groups = coupled_components(indptr, indices, np.zeros((0, 0)), label)
    p_new, changed = p.copy(), False
    for g in range(groups):
        members = np.flatnonzero(label == g)
        if members.shape[0] > POLISH_MAX_GROUP:
            continue
        lo_g, hi_g = gather_contacts(members, lo, False), gather_contacts(members, hi, False)
        p_g, u_g = gather_contacts(members, p, True), gather_contacts(members, u, True)
        if contact_residual(lo_g, hi_g, p_g, u_g) <= tolerance:
            continue
        if solve_mode(group_matrix(members, np.zeros((0, 0)), indptr, indices, blocks),
                      gather_contacts(members, q, True), lo_g, hi_g, p_g, u_g):
            for a in range(members.shape[0]):
                p_new[2 * members[a]], p_new[2 * members[a] + 1] = p_g[2 * a], p_g[2 * a + 1]
            changed = True
    if not changed:
        return False
    u_new = np.empty_like(u)
    block_velocities(indptr, indices, blocks, q, p_new, u_new)
    if contact_residual(lo, hi, p_new, u_new) > rtol * problem_scale(q, p_new, u_new) + 1e-300:
        return False
    p[:] = p_new
    u[:] = u_new
    return True


@jit
def pgs_dense_floats(n_contacts):
    """Floats pgs_dense_into takes for n_contacts contacts: every block of the dense W, and pgs's."""
    return 4 * n_contacts * n_contacts + PGS_FLOATS


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def pgs_dense_ints(n_contacts):
    """int64s pgs_dense_into takes: the blocks' row starts and columns, the diagonal's positions."""
    return n_contacts * n_contacts + 2 * n_contacts + 1


def pgs_dense(W, q, lo, hi, p, u, rtol, max_sweeps):
    """pgs_dense_into with scratch of its own, allocated here (callers outside the step): the loop's
    compiled kernel with the loop's argument types (_common.loop_array; p, u filled in place)."""
    na = lo.shape[0]
    floats = np.empty(pgs_dense_floats(na))
    ints = np.empty(python_body(pgs_dense_ints)(na), dtype=np.int64)
    return pgs_dense_into(loop_array(W), loop_array(q), loop_array(lo), loop_array(hi), p, u, float(rtol),
                          int(max_sweeps), floats, ints)


@jit_borrowing
def pgs_dense_into(W, q, lo, hi, p, u, rtol, max_sweeps, floats, ints):
    """`pgs_block_into` on a dense W, its blocks (delassus.dense_to_blocks' layout, O(contacts²))
    carved from the scratch (floats, ints: at least pgs_dense_floats, pgs_dense_ints of these
    contacts). Borrowing: it allocates nothing."""
    na = W.shape[0] // 2
    finite = True
    for i in range(W.shape[0]):
        for j in range(W.shape[1]):
            finite = finite and np.isfinite(W[i, j])
    if not finite:
        _unsolved(q, p, u)
        return KERNEL_NONFINITE, 0, np.inf
    indptr, at = carve(ints, 0, na + 1)
    nnz = count_blocks(W, indptr)
    indices, at = carve(ints, at, nnz)
    blocks = floats[:4 * nnz].reshape((nnz, 2, 2))
    fill_blocks(W, indptr, indices, blocks)
    return pgs_block_into(indptr, indices, blocks, q, lo, hi, p, u, rtol, max_sweeps, floats[4 * nnz:], ints[at:])


def projected_gauss_seidel(
    problem: PlanarFrictionProblem,
    *,
    tol: float | None = None,
    max_iter: int = PGS_MAX_SWEEPS,
    p0=None,
):
    """Solve the step by nonsmooth Gauss–Seidel sweeps; return a ContactSolution ("pgs").

    ``tol``: stop when complementarity_residual ≤ tol · residual_scale (checked after each
    sweep). Default (None): aim for PGS_RTOL and accept a stalled residual within
    DEFAULT_RTOL · scale, the acceptance of Lemke and enum (module docstring). ``max_iter``: sweep limit; reaching it raises NoConvergence naming the sweeps
    and the residual. ``p0``: warm start (e.g. the previous step's impulses); default zero.
    iterations = sweeps. Runs the compiled `pgs_block` kernel (interpreted without numba).
    """
    n = 2 * problem.n_contacts
    p = np.zeros(n) if p0 is None else np.array(p0, dtype=float).ravel()
    if p.shape[0] != n:
        raise InputError(f"pgs: warm start has {p.shape[0]} entries, the problem has {n}")
    require_finite_array("p0", p, "pgs")
    u = problem.q.copy()
    if n == 0:
        return make_solution(problem, p, u, "pgs", 0, 0.0)
    rtol = 0.0 if tol is None else float(tol)
    status, sweeps, residual = pgs_dense(problem.W, problem.q, problem.lo, problem.hi, p, u, rtol,
                                         int(max_iter))
    if status == KERNEL_NONFINITE:  # only if the problem's arrays were changed after it was made
        raise InputError("pgs: the problem's W, q, lo, hi must be finite")
    if status != KERNEL_SOLVED:
        scale = max(np.abs(p).max(), np.abs(u).max(), np.abs(problem.q).max()) or 1.0
        raise NoConvergence(
            f"pgs: no convergence after {sweeps} sweeps, residual {residual:.3e} > "
            f"tol {rtol or PGS_RTOL:.0e} × scale {scale:.3e}"
        )
    return make_solution(problem, p, u, "pgs", int(sweeps), float(residual))


__all__ = [
    "projected_gauss_seidel", "solve_contact", "local_contact_solve", "pgs_block", "pgs_block_into", "pgs_dense",
    "pgs_dense_into", "pgs_dense_floats", "pgs_dense_ints", "PGS_FLOATS",
    "block_velocities", "solve_mode", "polish_modes",
]
