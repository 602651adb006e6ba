"""Closed-form enumeration of contact modes ("enum"), the reference solver for tiny steps.

Each contact is open, sticking or slipping in one of two directions; each mode turns the
contact's two conditions into two linear equations on p:

    open    p_N = 0,  p_T = 0                       (needs u_N ≥ 0)
    stick   u_N = 0,  u_T = 0                       (needs p_N ≥ 0, lo p_N ≤ p_T ≤ hi p_N)
    slip+   u_N = 0,  p_T = lo·p_N                  (needs p_N ≥ 0, u_T ≥ 0)
    slip−   u_N = 0,  p_T = hi·p_N                  (needs p_N ≥ 0, u_T ≤ 0)

All 4^n_c combinations are solved at once (a stack of 2n_c × 2n_c systems) with the
pseudo-inverse, i.e. the least-norm solution when a system is singular (statically
indeterminate sticking: only the sum of some impulses is determined). A candidate is a
solution when it satisfies the whole step law, which the common complementarity residual
measures exactly; among the solutions the least-norm impulse is returned.
"""
from __future__ import annotations

import itertools

import numpy as np

from ._common import make_solution
from .problem import InfeasibleProblem, PlanarFrictionProblem

OPEN, STICK, SLIP_POS, SLIP_NEG = range(4)
MODE_NAMES = ("open", "stick", "slip+", "slip-")

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


def _batched_residuals(problem: PlanarFrictionProblem, P: np.ndarray) -> np.ndarray:
    """complementarity_residual of every row of P (same formula, vectorised)."""
    U = P @ problem.W.T + problem.q
    pN, pT, uN, uT = P[:, 0::2], P[:, 1::2], U[:, 0::2], U[:, 1::2]
    pN_pos = np.maximum(pN, 0.0)
    projected = np.clip(pT - uT, problem.lo * pN_pos, problem.hi * pN_pos)
    r = np.maximum(np.abs(np.minimum(pN, uN)), np.abs(pT - projected))
    return r.max(axis=1), U


def enumerate_modes(problem: PlanarFrictionProblem, *, tol: float = 1e-10, rcond: float = 1e-12):
    """Solve the step by trying every mode combination; return a ContactSolution ("enum").

    ``tol``: a candidate is accepted when complementarity_residual ≤ tol · residual_scale.
    ``rcond``: relative singular-value cut-off of the pseudo-inverse (singular W).
    info["modes"] gives the mode combination the returned solution came from and
    info["n_solutions"] how many combinations produced a valid (possibly equal) solution.
    Raises InfeasibleProblem when no combination satisfies the law.
    """
    n_c = problem.n_contacts
    if n_c > MAX_CONTACTS:
        raise ValueError(f"enum: {n_c} contacts exceed the enumeration limit of {MAX_CONTACTS}")
    if n_c == 0:
        return make_solution(problem, np.zeros(0), problem.q.copy(), "enum", 0, 0.0)
    modes = _mode_table(n_c)
    A, b = _mode_systems(problem, modes)
    P = np.einsum("kij,kj->ki", np.linalg.pinv(A, rcond=rcond), b)
    residuals, U = _batched_residuals(problem, P)
    scales = np.maximum.reduce(
        [np.abs(P).max(axis=1), np.abs(U).max(axis=1), np.full(len(P), np.abs(problem.q).max())]
    )
    scales[scales == 0.0] = 1.0
    valid = np.flatnonzero(residuals <= tol * scales)
    if valid.size == 0:
        best = int(np.argmin(residuals / scales))
        raise InfeasibleProblem(
            f"enum: none of the {len(modes)} mode combinations satisfies the step law; best "
            f"{[MODE_NAMES[m] for m in modes[best]]} with residual {residuals[best]:.3e} "
            f"(> {tol:.0e} × scale {scales[best]:.3e})"
        )
    # least-norm among the valid candidates (stable choice where the solution is not unique)
    norms = np.einsum("ki,ki->k", P[valid], P[valid])
    k = int(valid[np.argmin(norms)])
    return make_solution(
        problem, P[k], U[k], "enum", len(modes), float(residuals[k]),
        modes=[MODE_NAMES[m] for m in modes[k]], n_solutions=int(valid.size),
    )


__all__ = ["enumerate_modes", "MAX_CONTACTS"]
