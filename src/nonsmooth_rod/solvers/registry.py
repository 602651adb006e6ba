"""The one table of one-step solvers: every fact about a solver is written here once.

Each row (`SolverSpec`) says what `solver=` accepts, the compiled kernels' code of the solver
(the Moreau–Jean loop reads it from iparams; None: a Python solver the loop calls back), whether
it is one of our exact solvers or a QP backend, the `solver_options` it takes with their checks,
the function `solvers.solve` runs, and — for the QP backends, an optional extra — how the
installed ones are found (probed once per process). Everything else is derived from the table:
`SOLVER_CODES` and `EXACT_SOLVERS`, `available_solvers()`, the check of a solver's name
(`require_solver`, for the driver, scene files and the command line) and of its options
(`check_solver_options`), and the compiled loop's per-code facts (`BLOCK_SPARSE_CODES`).

Adding a compiled solver: a row here (the next code) and its kernel, plus a branch in the
compiled dispatch `kernels.solve_interval_into` — numba calls a kernel by name, not from a table.
"""
from __future__ import annotations

import dataclasses
import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from ..validation import InputError, Integer, Number, quoted

EXACT, QP = "exact", "qp"

_TOL = Number(0.0, 1.0, open_lo=True)


@dataclass(frozen=True)
class SolverSpec:
    """One solver (or, for a QP family, one solver per installed backend)."""

    # what `solver=` takes; a QP family's names are "{backend}" + a suffix, one per installed backend
    name: str
    # the compiled kernels' code (kernels.solve_interval_into, the loop's iparams); None: Python
    code: int | None
    kind: str  # EXACT (our compiled kernels) or QP (a QP backend through qpsolvers)
    # solver_options it accepts inside Moreau–Jean, each with its check
    settings: Mapping[str, Callable] = field(default_factory=dict)
    # other scalar settings pass through by name (a QP backend's own, which the backend checks)
    backend_settings: bool = False
    entry: str = ""  # "module:function" that `solvers.solve` runs on a PlanarFrictionProblem
    block_sparse: bool = False  # the compiled loop hands it the block-sparse W (pgs), not the dense one
    extra: str | None = None  # the optional extra that installs it (pip install nonsmooth-rod[qp])
    probe: str | None = None  # "module:function" listing the installed backends (cached there)
    backend: str | None = None  # the QP backend of a row expanded from a family (filled by installed)


SOLVERS = (
    # Lemke's method on the exact lifted LCP
    SolverSpec("lemke", 0, EXACT, {"tol": _TOL, "max_iter": Integer(1, 10**9)}, entry="lemke:lemke_friction"),
    # nonsmooth Gauss–Seidel with exact 2×2 contact solves, on the block-sparse W
    SolverSpec("pgs", 1, EXACT, {"tol": _TOL, "max_iter": Integer(1, 10**9)},
               entry="gauss_seidel:projected_gauss_seidel", block_sparse=True),
    # enumeration of all contact-mode combinations (≤ 4 contacts a group)
    SolverSpec("enum", 2, EXACT, {"tol": _TOL}, entry="enumeration:enumerate_modes"),
    # per installed backend: Tresca fixed point of QPs through qpsolvers (e.g. osqp, clarabel)
    SolverSpec("{backend}", None, QP, {"tol": _TOL, "max_iter": Integer(1, 10**6), "check_tol": _TOL},
               backend_settings=True, entry="qp:tresca_fixed_point", extra="qp", probe="qp:installed_backends"),
    # per installed backend: the convex relaxation, one QP (has the sliding-separation artefact)
    SolverSpec("{backend}-relaxed", None, QP, {"check_tol": _TOL}, backend_settings=True,
               entry="qp:relaxed_qp", extra="qp", probe="qp:installed_backends"),
)

DEFAULT_SOLVER = SOLVERS[0].name
EXACT_SOLVERS = tuple(s.name for s in SOLVERS if s.probe is None)  # always there, in table order
SOLVER_CODES = {s.name: s.code for s in SOLVERS if s.code is not None}  # name -> compiled code
_BY_CODE = sorted((s for s in SOLVERS if s.code is not None), key=lambda s: s.code)
if [s.code for s in _BY_CODE] != list(range(len(_BY_CODE))):  # the compiled loop indexes per-code facts
    raise ValueError(f"solver codes must be 0, 1, ... in the table, got {[s.code for s in _BY_CODE]}")
BLOCK_SPARSE_CODES = tuple(bool(s.block_sparse) for s in _BY_CODE)  # per code: takes the block-sparse W


# the command line's --solver help, from the table
SOLVER_HELP = (f"Moreau–Jean one-step solver: {', '.join(EXACT_SOLVERS)}, or a QP backend of the optional extra "
               f"[qp] ('<backend>', '<backend>-relaxed'); default {DEFAULT_SOLVER}")


def spec(name: str) -> SolverSpec:
    """The row of a solver always there (an exact one), by name (for the compiled dispatch)."""
    return next(s for s in SOLVERS if s.name == name and s.probe is None)


def _function(path: str):
    module, _, name = path.partition(":")
    return getattr(importlib.import_module(f".{module}", __package__), name)


def installed() -> list[SolverSpec]:
    """Every solver `solve` accepts: the rows always there, then per installed backend (in the
    probe's order) its rows of each family (osqp, osqp-relaxed, clarabel, ...)."""
    rows = [s for s in SOLVERS if s.probe is None]
    families = [s for s in SOLVERS if s.probe is not None]
    for probe in dict.fromkeys(s.probe for s in families):
        for backend in _function(probe)():
            rows += [dataclasses.replace(s, name=s.name.format(backend=backend), backend=backend)
                     for s in families if s.probe == probe]
    return rows


def available_solvers() -> list[str]:
    """The names `solve` and Moreau–Jean's `solver` accept (the exact ones first)."""
    return [s.name for s in installed()]


def find_solver(name) -> SolverSpec | None:
    """The row of an accepted solver name, or None."""
    if not isinstance(name, str):
        return None
    if name in EXACT_SOLVERS:
        return spec(name)
    return next((s for s in installed() if s.name == name), None)


def require_solver(field_name: str, name) -> SolverSpec:
    """The row of `name`, or a one-line InputError naming the field and listing the choices."""
    found = find_solver(name)
    if found is None:
        raise InputError(f"unknown {field_name} {quoted(name)}; choose from: {', '.join(available_solvers())}")
    return found


def check_solver_options(solver: str, options) -> dict:
    """`solver_options` of the named solver, checked key by key (InputError naming the key):
    the row's settings, each a number in its range; a QP backend's own settings pass through by
    name if they are plain scalars (the backend checks their values)."""
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise InputError(f"solver_options must be a table of settings (e.g. {{tol = 1e-10}}), got {quoted(options)}")
    row = require_solver("solver", solver)
    checked = {}
    for key, value in options.items():
        if key in row.settings:
            checked[key] = row.settings[key](f"solver_options.{key}", value)
        elif not row.backend_settings or not (isinstance(key, str) and key.isidentifier()):
            raise InputError(f"solver_options: unknown setting {quoted(key)} for solver {solver!r}; "
                             f"it takes: {', '.join(row.settings) or 'none'}")
        elif isinstance(value, bool) or (isinstance(value, str) and value.isprintable()):
            checked[key] = value
        else:
            checked[key] = Number()(f"solver_options.{key}", value)
    return checked


@dataclass(frozen=True)
class SolverName:
    """An options field's check (validation.option): a solver name of the table."""

    def __call__(self, field_name: str, value) -> str:
        return require_solver(field_name, value).name


_LOADED: dict = {}


def solver_function(row: SolverSpec):
    """The function `solve` runs for a row, (problem, **options) → ContactSolution; imported on
    first use (lemke pulls in numba) and cached."""
    function = _LOADED.get(row.entry)
    if function is None:
        function = _LOADED[row.entry] = _function(row.entry)
    if row.backend is None:
        return function
    return lambda problem, **options: function(problem, backend=row.backend, **options)


__all__ = ["SolverSpec", "SOLVERS", "EXACT", "QP", "DEFAULT_SOLVER", "EXACT_SOLVERS", "SOLVER_CODES",
           "BLOCK_SPARSE_CODES", "SOLVER_HELP", "spec", "installed", "available_solvers", "find_solver",
           "require_solver", "SolverName", "check_solver_options", "solver_function"]
