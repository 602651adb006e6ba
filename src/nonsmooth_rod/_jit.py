"""One decorator for every compiled kernel: numba when it is installed, plain Python otherwise.

The same source runs both ways, so there is never a second copy of a kernel to keep in step.
`NONSMOOTH_ROD_NO_JIT=1` forces the interpreted path (tests use it to compare the two).

Compiled kernels are cached on disk (numba's `cache=True`), next to the package by default.
Where that folder is read-only (a system install, a container image) the cache goes to a
user folder instead — `$XDG_CACHE_HOME/nonsmooth-rod/numba` or `~/.cache/nonsmooth-rod/numba` —
unless `NUMBA_CACHE_DIR` is set, which always wins.
"""
from __future__ import annotations

import os
import warnings
from pathlib import Path


def _user_cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "nonsmooth-rod" / "numba"


def _choose_cache_dir() -> None:
    """Point numba at a writable cache when the package folder is not (before numba is imported)."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    here = Path(__file__).resolve().parent
    if os.access(here, os.W_OK):
        return
    target = _user_cache_dir()
    try:
        target.mkdir(parents=True, exist_ok=True)
    except OSError:
        return  # numba then compiles in memory each run; still correct
    os.environ["NUMBA_CACHE_DIR"] = str(target)


_choose_cache_dir()

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
