"""Closed-form enumeration of contact modes ("enum"), the reference solver for tiny steps.

Each contact is open, sticking or slipping in one of two directions; each mode turns the
contact's two conditions into two linear equations on p:

    open    p_N = 0,  p_T = 0                       (needs u_N ≥ 0)
    stick   u_N = 0,  u_T = 0                       (needs p_N ≥ 0, lo p_N ≤ p_T ≤ hi p_N)
    slip+   u_N = 0,  p_T = lo·p_N                  (needs p_N ≥ 0, u_T ≥ 0)
    slip−   u_N = 0,  p_T = hi·p_N                  (needs p_N ≥ 0, u_T ≤ 0)

All 4^n_c combinations are solved at once (a stack of 2n_c × 2n_c systems) with the
pseudo-inverse, i.e. the least-norm solution when a system is singular (statically
indeterminate sticking: only the sum of some impulses is determined). When the singular
system's solutions form a line (two contacts on a 3-DOF body: W has rank 3), the point of
the line nearest the least-norm one that meets the mode's inequalities is taken instead: the
least-norm point itself can violate them (wedged contacts, unequal normal loads). A
candidate is a solution when it satisfies the whole step law, which the common
complementarity residual measures exactly; among the solutions the least-norm impulse is
returned.
"""
from __future__ import annotations

import itertools

import numpy as np

from ._common import RESIDUAL_FLOOR, make_solution
from .problem import InfeasibleProblem, PlanarFrictionProblem

OPEN, STICK, SLIP_POS, SLIP_NEG = range(4)
MODE_NAMES = ("open", "stick", "slip+", "slip-")

# Default acceptance: complementarity_residual ≤ ACCEPT_TOL · scale (see enumerate_modes).
ACCEPT_TOL = 1e-9

# Enumeration grows as 4^n_c; beyond this it is no longer a "tiny problem" solver.
MAX_CONTACTS = 4

_mode_table_cache: dict[int, np.ndarray] = {}


def _mode_table(n_contacts: int) -> np.ndarray:
    """All mode combinations, shape (4^n_c, n_c), in a fixed order (open first)."""
    table = _mode_table_cache.get(n_contacts)
    if table is None:
        table = np.array(list(itertools.product(range(4), repeat=n_contacts)), dtype=int)
        _mode_table_cache[n_contacts] = table
    return table


def _mode_systems(problem: PlanarFrictionProblem, modes: np.ndarray):
    """Stack of linear systems A p = b, one per mode combination (rows of ``modes``)."""
    W, q = problem.W, problem.q
    n = q.shape[0]
    K = modes.shape[0]
    A = np.zeros((K, n, n))
    b = np.zeros((K, n))
    identity = np.eye(n)
    for i in range(problem.n_contacts):
        N, T = 2 * i, 2 * i + 1
        mode = modes[:, i]
        contact = mode != OPEN
        # normal row: u_N = 0 unless open (then p_N = 0)
        A[contact, N] = W[N]
        b[contact, N] = -q[N]
        A[~contact, N] = identity[N]
        # tangential row
        A[mode == OPEN, T] = identity[T]
        A[mode == STICK, T] = W[T]
        b[mode == STICK, T] = -q[T]
        for slip, bound in ((SLIP_POS, problem.lo[i]), (SLIP_NEG, problem.hi[i])):
            row = identity[T] - bound * identity[N]
            A[mode == slip, T] = row
    return A, b


def _mode_inequalities(problem: PlanarFrictionProblem, modes: np.ndarray):
    """Stack of inequalities G p + h ≥ 0 each mode combination still needs (3 per contact;
    unused rows are 0·p + 1 ≥ 0)."""
    W, q = problem.W, problem.q
    n = q.shape[0]
    K = modes.shape[0]
    G = np.zeros((K, 3 * problem.n_contacts, n))
    h = np.zeros((K, 3 * problem.n_contacts))
    h[:] = 1.0
    for i in range(problem.n_contacts):
        N, T = 2 * i, 2 * i + 1
        r = 3 * i
        mode = modes[:, i]
        is_open, stick = mode == OPEN, mode == STICK
        G[is_open, r] = W[N]  # u_N ≥ 0
        h[is_open, r] = q[N]
        G[~is_open, r, N] = 1.0  # p_N ≥ 0
        h[~is_open, r] = 0.0
        G[stick, r + 1, T], G[stick, r + 1, N] = 1.0, -problem.lo[i]  # p_T − lo p_N ≥ 0
        G[stick, r + 2, T], G[stick, r + 2, N] = -1.0, problem.hi[i]  # hi p_N − p_T ≥ 0
        h[stick, r + 1 : r + 3] = 0.0
        for slip, sign in ((SLIP_POS, 1.0), (SLIP_NEG, -1.0)):  # ±u_T ≥ 0
            G[mode == slip, r + 1] = sign * W[T]
            h[mode == slip, r + 1] = sign * q[T]
    return G, h


def _solve_modes(problem, modes, rcond):
    """Least-norm solution of every mode system, then, where the system is singular with a
    one-dimensional null space (statically indeterminate or wedged contacts), the point of
    that line closest to it which satisfies the mode's inequalities, if there is one."""
    A, b = _mode_systems(problem, modes)
    U, S, Vt = np.linalg.svd(A)
    cutoff = rcond * S[:, :1]
    S_inv = np.where(S > cutoff, 1.0 / np.where(S > cutoff, S, 1.0), 0.0)

    def least_norm(rhs):
        return np.einsum("kji,kj->ki", Vt, S_inv * np.einsum("kji,kj->ki", U, rhs))

    P = least_norm(b)
    # one step of iterative refinement: near-singular systems lose digits in the first solve
    P += least_norm(b - np.einsum("kij,kj->ki", A, P))
    line = np.flatnonzero(np.sum(S <= cutoff, axis=1) == 1)
    if line.size:
        G, h = _mode_inequalities(problem, modes[line])
        direction = Vt[line, -1]  # null vector
        slope = np.einsum("kij,kj->ki", G, direction)
        value = np.einsum("kij,kj->ki", G, P[line]) + h
        # slope·t + value ≥ 0 bounds t from below (slope > 0) or above (slope < 0)
        steep = np.abs(slope) > 1e-12 * np.maximum(np.abs(G).sum(axis=2), 1e-300)
        bound = np.where(steep, -value / np.where(steep, slope, 1.0), 0.0)
        t_low = np.where(steep & (slope > 0), bound, -np.inf).max(axis=1)
        t_high = np.where(steep & (slope < 0), bound, np.inf).min(axis=1)
        feasible = t_low <= t_high
        t = np.where(feasible, np.clip(0.0, t_low, t_high), 0.0)
        P[line] += t[:, None] * direction
    return P


def _batched_residuals(problem: PlanarFrictionProblem, P: np.ndarray) -> np.ndarray:
    """complementarity_residual of every row of P (same formula, vectorised)."""
    U = P @ problem.W.T + problem.q
    pN, pT, uN, uT = P[:, 0::2], P[:, 1::2], U[:, 0::2], U[:, 1::2]
    pN_pos = np.maximum(pN, 0.0)
    projected = np.clip(pT - uT, problem.lo * pN_pos, problem.hi * pN_pos)
    r = np.maximum(np.abs(np.minimum(pN, uN)), np.abs(pT - projected))
    return r.max(axis=1), U


def _candidates(problem: PlanarFrictionProblem, rcond: float):
    """(modes, P, U, residuals, scales) for every mode combination's least-norm solution."""
    modes = _mode_table(problem.n_contacts)
    P = _solve_modes(problem, modes, rcond)
    residuals, U = _batched_residuals(problem, P)
    # Judge each candidate against the velocities and the problem's own impulse scale
    # ‖q‖/max|W|, not against its own ‖p‖: on wedged contacts a singular mode admits
    # self-equilibrated impulses of any size, and ‖p‖ ~ 1e10 must not buy a lax tolerance.
    q_norm = float(np.abs(problem.q).max())
    W_norm = float(np.abs(problem.W).max())
    impulse_scale = q_norm / W_norm if W_norm > 0.0 else 0.0
    scales = np.maximum(np.abs(U).max(axis=1), max(q_norm, impulse_scale))
    scales[scales == 0.0] = 1.0
    return modes, P, U, residuals, scales


def mode_solutions(problem: PlanarFrictionProblem, *, tol: float = ACCEPT_TOL, rcond: float = 1e-12):
    """Every mode combination whose least-norm solution satisfies the step law.

    Returns a list of (modes, p, u), modes a tuple of "open" | "stick" | "slip+" | "slip-".
    Several entries may be the same solution (a contact at a case boundary, e.g. sliding
    with u_T = 0); different u among them show that the step's velocities are not unique.
    """
    _check_size(problem)
    modes, P, U, residuals, scales = _candidates(problem, rcond)
    return [
        (tuple(MODE_NAMES[m] for m in modes[k]), P[k], U[k])
        for k in np.flatnonzero(residuals <= tol * scales + RESIDUAL_FLOOR)
    ]


def _check_size(problem):
    if problem.n_contacts > MAX_CONTACTS:
        raise ValueError(
            f"enum: {problem.n_contacts} contacts exceed the enumeration limit of {MAX_CONTACTS}"
        )


def enumerate_modes(problem: PlanarFrictionProblem, *, tol: float = ACCEPT_TOL, rcond: float = 1e-12):
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
    valid = np.flatnonzero(residuals <= tol * scales + RESIDUAL_FLOOR)
    if valid.size == 0:
        best = int(np.argmin(residuals / scales))
        raise InfeasibleProblem(
            f"enum: none of the {len(modes)} mode combinations satisfies the step law; best "
            f"{[MODE_NAMES[m] for m in modes[best]]} with residual {residuals[best]:.3e} "
            f"(> {tol:.0e} × scale {scales[best]:.3e})"
        )
    # Among the valid candidates keep those as exact as the best one (a candidate of a wrong
    # mode can pass `tol` when an interval end is within tol of another, e.g. lo = −1e-10),
    # then the least-norm one (stable choice where the solution is not unique).
    relative = residuals[valid] / scales[valid]
    exact = valid[relative <= max(100.0 * relative.min(), 1e-14)]
    norms = np.einsum("ki,ki->k", P[exact], P[exact])
    k = int(exact[np.argmin(norms)])
    return make_solution(
        problem, P[k], U[k], "enum", len(modes), float(residuals[k]),
        modes=[MODE_NAMES[m] for m in modes[k]], n_solutions=int(valid.size),
    )


__all__ = ["enumerate_modes", "mode_solutions", "MAX_CONTACTS"]
