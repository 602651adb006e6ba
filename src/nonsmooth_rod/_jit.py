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

import importlib.util

# numba is the optional `fast` extra; it is imported only when a kernel is first decorated, so
# `import nonsmooth_rod` stays light.
HAVE_NUMBA = importlib.util.find_spec("numba") is not None
ENABLED = HAVE_NUMBA and os.environ.get("NONSMOOTH_ROD_NO_JIT", "") in ("", "0")
_warned = False


NO_NUMBA_MESSAGE = ("numba is not installed: Moreau–Jean runs interpreted, about 30x slower "
                    "(pip install 'nonsmooth-rod[fast]')")


def _warn_once() -> None:
    """Said once per process, and only by a run that would have been compiled (the event-driven
    and regularized methods never use numba): through the CLI's notifier (one line on stderr)
    when one is set, else as a RuntimeWarning."""
    global _warned
    if HAVE_NUMBA or _warned:
        return
    _warned = True
    if _notifier is not None:
        _notifier(NO_NUMBA_MESSAGE)
    else:
        warnings.warn(NO_NUMBA_MESSAGE, RuntimeWarning, stacklevel=4)


def jit(function):
    """numba.njit(cache=True) of `function` when compiling is enabled; `function` itself otherwise.

    Kernels take float64 arrays and int64 indices only, so each compiles to one signature.
    """
    if not ENABLED:
        return function
    import numba

    if not _purged:
        purge_stale_kernels()
    return numba.njit(cache=True)(function)


# ---------------------------------------------------------------- stale cached kernels
# numba recompiles a cached kernel when its own source file changes, not when a kernel it calls
# (and compiled into itself) changes: after an edit of solvers/lemke.py the Moreau–Jean loop
# would go on running the old Lemke from the cache. A digest of the package's sources, kept
# next to the cache, drops every cached kernel of the package when any source changed.
_purged = False


def _package_sources() -> list[Path]:
    return sorted(Path(__file__).resolve().parent.rglob("*.py"))


def _cache_dir_of(source: Path) -> Path:
    """Where numba caches the kernels of `source` (its in-tree or user-provided locator)."""
    from numba.core import caching, config

    if config.CACHE_DIR:
        return Path(config.CACHE_DIR) / caching._CacheLocator.get_suitable_cache_subpath(str(source))
    return source.parent / "__pycache__"


def sources_digest() -> str:
    import hashlib

    digest = hashlib.blake2b(digest_size=16)
    for source in _package_sources():
        digest.update(source.name.encode())
        digest.update(source.read_bytes())
    return digest.hexdigest()


def purge_stale_kernels() -> bool:
    """Drop the package's cached kernels and compile markers when its sources changed since they
    were cached; True when it purged. Costs ~1 ms (hashing the sources) once per process."""
    global _purged
    _purged = True
    stamp = _marker("sources").with_suffix(".digest")
    current = sources_digest()
    try:
        if stamp.read_text() == current:
            return False
    except OSError:
        pass
    for source in _package_sources():
        folder = _cache_dir_of(source)
        for cached in list(folder.glob(f"{source.stem}.*.nbi")) + list(folder.glob(f"{source.stem}.*.nbc")):
            cached.unlink(missing_ok=True)
    for marker in stamp.parent.glob("nonsmooth-rod-*.compiled"):
        marker.unlink(missing_ok=True)
    try:
        stamp.parent.mkdir(parents=True, exist_ok=True)
        stamp.write_text(current)
    except OSError:
        pass  # a read-only cache: numba cannot write there either
    return True


__all__ = ["jit", "ENABLED", "one_blas_thread"]


# ---------------------------------------------------------------- BLAS threads
# The hold search (solvers/sticking.py) calls LAPACK (an SVD) on matrices of a few rows. With
# OpenBLAS's thread pool each such call wakes its threads, which then spin after it: on the
# 2-core machine that doubled the search's cost and slowed whatever ran next (MuJoCo's N = 16
# row measured twice its cost after one of our runs). A Moreau–Jean run therefore keeps BLAS on
# one thread (threadpoolctl, in the `fast` extra; without it this does nothing).
_blas = None
_blas_depth = 0  # nested uses (a sweep's batch around its runs) limit and restore once


class one_blas_thread:
    """Context manager: BLAS/LAPACK (numpy's and scipy's OpenBLAS, which numba's kernels call) on
    one thread inside, the previous limits restored after. ~15–30 µs to enter once warm; nested
    inside another, nearly free — so a sweep wraps its whole batch once, not each short run."""

    def __enter__(self):
        global _blas, _blas_depth
        self._limit = None
        _blas_depth += 1
        if _blas_depth > 1:
            return self
        if _blas is None:
            try:
                import scipy.linalg.cython_lapack  # noqa: F401  (the LAPACK numba's kernels call)
                from threadpoolctl import ThreadpoolController
            except ImportError:
                _blas = False
                return self
            _blas = ThreadpoolController()
        if _blas:
            self._limit = _blas.limit(limits=1, user_api="blas")
        return self

    def __exit__(self, exc_type, exc, tb):
        global _blas_depth
        _blas_depth -= 1
        if self._limit is not None:
            self._limit.restore_original_limits()
        return False


# ---------------------------------------------------------------- saying when we compile
# The first compiled run on a fresh install compiles the engine (seconds); later processes load
# it from the cache. A marker next to the cache records that compiling has happened for this
# version, so the CLI can say "compiling the engine, once" only when it really will.
COMPILE_ESTIMATE_S = 45  # benchmarks/bench_startup.py: 46.8 s cold (lemke, rod) on the 2 shared cores at load 2.5
_notifier = None


def _marker(part: str = "engine") -> Path:
    from . import __version__

    base = os.environ.get("NUMBA_CACHE_DIR") or str(Path(__file__).resolve().parent / "__pycache__")
    return Path(base) / f"nonsmooth-rod-{__version__}-{part}.compiled"


def engine_is_warm(part: str = "engine") -> bool:
    """True when the engine's compiled kernels are (very likely) in the on-disk cache."""
    return not ENABLED or _marker(part).exists()


def set_compile_notifier(notify) -> None:
    """`notify(message)` is called once, before a compile that will take a while (the CLI prints it)."""
    global _notifier
    _notifier = notify


class compiling_notice:
    """Context manager around a compiled run: says once that compiling happens, marks it done."""

    def __init__(self, active: bool = True, part: str = "engine"):
        self.active = active
        self.part = part  # each solver's loop compiles on its first use: one marker each

    def __enter__(self):
        if self.active:
            _warn_once()
        self.cold = self.active and not engine_is_warm(self.part)
        if self.cold:
            import logging

            message = f"compiling the engine, once: ~{COMPILE_ESTIMATE_S} s"
            logging.getLogger("nonsmooth_rod").info(message)
            if _notifier is not None:
                _notifier(message)
        return self

    def __exit__(self, exc_type, exc, tb):
        if self.cold and exc_type is None:
            try:
                _marker(self.part).parent.mkdir(parents=True, exist_ok=True)
                _marker(self.part).touch()
            except OSError:
                pass
        return False
