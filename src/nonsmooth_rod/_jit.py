"""One decorator for every compiled kernel: numba when it is installed, plain Python otherwise.

The same source runs both ways, so there is never a second copy of a kernel to keep in step.
`NONSMOOTH_ROD_NO_JIT=1` forces the interpreted path (tests use it to compare the two).
"""
from __future__ import annotations

import os
import warnings

try:  # numba is the optional `fast` extra
    import numba as _numba
except ImportError:  # pragma: no cover - exercised on installs without numba
    _numba = None

ENABLED = _numba is not None and os.environ.get("NONSMOOTH_ROD_NO_JIT", "") in ("", "0")
_warned = False


def _warn_once() -> None:
    global _warned
    if _numba is None and not _warned:
        _warned = True
        warnings.warn("numba is not installed: the compiled Moreau–Jean engine is off and runs are about "
                      "30x slower (pip install 'nonsmooth-rod[fast]')", RuntimeWarning, stacklevel=3)


def jit(function):
    """numba.njit(cache=True) of `function` when compiling is enabled; `function` itself otherwise.

    Kernels take float64 arrays and int64 indices only, so each compiles to one signature.
    """
    if not ENABLED:
        _warn_once()
        return function
    return _numba.njit(cache=True)(function)


__all__ = ["jit", "ENABLED"]
