"""The one-step solvers as compiled kernels behind one interface (for the compiled loops).

The step problem (dense): u = W p + q, m = 2 na unknowns ordered (N, T) per contact, with
the friction interval [lo_i p_N, hi_i p_N] of `problem.PlanarFrictionProblem`::

    solve_interval(solver_code, W, q, lo, hi, p, u, rtol, max_iter) -> (status, iterations, residual)

(`solve_interval_into`: the same in a caller's scratch; the codes are registry.SOLVERS')

fills p and u = W p + q in place (p on entry is the warm start: pgs's first iterate, the basis
Lemke tries first) and returns a status code,
the solver's iterations (Lemke pivots, pgs sweeps, enum combinations) and the common
complementarity residual. ``rtol`` is the tolerance on that residual relative to the
problem's scale max(‖q‖∞, ‖p‖∞, ‖u‖∞); ``rtol ≤ 0`` takes the solver's default (Lemke and
enum accept DEFAULT_RTOL; pgs aims for PGS_RTOL and accepts DEFAULT_RTOL once it stalls).
``max_iter``: Lemke's pivot limit, pgs's sweep limit (≤ 0: their defaults); enum ignores it
(all 4^na combinations up to enumeration.MAX_CONTACTS contacts, KERNEL_TOO_LARGE beyond).
On any status but KERNEL_SOLVED, p = 0 and u = q (pgs leaves its last iterate).

Large scenes: `pgs_block` on the block-sparse Delassus (indptr, indices, blocks; see
`delassus.py`) costs O(nonzero blocks) per sweep.

Every function here is decorated with `nonsmooth_rod._jit.jit`: numba-compiled when numba is
installed, the same source interpreted otherwise. Float64 arrays, int64 scalars only.
Non-finite data return KERNEL_NONFINITE (p = 0, u = q) instead of garbage.
"""
from __future__ import annotations

import numpy as np

from .._jit import jit, jit_borrowing, jit_inline
from ._common import loop_array
from .enumeration import enum_interval
from .delassus import dense_to_blocks
from .gauss_seidel import pgs_block, pgs_block_into, pgs_dense, pgs_dense_into
from .lemke import CONE, INTERVAL, RAY, SOLVED, default_max_pivots, _lemke_friction_into, warm_interval_answer

from .kernel_base import (
    DEFAULT_RTOL,
    KERNEL_NO_CONVERGENCE,
    KERNEL_NONFINITE,
    KERNEL_RAY,
    KERNEL_SOLVED,
    KERNEL_TOO_LARGE,
    BLOCK_SPARSE_CODES,
    SOLVER_CODES,
    SOLVER_ENUM,
    SOLVER_LEMKE,
    SOLVER_PGS,
    STATUS_NAMES,
    all_finite,
    carve,
    carve_matrix,
    contact_residual,
    fits_scratch,
    fitting_scratch,
    problem_scale,
    solver_floats,
    solver_ints,
    solver_scratch,
    step_residual,
    takes_block_sparse,
)


@jit_borrowing
def lemke_interval(W, q, lo, hi, p, u, rtol, max_pivots, floats, ints):
    """Lemke on the interval LCP, then on the cone LCP if that fails (as lemke_friction does),
    in the scratch (floats, ints) (kernel_base.solver_scratch of ≥ lo.shape[0] contacts).
    p on entry is the warm start: the basis of the interval LCP it sits at is tried first
    (lemke.warm_interval_answer: zero pivots when that basis still solves the problem to rtol).

    Returns (status, pivots, residual); the first formulation's failure status when both fail.
    Compiled without reference counting (the step's hot path; it allocates nothing).
    """
    if rtol <= 0.0:
        rtol = DEFAULT_RTOL
    n = 3 * lo.shape[0]  # (the warm start's room: the cold path's scratch, which it then refills)
    residual = warm_interval_answer(W, q, lo, hi, p, u, rtol, floats[:n * n + 2 * n], ints[:2 * n])
    if residual >= 0.0:
        return KERNEL_SOLVED, 0, residual
    first_status = KERNEL_SOLVED
    pivots = 0
    residual = 0.0
    for attempt in range(2):
        formulation = INTERVAL if attempt == 0 else CONE
        limit = max_pivots if max_pivots > 0 else default_max_pivots((3 + attempt) * lo.shape[0])
        residual, status, pivots, q_norm, W_norm, scale = _lemke_friction_into(W, q, lo, hi, limit, formulation,
                                                                              floats, ints, p, u)
        if status == SOLVED and residual <= rtol * (scale if scale > 0.0 else 1.0):
            return KERNEL_SOLVED, pivots, residual
        if attempt == 0:
            first_status = KERNEL_RAY if status == RAY else KERNEL_NO_CONVERGENCE
    for i in range(q.shape[0]):
        p[i], u[i] = 0.0, q[i]
    return first_status, pivots, residual


@jit_borrowing
def _screen(W, q, lo, hi, p, u):
    """The status of a problem no solver needs to see (non-finite data: p = 0, u = q; no
    contacts), or −1 when a solver must run. (Borrowing, on the step's hot path.)"""
    if not (all_finite(W) and all_finite(q) and all_finite(lo) and all_finite(hi)):
        for i in range(q.shape[0]):
            p[i], u[i] = 0.0, q[i]
        return KERNEL_NONFINITE
    if q.shape[0] == 0:
        return KERNEL_SOLVED
    return -1


@jit
def _screened(status):
    """(status, iterations, residual) of a problem `_screen` answered."""
    return status, 0, (np.inf if status == KERNEL_NONFINITE else 0.0)


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def solve_lemke_into(W, q, lo, hi, p, u, rtol, max_iter, floats, ints):
    """lemke_interval behind the common screen, in the scratch (floats, ints: at least
    kernel_base.solver_scratch of these contacts — the counting callers' fitting_scratch).
    Borrowing (the step's hot path): it allocates nothing."""
    status = _screen(W, q, lo, hi, p, u)
    if status >= 0:
        return _screened(status)
    return lemke_interval(W, q, lo, hi, p, u, rtol, max_iter, floats, ints)


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def solve_pgs_into(W, q, lo, hi, p, u, rtol, max_iter, floats, ints):
    """pgs_dense_into behind the common screen, in the scratch (floats, ints: kernel_base.solver_scratch
    of these contacts holds it). Borrowing (the step's dense pgs: a step with joints)."""
    status = _screen(W, q, lo, hi, p, u)
    if status >= 0:
        return _screened(status)
    return pgs_dense_into(W, q, lo, hi, p, u, rtol, max_iter, floats, ints)


@jit
def solve_enum(W, q, lo, hi, p, u, rtol, max_iter):
    """enum_interval behind the common screen (max_iter has no meaning for enum)."""
    status = _screen(W, q, lo, hi, p, u)
    if status >= 0:
        return _screened(status)
    return enum_interval(W, q, lo, hi, p, u, rtol, 0)


@jit_borrowing
def solve_interval_into(solver_code, W, q, lo, hi, p, u, rtol, max_iter, floats, ints):
    """The compiled dispatch: the dense step problem solved by the solver of code `solver_code`
    (registry.SOLVERS), Lemke in the scratch (floats, ints). One branch per compiled solver of
    the table — numba calls a kernel by its name, not out of a table; the loop reads the code at
    run time, so every solver compiles into the one loop. Fills p, u in place; returns (status,
    iterations, residual) (module docstring). Borrowing (the step's hot path): the scratch
    must fit these contacts (solver_scratch's sizes: fitting_scratch in the counting caller)."""
    if solver_code == SOLVER_LEMKE:
        return solve_lemke_into(W, q, lo, hi, p, u, rtol, max_iter, floats, ints)
    if solver_code == SOLVER_PGS:
        return solve_pgs_into(W, q, lo, hi, p, u, rtol, max_iter, floats, ints)
    if solver_code == SOLVER_ENUM:
        return solve_enum(W, q, lo, hi, p, u, rtol, max_iter)
    for i in range(q.shape[0]):  # an unknown solver code: nothing solved
        p[i], u[i] = 0.0, q[i]
    return KERNEL_NO_CONVERGENCE, 0, np.inf


def solve_interval(solver_code, W, q, lo, hi, p, u, rtol, max_iter):
    """solve_interval_into with scratch of its own (Lemke's and pgs's; enum needs none), allocated
    here: Python runs the loop's compiled dispatch with the loop's argument types
    (_common.loop_array; p, u are filled in place: the caller's float64 arrays)."""
    na = lo.shape[0] if solver_code != SOLVER_ENUM else 0
    return solve_interval_into(int(solver_code), loop_array(W), loop_array(q), loop_array(lo), loop_array(hi), p, u,
                               float(rtol), int(max_iter), np.empty(solver_floats(na)),
                               np.empty(solver_ints(na), dtype=np.int64))


__all__ = [
    "KERNEL_SOLVED", "KERNEL_RAY", "KERNEL_NO_CONVERGENCE", "KERNEL_TOO_LARGE", "KERNEL_NONFINITE",
    "SOLVER_LEMKE", "SOLVER_PGS", "SOLVER_ENUM", "SOLVER_CODES", "BLOCK_SPARSE_CODES", "STATUS_NAMES", "DEFAULT_RTOL",
    "solve_interval", "solve_interval_into", "solve_lemke_into", "solver_scratch", "fitting_scratch", "carve", "carve_matrix", "solve_pgs_into", "solve_enum", "lemke_interval", "pgs_block", "pgs_block_into", "pgs_dense", "pgs_dense_into", "fits_scratch", "solver_floats", "solver_ints", "dense_to_blocks", "enum_interval", "step_residual", "contact_residual", "problem_scale", "all_finite", "takes_block_sparse",
]
