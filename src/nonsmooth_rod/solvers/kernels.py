"""The one-step solvers as compiled kernels behind one interface (for the compiled loops).

The step problem (dense): u = W p + q, m = 2 na unknowns ordered (N, T) per contact, with
the friction interval [lo_i p_N, hi_i p_N] of `problem.PlanarFrictionProblem`::

    solve_interval(solver_code, W, q, lo, hi, p, u, rtol, max_iter) -> (status, iterations, residual)

fills p and u = W p + q in place (p is also pgs's warm start) and returns a status code,
the solver's iterations (Lemke pivots, pgs sweeps, enum combinations) and the common
complementarity residual. ``rtol`` is the acceptance tolerance relative to the problem's
scale max(‖q‖∞, ‖p‖∞, ‖u‖∞); ``rtol ≤ 0`` or ``max_iter ≤ 0`` take the solver's default.

Every function here is decorated with `nonsmooth_rod._jit.jit`: numba-compiled when numba is
installed, the same source interpreted otherwise. Float64 arrays, int64 scalars only.
Non-finite data return KERNEL_NONFINITE (p = 0, u = q) instead of garbage.
"""
from __future__ import annotations

import numpy as np

from .._jit import jit
from .lemke import CONE, INTERVAL, RAY, RESIDUAL_TOL, SOLVED, _default_max_pivots, _lemke_friction_kernel

# Status codes.
KERNEL_SOLVED = 0
KERNEL_RAY = 1  # Lemke: no solution by complementary pivoting
KERNEL_NO_CONVERGENCE = 2  # iteration/pivot limit, or an answer that misses the step law
KERNEL_TOO_LARGE = 3  # enum beyond its contact limit
KERNEL_NONFINITE = 4  # NaN/inf in the data

# Solver codes.
SOLVER_LEMKE = 0
SOLVER_PGS = 1
SOLVER_ENUM = 2
SOLVER_CODES = {"lemke": SOLVER_LEMKE, "pgs": SOLVER_PGS, "enum": SOLVER_ENUM}
STATUS_NAMES = ("solved", "ray", "no-convergence", "too-large", "non-finite")

# Default acceptance (relative): the same for the three solvers, so that none of them fails
# where another one's answer would be accepted.
DEFAULT_RTOL = RESIDUAL_TOL


@jit
def all_finite(values) -> bool:
    """True when no entry of the (flattened) array is NaN or ±inf."""
    for x in values.ravel():
        if not np.isfinite(x):
            return False
    return True


@jit
def step_residual(W, q, lo, hi, p, u):
    """u = W p + q in place; return the complementarity residual (problem.py's formula)."""
    m = q.shape[0]
    for i in range(m):
        value = q[i]
        for j in range(m):
            value += W[i, j] * p[j]
        u[i] = value
    return contact_residual(lo, hi, p, u)


@jit
def contact_residual(lo, hi, p, u):
    """max over contacts of |min(p_N, u_N)| and |p_T − proj_[lo p_N⁺, hi p_N⁺](p_T − u_T)|."""
    residual = 0.0
    for i in range(lo.shape[0]):
        p_n = p[2 * i]
        p_t = p[2 * i + 1]
        r_n = abs(min(p_n, u[2 * i]))
        p_n_pos = max(p_n, 0.0)
        trial = p_t - u[2 * i + 1]
        low = lo[i] * p_n_pos
        high = hi[i] * p_n_pos
        projected = low if trial < low else (high if trial > high else trial)
        residual = max(residual, r_n, abs(p_t - projected))
    return residual


@jit
def problem_scale(q, p, u) -> float:
    """max(‖q‖∞, ‖p‖∞, ‖u‖∞), or 1 when all vanish: what a relative tolerance multiplies."""
    scale = 0.0
    for i in range(q.shape[0]):
        scale = max(scale, abs(q[i]), abs(p[i]), abs(u[i]))
    return scale if scale > 0.0 else 1.0


@jit
def lemke_interval(W, q, lo, hi, p, u, rtol, max_pivots):
    """Lemke on the interval LCP, then on the cone LCP if that fails (as lemke_friction does).

    Returns (status, pivots, residual); the first formulation's failure status when both fail.
    """
    first_status = KERNEL_SOLVED
    pivots = 0
    residual = 0.0
    for attempt in range(2):
        formulation = INTERVAL if attempt == 0 else CONE
        limit = max_pivots if max_pivots > 0 else _default_max_pivots((3 + attempt) * lo.shape[0])
        p_new, u_new, residual, status, pivots, norms = _lemke_friction_kernel(
            W, q, lo, hi, limit, formulation)
        scale = norms[2] if norms[2] > 0.0 else 1.0
        if status == SOLVED and residual <= rtol * scale:
            p[:] = p_new
            u[:] = u_new
            return KERNEL_SOLVED, pivots, residual
        if attempt == 0:
            first_status = KERNEL_RAY if status == RAY else KERNEL_NO_CONVERGENCE
    p[:] = 0.0
    u[:] = q
    return first_status, pivots, residual


@jit
def solve_interval(solver_code, W, q, lo, hi, p, u, rtol, max_iter):
    """Solve the dense step problem with solver SOLVER_LEMKE | SOLVER_PGS | SOLVER_ENUM.

    Fills p, u in place; returns (status, iterations, residual) (module docstring).
    """
    if not (all_finite(W) and all_finite(q) and all_finite(lo) and all_finite(hi)):
        p[:] = 0.0
        u[:] = q
        return KERNEL_NONFINITE, 0, np.inf
    if rtol <= 0.0:
        rtol = DEFAULT_RTOL
    if q.shape[0] == 0:
        return KERNEL_SOLVED, 0, 0.0
    if solver_code == SOLVER_LEMKE:
        return lemke_interval(W, q, lo, hi, p, u, rtol, max_iter)
    # pgs and enum: wired in the next commits
    p[:] = 0.0
    u[:] = q
    return KERNEL_NO_CONVERGENCE, 0, np.inf


__all__ = [
    "KERNEL_SOLVED", "KERNEL_RAY", "KERNEL_NO_CONVERGENCE", "KERNEL_TOO_LARGE", "KERNEL_NONFINITE",
    "SOLVER_LEMKE", "SOLVER_PGS", "SOLVER_ENUM", "SOLVER_CODES", "STATUS_NAMES", "DEFAULT_RTOL",
    "solve_interval", "lemke_interval", "step_residual", "contact_residual", "problem_scale", "all_finite",
]
