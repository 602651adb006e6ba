"""One-step nonsmooth solvers: one entry point, ``solve(problem, solver=..., **options)``.

The solvers, their names, codes, options and entry functions are one table,
`solvers.registry.SOLVERS`: the exact solvers (lemke, pgs, enum: compiled kernels,
`solvers.kernels.solve_interval`, numba when installed, the same source interpreted otherwise)
and, per QP backend qpsolvers reports installed (an optional extra, imported only when a QP
solver is listed or used), its Tresca fixed point ``<backend>`` and its convex relaxation
``<backend>-relaxed``. `solvers.lcp.lemke(M, q)` solves any LCP 0 ≤ z ⊥ M z + q ≥ 0 (public
API). Non-finite data are refused where the problem is made.
"""
from __future__ import annotations

from ..validation import InputError
from .problem import (
    ContactSolution,
    InfeasibleProblem,
    NoConvergence,
    PlanarFrictionProblem,
    RayTermination,
    SolverError,
    complementarity_residual,
    contact_states,
    residual_scale,
)
from .registry import (DEFAULT_SOLVER, EXACT_SOLVERS, available_solvers, check_solver_options, find_solver,
                       require_solver, solver_function)


def __getattr__(name: str):
    """`solvers.lcp` (the generic LCP API) and `solvers.kernels` load on first use (numba)."""
    if name in ("lcp", "kernels"):
        import importlib

        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def solve(problem: PlanarFrictionProblem, solver: str = DEFAULT_SOLVER, **options) -> ContactSolution:
    """Solve one step's contact problem with the named solver.

    ``options`` go to the solver (e.g. pgs: tol, max_iter, p0; lemke: formulation,
    max_pivots; QP: tol, max_iter, check_tol and backend settings). The returned
    ContactSolution carries iterations, the common residual and info["states"] (per contact
    "open" | "stick" | "slip+" | "slip-"). Raises SolverError subclasses on failure and
    InputError (a ValueError) for an unknown solver name, listing the choices. Non-finite
    data never get here: PlanarFrictionProblem refuses them (InputError naming W, q, lo or hi).
    """
    if not isinstance(problem, PlanarFrictionProblem):
        raise InputError(f"solve: problem must be a PlanarFrictionProblem, got {type(problem).__name__}")
    return solver_function(require_solver("solver", solver))(problem, **options)


__all__ = [
    "solve",
    "available_solvers",
    "check_solver_options",
    "require_solver",
    "find_solver",
    "EXACT_SOLVERS",
    "DEFAULT_SOLVER",
    "ContactSolution",
    "PlanarFrictionProblem",
    "SolverError",
    "RayTermination",
    "NoConvergence",
    "InfeasibleProblem",
    "complementarity_residual",
    "contact_states",
    "residual_scale",
]
