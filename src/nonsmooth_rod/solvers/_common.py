"""Small pieces shared by the solver modules (not public API)."""
from __future__ import annotations

import types

import numpy as np

from ..validation import InputError
from .problem import ContactSolution, PlanarFrictionProblem, _require_finite, contact_states


def velocities_and_residual(W, q, lo, hi, p):
    """u = W p + q (a list) and the `complementarity_residual`, through the kernels'
    `kernel_base.step_residual` (the tests hold it to problem.py's numpy formula)."""
    from .kernel_base import step_residual

    q = np.array(q, dtype=float)
    p = np.array(p, dtype=float)
    u = np.zeros_like(q)
    residual = step_residual(np.array(W, dtype=float), q, np.array(lo, dtype=float),
                             np.array(hi, dtype=float), p, u)
    return u.tolist(), float(residual)


# Residuals below this count as zero whatever the scale: with subnormal data (|q| ~ 1e-313)
# tol · scale underflows below the smallest representable residual.
RESIDUAL_FLOOR = 1e-300


def max_abs(*vectors) -> float:
    """Max-norm over several float sequences (0 for empty)."""
    return max((max(map(abs, v), default=0.0) for v in vectors), default=0.0)


def relative_floor(*vectors) -> float:
    """`problem.residual_scale` on lists: the scale a relative tolerance multiplies."""
    scale = max_abs(*vectors)
    return scale if scale > 0.0 else 1.0


def make_solution(
    problem: PlanarFrictionProblem, p, u, solver: str, iterations: int, residual: float,
    state_tol: float = 1e-9, **info
) -> ContactSolution:
    """ContactSolution with the per-contact states every solver reports in ``info["states"]``.

    ``state_tol``: relative tolerance of `contact_states` (looser for the inexact QP solvers).
    """
    info["states"] = contact_states(problem, p, u, state_tol)
    p = np.asarray(p, dtype=float)
    u = np.asarray(u, dtype=float)
    return ContactSolution(p=p, u=u, solver=solver, iterations=iterations, residual=residual, info=info)


def require_finite_array(name: str, values: np.ndarray, who: str = "") -> None:
    """InputError naming the argument (and ``who`` refused it) at its first NaN/inf entry."""
    try:
        _require_finite(name, values)
    except InputError as error:
        raise InputError(f"{who}: {error}" if who else str(error)) from None


_INTERPRETED: dict = {}


def interpreted(function):
    """The plain-Python twin of a `_jit.jit` kernel: its source run by the interpreter, and so
    every compiled kernel it calls (their globals rebound to interpreted twins, recursively).
    Without numba the kernels are plain functions already and come back unchanged. Lets
    ``jit=False`` and the compiled-vs-interpreted tests run the one source both ways."""
    python = getattr(function, "py_func", None)
    if python is None:
        return function
    twin = _INTERPRETED.get(id(function))
    if twin is None:
        namespace = dict(python.__globals__)
        twin = types.FunctionType(python.__code__, namespace, python.__name__, python.__defaults__,
                                  python.__closure__)
        _INTERPRETED[id(function)] = twin
        for name, value in list(namespace.items()):
            if getattr(value, "py_func", None) is not None and callable(value):
                namespace[name] = interpreted(value)
    return twin


# ---------------------------------------------------------------- one compiled entry per kernel
# numba compiles a dispatcher's whole call subtree into its own machine code, once per argument
# type signature: a compiled wrapper that allocates and calls an `_into` kernel, or the kernel
# called with a readonly, strided or other-dtype array, compiles that subtree again (seconds).
# So Python calls the very kernels the compiled loop calls, with the loop's argument types, and
# loads the loop's cached code (docs/performance.md, "One compiled entry per kernel").

def loop_array(values, dtype=np.float64) -> np.ndarray:
    """`values` as the compiled loop passes its arrays: C-contiguous, writable, float64 (int64 for
    dtype=np.int64). An array already so is returned itself (an output filled in place stays the
    caller's); a readonly, strided or other-dtype one is copied."""
    return np.require(values, dtype=dtype, requirements=["C", "W"])


def python_body(kernel):
    """A `_jit.jit_inline` kernel's Python source with the kernels it calls still compiled: how
    Python runs a kernel that exists only inlined into its compiled callers (compiled on its own
    it would compile its callees' subtree again). The function itself without numba."""
    return getattr(kernel, "py_func", kernel)
