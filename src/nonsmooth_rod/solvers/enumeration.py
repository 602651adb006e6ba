"""Closed-form enumeration of contact modes ("enum"), the reference solver for tiny steps.

Each contact is open, sticking or slipping in one of two directions; each mode turns the
contact's two conditions into two linear equations on p:

    open    p_N = 0,  p_T = 0                       (needs u_N ≥ 0)
    stick   u_N = 0,  u_T = 0                       (needs p_N ≥ 0, lo p_N ≤ p_T ≤ hi p_N)
    slip+   u_N = 0,  p_T = lo·p_N                  (needs p_N ≥ 0, u_T ≥ 0)
    slip−   u_N = 0,  p_T = hi·p_N                  (needs p_N ≥ 0, u_T ≤ 0)

All 4^n_c combinations are solved in one compiled kernel (`enum_interval`, the same source
interpreted without numba; up to MAX_CONTACTS contacts, KERNEL_TOO_LARGE beyond), each
2n_c × 2n_c system with the pseudo-inverse (SVD), i.e. the least-norm solution when a system is singular (statically
indeterminate sticking: only the sum of some impulses is determined). When the singular
system's solutions form a line (two contacts on a 3-DOF body: W has rank 3), the point of
the line nearest the least-norm one that meets the mode's inequalities is taken instead: the
least-norm point itself can violate them (wedged contacts, unequal normal loads). A
candidate is a solution when it satisfies the whole step law, which the common
complementarity residual measures exactly; among the solutions the least-norm impulse is
returned.
"""
from __future__ import annotations

import numpy as np

from .._jit import jit, jit_inline
from ._common import RESIDUAL_FLOOR, make_solution
from ..validation import InputError
from .kernel_base import (
    KERNEL_NO_CONVERGENCE,
    KERNEL_NONFINITE,
    KERNEL_SOLVED,
    KERNEL_TOO_LARGE,
    all_finite,
    step_residual,
)
from .problem import (CONTACT_STATES, STATE_OPEN, STATE_SLIP_MINUS, STATE_SLIP_PLUS, STATE_STICK,
                      InfeasibleProblem, PlanarFrictionProblem)


# Default acceptance: complementarity_residual ≤ ACCEPT_TOL · scale (see enumerate_modes).
ACCEPT_TOL = 1e-9

# Relative singular-value cut-off of the pseudo-inverse (singular W).
RCOND = 1e-12

# Enumeration grows as 4^n_c; beyond this it is no longer a "tiny problem" solver.
MAX_CONTACTS = 4

_mode_table_cache: dict[int, np.ndarray] = {}


def _mode_table(n_contacts: int) -> np.ndarray:
    """All mode combinations, shape (4^n_c, n_c), in a fixed order (open first)."""
    table = _mode_table_cache.get(n_contacts)
    if table is None:
        table = _mode_table_cache[n_contacts] = enum_table(n_contacts)
    return table


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _mode_system(W, q, lo, hi, modes, A, b):
    """The linear system A p = b of one mode combination (module docstring), in place."""
    n = q.shape[0]
    A[:, :] = 0.0
    b[:] = 0.0
    for i in range(modes.shape[0]):
        N = 2 * i
        T = N + 1
        mode = modes[i]
        if mode == STATE_OPEN:
            A[N, N] = 1.0  # p_N = 0, p_T = 0
            A[T, T] = 1.0
            continue
        for j in range(n):  # u_N = 0
            A[N, j] = W[N, j]
        b[N] = -q[N]
        if mode == STATE_STICK:  # u_T = 0
            for j in range(n):
                A[T, j] = W[T, j]
            b[T] = -q[T]
        else:  # p_T = bound · p_N
            A[T, T] = 1.0
            A[T, N] = -(lo[i] if mode == STATE_SLIP_PLUS else hi[i])


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _mode_inequalities(W, q, lo, hi, modes, G, h):
    """G p + h ≥ 0: what the mode combination still needs, 3 rows per contact (unused rows
    are 0·p + 1 ≥ 0), in place."""
    n = q.shape[0]
    G[:, :] = 0.0
    h[:] = 1.0
    for i in range(modes.shape[0]):
        N = 2 * i
        T = N + 1
        r = 3 * i
        mode = modes[i]
        if mode == STATE_OPEN:  # u_N ≥ 0
            for j in range(n):
                G[r, j] = W[N, j]
            h[r] = q[N]
        else:  # p_N ≥ 0
            G[r, N] = 1.0
            h[r] = 0.0
        if mode == STATE_STICK:  # p_T − lo p_N ≥ 0, hi p_N − p_T ≥ 0
            G[r + 1, T] = 1.0
            G[r + 1, N] = -lo[i]
            G[r + 2, T] = -1.0
            G[r + 2, N] = hi[i]
            h[r + 1] = 0.0
            h[r + 2] = 0.0
        elif mode == STATE_SLIP_PLUS or mode == STATE_SLIP_MINUS:  # ±u_T ≥ 0
            sign = 1.0 if mode == STATE_SLIP_PLUS else -1.0
            for j in range(n):
                G[r + 1, j] = sign * W[T, j]
            h[r + 1] = sign * q[T]


@jit
def _least_norm(U, S_inv, Vt, rhs):
    """Vᵀᵀ diag(S_inv) Uᵀ rhs: the pseudo-inverse applied to rhs."""
    return Vt.T @ (S_inv * (U.T @ rhs))


@jit
def _solve_mode(W, q, lo, hi, modes, rcond, A, b, G, h):
    """Least-norm solution of one mode's system, moved along a one-dimensional null space to
    the nearest point meeting the mode's inequalities (module docstring)."""
    _mode_system(W, q, lo, hi, modes, A, b)
    U, S, Vt = np.linalg.svd(A)
    cutoff = rcond * S[0]
    S_inv = np.zeros(S.shape[0])
    null_dimension = 0
    for k in range(S.shape[0]):
        if S[k] > cutoff:
            S_inv[k] = 1.0 / S[k]
        else:
            null_dimension += 1
    P = _least_norm(U, S_inv, Vt, b)
    # one step of iterative refinement: near-singular systems lose digits in the first solve
    P += _least_norm(U, S_inv, Vt, b - A @ P)
    if null_dimension == 1:
        _mode_inequalities(W, q, lo, hi, modes, G, h)
        direction = Vt[Vt.shape[0] - 1].copy()
        slope = G @ direction
        value = G @ P + h
        t_low = -np.inf
        t_high = np.inf
        for r in range(G.shape[0]):
            # slope·t + value ≥ 0 bounds t from below (slope > 0) or above (slope < 0)
            if abs(slope[r]) > 1e-12 * max(np.abs(G[r]).sum(), 1e-300):
                if slope[r] > 0.0:
                    t_low = max(t_low, -value[r] / slope[r])
                else:
                    t_high = min(t_high, -value[r] / slope[r])
        if t_low <= t_high:
            P += min(max(0.0, t_low), t_high) * direction
    return P


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def solve_mode_table(W, q, lo, hi, table, rcond):
    """`_solve_mode` for every row of ``table`` (mode combinations): P, shape (K, 2 n_c)."""
    n = q.shape[0]
    A = np.zeros((n, n))
    b = np.zeros(n)
    G = np.zeros((3 * (n // 2), n))
    h = np.zeros(3 * (n // 2))
    P = np.zeros((table.shape[0], n))
    for k in range(table.shape[0]):
        P[k] = _solve_mode(W, q, lo, hi, table[k], rcond, A, b, G, h)
    return P


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def enum_candidates(W, q, lo, hi, table, rcond):
    """(P, U, residuals, scales) of every mode combination's solution.

    Each candidate is judged against the velocities and the problem's own impulse scale
    ‖q‖/max|W|, not against its own ‖p‖: on wedged contacts a singular mode admits
    self-equilibrated impulses of any size, and ‖p‖ ~ 1e10 must not buy a lax tolerance.
    """
    P = solve_mode_table(W, q, lo, hi, table, rcond)
    K = P.shape[0]
    U = np.zeros_like(P)
    residuals = np.zeros(K)
    scales = np.zeros(K)
    q_norm = np.abs(q).max()
    W_norm = np.abs(W).max()
    floor = max(q_norm, q_norm / W_norm if W_norm > 0.0 else 0.0)
    for k in range(K):
        residuals[k] = step_residual(W, q, lo, hi, P[k], U[k])
        scale = max(np.abs(U[k]).max(), floor)
        scales[k] = scale if scale > 0.0 else 1.0
    return P, U, residuals, scales


@jit
def _mode_row(k, n_contacts):
    """Combination k of the table's order (itertools.product: the first contact varies slowest)."""
    modes = np.zeros(n_contacts, dtype=np.int64)
    for i in range(n_contacts - 1, -1, -1):
        modes[i] = k % 4
        k //= 4
    return modes


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def enum_table(n_contacts):
    """All 4^n_c mode combinations as rows (same order as `_mode_table`)."""
    table = np.zeros((4**n_contacts, n_contacts), dtype=np.int64)
    for k in range(table.shape[0]):
        table[k] = _mode_row(k, n_contacts)
    return table


@jit
def choose_candidate(residuals, scales, P, rtol):
    """Index of the returned candidate (−1 if none valid) and the number of valid ones.

    Among the valid candidates (residual ≤ rtol·scale) keep those as exact as the best one
    (a candidate of a wrong mode can pass `rtol` when an interval end is within rtol of
    another, e.g. lo = −1e-10), then the least-norm one (stable where the solution is not
    unique; the first in table order on ties).
    """
    best_relative = np.inf
    n_valid = 0
    for k in range(residuals.shape[0]):
        if residuals[k] <= rtol * scales[k] + RESIDUAL_FLOOR:
            n_valid += 1
            best_relative = min(best_relative, residuals[k] / scales[k])
    chosen = -1
    chosen_norm = np.inf
    for k in range(residuals.shape[0]):
        relative = residuals[k] / scales[k]
        valid = residuals[k] <= rtol * scales[k] + RESIDUAL_FLOOR
        if valid and relative <= max(100.0 * best_relative, 1e-14):
            norm = (P[k] * P[k]).sum()
            if norm < chosen_norm:
                chosen, chosen_norm = k, norm
    return chosen, n_valid


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def enum_interval(W, q, lo, hi, p, u, rtol, max_contacts):
    """The enumeration kernel: fills p, u; returns (status, combinations, residual).

    KERNEL_TOO_LARGE beyond ``max_contacts`` (≤ 0: MAX_CONTACTS) contacts,
    KERNEL_NO_CONVERGENCE when no combination satisfies the step law within rtol (≤ 0: ACCEPT_TOL).
    """
    n_contacts = lo.shape[0]
    limit = max_contacts if max_contacts > 0 else MAX_CONTACTS
    if n_contacts > limit:
        return KERNEL_TOO_LARGE, 0, np.inf
    if not (all_finite(W) and all_finite(q) and all_finite(lo) and all_finite(hi)):
        p[:] = 0.0
        u[:] = q
        return KERNEL_NONFINITE, 0, np.inf
    table = enum_table(n_contacts)
    P, U, residuals, scales = enum_candidates(W, q, lo, hi, table, RCOND)
    chosen, n_valid = choose_candidate(residuals, scales, P, rtol if rtol > 0.0 else ACCEPT_TOL)
    if chosen < 0:
        p[:] = 0.0
        u[:] = q
        return KERNEL_NO_CONVERGENCE, table.shape[0], residuals.min()
    p[:] = P[chosen]
    u[:] = U[chosen]
    return KERNEL_SOLVED, table.shape[0], residuals[chosen]


def _solve_modes(problem, modes, rcond):
    """Solutions of the given mode combinations (rows of ``modes``), shape (K, 2 n_c)."""
    table = np.ascontiguousarray(modes, dtype=np.int64).reshape(len(modes), problem.n_contacts)
    return solve_mode_table(problem.W, problem.q, problem.lo, problem.hi, table, float(rcond))


def _candidates(problem: PlanarFrictionProblem, rcond: float):
    """(modes, P, U, residuals, scales) for every mode combination's solution."""
    if not all(all_finite(getattr(problem, name)) for name in ("W", "q", "lo", "hi")):
        raise InputError("enum: the problem's W, q, lo, hi must be finite")  # changed after it was made
    modes = _mode_table(problem.n_contacts)
    P, U, residuals, scales = enum_candidates(problem.W, problem.q, problem.lo, problem.hi, modes,
                                              float(rcond))
    return modes, P, U, residuals, scales


def mode_solutions(problem: PlanarFrictionProblem, *, tol: float = ACCEPT_TOL, rcond: float = RCOND):
    """Every mode combination whose least-norm solution satisfies the step law.

    Returns a list of (modes, p, u), modes a tuple of "open" | "stick" | "slip+" | "slip-".
    Several entries may be the same solution (a contact at a case boundary, e.g. sliding
    with u_T = 0); different u among them show that the step's velocities are not unique.
    """
    _check_size(problem)
    modes, P, U, residuals, scales = _candidates(problem, rcond)
    return [
        (tuple(CONTACT_STATES[m] for m in modes[k]), P[k], U[k])
        for k in np.flatnonzero(residuals <= tol * scales + RESIDUAL_FLOOR)
    ]


def _check_size(problem):
    if problem.n_contacts > MAX_CONTACTS:
        raise InputError(
            f"enum: {problem.n_contacts} contacts exceed the enumeration limit of {MAX_CONTACTS}"
        )


def enumerate_modes(problem: PlanarFrictionProblem, *, tol: float = ACCEPT_TOL, rcond: float = RCOND):
    """Solve the step by trying every mode combination; return a ContactSolution ("enum").

    ``tol``: a candidate is accepted when complementarity_residual ≤ tol · scale, scale =
    max(‖u‖∞, ‖q‖∞, ‖q‖∞ / max|W|). Well-conditioned steps come out at ~1e-15; the default
    1e-9 (as Lemke's acceptance) leaves room for wedged two-contact steps, whose mode
    solutions are only accurate to ~1e-10.
    ``rcond``: relative singular-value cut-off of the pseudo-inverse (singular W).
    Among the valid candidates with the smallest residual (within a factor 100, or 1e-14) the
    least-norm impulse is returned; info["modes"] names the mode
    combination it came from and info["n_solutions"] counts the valid combinations.
    iterations = combinations tried (4^n_c). Raises InfeasibleProblem when none is valid.
    """
    _check_size(problem)
    if problem.n_contacts == 0:
        return make_solution(problem, np.zeros(0), problem.q.copy(), "enum", 0, 0.0)
    modes, P, U, residuals, scales = _candidates(problem, rcond)
    k, n_valid = choose_candidate(residuals, scales, P, float(tol))
    if k < 0:
        best = int(np.argmin(residuals / scales))
        raise InfeasibleProblem(
            f"enum: none of the {len(modes)} mode combinations satisfies the step law; best "
            f"{[CONTACT_STATES[m] for m in modes[best]]} with residual {residuals[best]:.3e} "
            f"(> {tol:.0e} × scale {scales[best]:.3e})"
        )
    return make_solution(
        problem, P[k], U[k], "enum", len(modes), float(residuals[k]),
        modes=[CONTACT_STATES[m] for m in modes[k]], n_solutions=int(n_valid),
    )


__all__ = ["enumerate_modes", "mode_solutions", "MAX_CONTACTS"]
