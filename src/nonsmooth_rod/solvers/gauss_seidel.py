"""Nonsmooth (projected) Gauss–Seidel on the contact impulses ("pgs").

A sweep visits the contacts in order and solves each contact's 2×2 local problem exactly,
the other contacts' impulses frozen at their latest values. Contact i sees

    u_i = W_ii p_i + v_i,    v_i = q_i + Σ_{j≠i} W_ij p_j,    W_ii = [[a, b], [b, c]],

and its exact local solution is the first consistent case of

    open   v_N ≥ 0                     → p_i = 0
    stick  p_i = −W_ii⁻¹ v_i           if p_N ≥ 0 and lo p_N ≤ p_T ≤ hi p_N
    slip   p_T = lo·p_N (needs u_T ≥ 0) or p_T = hi·p_N (needs u_T ≤ 0),
           p_N from the normal row u_N = 0: p_N = −v_N / (a + b·bound), needs a + b·bound > 0.

Convergence is judged on the common residual: stop when complementarity_residual ≤
tol · residual_scale (max-norm of p, u, q) after a sweep. With one contact the first sweep is
exact. Plain Python floats: for 1–2 contacts they beat numpy calls by a wide margin.
"""
from __future__ import annotations

import numpy as np

from ._common import RESIDUAL_FLOOR, make_solution, relative_floor, velocities_and_residual
from .problem import NoConvergence, PlanarFrictionProblem

# The local stick system counts as singular when det(W_ii) ≤ SINGULAR_DET · a·c. A disk or
# corner contact of a body with rotational inertia never gets there, but e.g. a contact on
# a body with a single translational DOF would (W_ii of rank one).
SINGULAR_DET = 1e-13
# Round-off slack of the local consistency tests (relative to the quantities compared).
LOCAL_SLACK = 1e-12


def solve_contact(a, b, c, v_n, v_t, lo, hi):
    """Exact solution (p_N, p_T) of one contact's 2×2 problem, or None when no case fits.

    The cases are tried in the order open, stick, slip at lo, slip at hi; the first that is
    consistent is returned (for an ill-posed local problem with several solutions this is
    the one Gauss–Seidel keeps).
    """
    if v_n >= 0.0:
        return 0.0, 0.0
    det = a * c - b * b
    if det > SINGULAR_DET * a * c:
        p_n = (-c * v_n + b * v_t) / det
        p_t = (b * v_n - a * v_t) / det
        slack = LOCAL_SLACK * (abs(p_n) + abs(p_t))
        if p_n >= 0.0 and lo * p_n - slack <= p_t <= hi * p_n + slack:
            return p_n, min(max(p_t, lo * p_n), hi * p_n)
    for bound, sign in ((lo, 1.0), (hi, -1.0)):
        normal_stiffness = a + b * bound
        if normal_stiffness > 0.0:
            p_n = -v_n / normal_stiffness
            u_t = (b + c * bound) * p_n + v_t
            if sign * u_t >= -LOCAL_SLACK * (abs(v_t) + abs((b + c * bound) * p_n)):
                return p_n, bound * p_n
    return None


def projected_gauss_seidel(
    problem: PlanarFrictionProblem,
    *,
    tol: float = 1e-12,
    max_iter: int = 10000,
    p0=None,
):
    """Solve the step by nonsmooth Gauss–Seidel sweeps; return a ContactSolution ("pgs").

    ``tol``: stop when complementarity_residual ≤ tol · residual_scale (checked after each
    sweep). ``max_iter``: sweep limit; reaching it raises NoConvergence naming the sweeps and
    the residual. ``p0``: warm start (e.g. the previous step's impulses); default zero.
    iterations = sweeps.
    """
    W = problem.W.tolist()
    q = problem.q.tolist()
    lo = problem.lo.tolist()
    hi = problem.hi.tolist()
    n_c = problem.n_contacts
    p = [0.0] * (2 * n_c) if p0 is None else [float(x) for x in np.asarray(p0, dtype=float).ravel()]
    if len(p) != 2 * n_c:
        raise ValueError(f"pgs: warm start has {len(p)} entries, the problem has {2 * n_c}")
    local = [(W[2 * i][2 * i], W[2 * i][2 * i + 1], W[2 * i + 1][2 * i + 1]) for i in range(n_c)]
    u, residual = velocities_and_residual(W, q, lo, hi, p)
    for sweep in range(1, max_iter + 1):
        for i in range(n_c):
            N, T = 2 * i, 2 * i + 1
            a, b, c = local[i]
            p_n, p_t = p[N], p[T]
            W_n, W_t = W[N], W[T]
            v_n = q[N] + sum(w * x for w, x in zip(W_n, p)) - a * p_n - b * p_t
            v_t = q[T] + sum(w * x for w, x in zip(W_t, p)) - b * p_n - c * p_t
            solution = solve_contact(a, b, c, v_n, v_t, lo[i], hi[i])
            if solution is not None:
                p[N], p[T] = solution
        u, residual = velocities_and_residual(W, q, lo, hi, p)
        scale = relative_floor(p, u, q)
        if residual <= tol * scale + RESIDUAL_FLOOR:
            return make_solution(problem, p, u, "pgs", sweep, residual)
    raise NoConvergence(
        f"pgs: no convergence after {max_iter} sweeps, residual {residual:.3e} > "
        f"tol {tol:.0e} × scale {relative_floor(p, u, q):.3e}"
    )


__all__ = ["projected_gauss_seidel", "solve_contact"]
