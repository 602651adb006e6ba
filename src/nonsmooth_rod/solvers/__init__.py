"""One-step nonsmooth solvers: one entry point, ``solve(problem, solver=..., **options)``.

    lemke                 Lemke's method on the exact lifted LCP (lemke.lemke_friction)
    pgs                   nonsmooth Gauss–Seidel with exact 2×2 contact solves
    enum                  enumeration of all contact-mode combinations (≤ 4 contacts)
    <backend>             Tresca fixed point of QPs through qpsolvers (e.g. osqp, clarabel)
    <backend>-relaxed     convex relaxation, one QP (has the sliding-separation artefact)

The exact solvers run compiled kernels (`solvers.kernels.solve_interval`, numba when installed,
the same source interpreted otherwise). `solvers.lcp.lemke(M, q)` solves any LCP
0 ≤ z ⊥ M z + q ≥ 0 (public API). Non-finite data are refused where the problem is made.

The QP solvers exist for every backend qpsolvers reports installed; qpsolvers itself is an
optional extra, imported only when a QP solver is listed or used.
"""
from __future__ import annotations

from collections.abc import Mapping

from ..validation import InputError, Integer, Number, quoted
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

EXACT_SOLVERS = ("lemke", "pgs", "enum")


def _exact_solver(name: str):
    """The exact solver's function, imported on first use (lemke pulls in numba) and cached."""
    function = _EXACT_LOADED.get(name)
    if function is None and name in EXACT_SOLVERS:
        if name == "lemke":
            from .lemke import lemke_friction as function
        elif name == "pgs":
            from .gauss_seidel import projected_gauss_seidel as function
        else:
            from .enumeration import enumerate_modes as function
        _EXACT_LOADED[name] = function
    return function


_EXACT_LOADED: dict = {}


def __getattr__(name: str):
    """`solvers.lcp` (the generic LCP API) and `solvers.kernels` load on first use (numba)."""
    if name in ("lcp", "kernels"):
        import importlib

        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def available_solvers() -> list[str]:
    """Solver names ``solve`` accepts: lemke, pgs, enum, then per installed QP backend its
    name and name + "-relaxed"."""
    from .qp import RELAXED_SUFFIX, installed_backends

    names = list(EXACT_SOLVERS)
    for backend in installed_backends():
        names += [backend, backend + RELAXED_SUFFIX]
    return names


# The settings each solver takes inside Moreau–Jean (`solver_options`), with their checks: the
# compiled kernels read tol (relative residual) and max_iter (Lemke's pivots, pgs's sweeps; enum
# has none); the QP solvers take theirs plus the backend's own settings (scalars, by name).
_TOL = Number(0.0, 1.0, open_lo=True)
SOLVER_SETTINGS = {
    "lemke": {"tol": _TOL, "max_iter": Integer(1, 10**9)},
    "pgs": {"tol": _TOL, "max_iter": Integer(1, 10**9)},
    "enum": {"tol": _TOL},
}
QP_SETTINGS = {"tol": _TOL, "max_iter": Integer(1, 10**6), "check_tol": _TOL}
RELAXED_QP_SETTINGS = {"check_tol": _TOL}


def check_solver_options(solver: str, options) -> dict:
    """`solver_options` of the named solver, checked key by key (InputError naming the key):
    a table of known settings, each a number in its range; QP backends' own settings pass
    through by name if they are plain scalars (the backend checks their values)."""
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise InputError(f"solver_options must be a table of settings (e.g. {{tol = 1e-10}}), got {quoted(options)}")
    exact = solver in SOLVER_SETTINGS
    settings = SOLVER_SETTINGS.get(solver) or (RELAXED_QP_SETTINGS if solver.endswith("-relaxed") else QP_SETTINGS)
    checked = {}
    for key, value in options.items():
        if key in settings:
            checked[key] = settings[key](f"solver_options.{key}", value)
        elif exact or not (isinstance(key, str) and key.isidentifier()):
            raise InputError(f"solver_options: unknown setting {quoted(key)} for solver {solver!r}; "
                             f"it takes: {', '.join(settings) or 'none'}")
        elif isinstance(value, bool) or (isinstance(value, str) and value.isprintable()):
            checked[key] = value
        else:
            checked[key] = Number()(f"solver_options.{key}", value)
    return checked


def solve(problem: PlanarFrictionProblem, solver: str = "lemke", **options) -> ContactSolution:
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
    if not isinstance(solver, str):
        raise InputError(f"unknown solver {solver!r}; choose from: {', '.join(available_solvers())}")
    run = _exact_solver(solver)
    if run is not None:
        return run(problem, **options)
    from .qp import RELAXED_SUFFIX, installed_backends, relaxed_qp, tresca_fixed_point

    backends = installed_backends()
    if solver in backends:
        return tresca_fixed_point(problem, backend=solver, **options)
    if solver.endswith(RELAXED_SUFFIX) and solver[: -len(RELAXED_SUFFIX)] in backends:
        return relaxed_qp(problem, backend=solver[: -len(RELAXED_SUFFIX)], **options)
    raise InputError(f"unknown solver {solver!r}; choose from: {', '.join(available_solvers())}")


__all__ = [
    "solve",
    "available_solvers",
    "check_solver_options",
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
