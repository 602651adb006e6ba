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
import re
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
import sys
import threading

# numba is the optional `fast` extra. It is imported on the first compiled call, not by the
# decorators: `import nonsmooth_rod` stays light (numba, llvmlite, yaml and scipy cost ~0.2 s of
# an idle start), and runs that never compile (interpreted, event-driven, the CLI's help) never
# load it.
HAVE_NUMBA = importlib.util.find_spec("numba") is not None
ENABLED = HAVE_NUMBA and os.environ.get("NONSMOOTH_ROD_NO_JIT", "") in ("", "0")
_warned = False


NO_NUMBA_MESSAGE = ("numba is not installed: Moreau–Jean runs interpreted, about 30x slower "
                    "(pip install 'nonsmooth-rod[fast]')")


def warn_once_without_numba() -> None:
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
        warnings.warn(NO_NUMBA_MESSAGE, RuntimeWarning, stacklevel=3)  # the driver's caller


def jit(function):
    """numba.njit(cache=True) of `function` when compiling is enabled; `function` itself otherwise.

    Kernels take float64 arrays and int64 indices only, so each compiles to one signature.
    """
    # NRT set here, not inherited: a function the step's borrowing ones call keeps its reference
    # counting (numba's callees inherit an unset NRT flag from their caller)
    return _kernel(function, {"cache": True, "_nrt": True}) if ENABLED else function


def jit_borrowing(function):
    """jit without reference counting (numba's NRT off): for the step's hot functions, which only
    borrow arrays their caller keeps alive. numba counts a reference (an atomic increment and
    decrement) for every array argument, view and tuple member bound in a function, and in the
    step's long functions its pruning pass leaves most of them: ~300 a step for one contact, most of
    the step's time (measured with gdb on NRT_incref). Such a function must not allocate, and
    must not return an array or take one from a function that allocates it."""
    return _kernel(function, {"cache": True, "_nrt": False}) if ENABLED else function


def jit_inline(function):
    """jit, inlined into its callers at numba's IR level: small helpers (a scratch view, a
    relative velocity, a Delassus block) compiled as part of the function that calls them, with
    its reference counting or without it (in a borrowing caller they count nothing either)."""
    return _kernel(function, {"cache": True, "inline": "always"}) if ENABLED else function


def jitable(function):
    """A kernel both ways: plain Python when Python calls it (it never waits for a compile), and
    compiled into the jitted kernels that call it (numba's register_jitable, once numba is loaded).
    For code that the compiled loop and the object model share (model/contact_kernels.py)."""
    if ENABLED:
        if _numba is None:
            _pending_jitable.append(function)
        else:
            _numba.extending.register_jitable(function)
    return function


# ---------------------------------------------------------------- numba on first use
_numba = None  # the numba module once loaded
_pending_jitable: list = []  # jitable functions to register with numba when it loads
_lazy_kernels: list = []  # LazyKernels made before numba loaded
_load_lock = threading.Lock()


class LazyKernel:
    """A compiled kernel before numba is loaded: `py_func` (what solvers._common.interpreted
    runs) without numba; called, or typed by numba inside a caller being compiled (its
    `_numba_type_`), it loads numba, which makes every kernel's dispatcher and rebinds the
    package's module globals to them (`load_numba`) — from then on the kernels are numba's own."""

    __slots__ = ("py_func", "options", "dispatcher", "__weakref__")

    def __init__(self, function, options: dict):
        self.py_func, self.options, self.dispatcher = function, options, None

    def materialized(self):
        if self.dispatcher is None:
            load_numba()
        return self.dispatcher

    def __call__(self, *args):
        return self.materialized()(*args)

    @property
    def _numba_type_(self):
        return self.materialized()._numba_type_

    def __getattr__(self, name):  # the dispatcher's attributes (compile, signatures, _cache...)
        if name.startswith("__"):
            raise AttributeError(name)
        return getattr(self.materialized(), name)

    def __reduce__(self):  # pickled as what it stands for: its module's attribute
        return _module_attribute, (self.py_func.__module__, self.py_func.__name__)

    def __repr__(self):
        return f"<kernel {self.py_func.__module__}.{self.py_func.__qualname__} (numba not loaded yet)>"


def _module_attribute(module: str, name: str):
    import importlib

    return getattr(importlib.import_module(module), name)


def _kernel(function, options: dict):
    """numba's dispatcher of `function` when numba is loaded, else a LazyKernel standing for it."""
    if _numba is not None:
        dispatcher = _numba.njit(**options)(function)
        _compile_once_across_processes(dispatcher)
        return dispatcher
    kernel = LazyKernel(function, options)
    _lazy_kernels.append(kernel)
    return kernel


def load_numba():
    """Load numba (once): the stale cached kernels purged first, the jitable functions
    registered, every LazyKernel's dispatcher made, and the package modules' globals that name
    a LazyKernel rebound to its dispatcher (Python calls then go straight to numba)."""
    global _numba
    if _numba is not None:
        return _numba
    with _load_lock:  # two threads' first compiled calls at once: one loads, the other finds it loaded
        return _numba if _numba is not None else _load_numba()


def _load_numba():
    global _numba
    import numba
    import numba.extending

    if not _purged:
        purge_stale_kernels()
    for function in _pending_jitable:
        numba.extending.register_jitable(function)
    _pending_jitable.clear()
    for kernel in _lazy_kernels:
        kernel.dispatcher = numba.njit(**kernel.options)(kernel.py_func)
        _compile_once_across_processes(kernel.dispatcher)
    _numba = numba
    package = __name__.rpartition(".")[0]
    for name, module in list(sys.modules.items()):
        if module is not None and (name == package or name.startswith(package + ".")):
            space = vars(module)
            for key, value in list(space.items()):
                if type(value) is LazyKernel:
                    space[key] = value.dispatcher
    _lazy_kernels.clear()
    return numba


def _compile_once_across_processes(dispatcher) -> None:
    """Make `dispatcher`'s compiles take a lock per kernel shared by the processes of this cache:
    a second process (a test worker, a Dask worker on a fresh install) waits for the first and
    then loads its kernel from the cache instead of compiling it again (measured: both workers of
    a fresh test suite compiled the hold search's kernels at once, ~40 s of CPU each).

    The file lock is taken inside numba's own compiler lock (re-entrant), so one thread of a
    process holds kernel locks at a time, and a compile takes its callees' locks while holding its
    own: the order follows the call graph, which has no cycles, so no two processes wait for each
    other. A kernel already compiled here takes no lock."""
    from numba.core import sigutils
    from numba.core.compiler_lock import global_compiler_lock

    compile_here = dispatcher.compile
    name = f"kernel-{dispatcher.py_func.__module__}.{dispatcher.py_func.__qualname__}"

    def compile(sig):
        args, _ = sigutils.normalize_signature(sig)
        if tuple(args) in dispatcher.overloads or name in _kernel_locks_held:
            return compile_here(sig)
        with global_compiler_lock, _part_lock(name):
            _kernel_locks_held.add(name)
            try:
                return compile_here(sig)  # numba loads it from the cache if another process wrote it
            finally:
                _kernel_locks_held.discard(name)

    dispatcher.compile = compile


_kernel_locks_held: set = set()  # kernel locks this process holds (a recursive compile takes none)


# ---------------------------------------------------------------- stale cached kernels
# numba recompiles a cached kernel when its own source file changes, not when a kernel it calls
# (and compiled into itself) changes: after an edit of solvers/lemke.py the Moreau–Jean loop
# would go on running the old Lemke from the cache. A digest of the package's sources, kept
# next to the cache, drops every cached kernel of the package when any of them changed. It covers
# the modules that hold compiled code and every package module they import at module level (where
# a kernel's globals come from: constants, other kernels); an edit elsewhere (the driver, results,
# studies, the CLI…) cannot change a compiled kernel and keeps the cache.
_purged = False
_COMPILED = re.compile(r"^@(jit|jit_borrowing|jit_inline|jitable|_inlined)\b", re.MULTILINE)


def _module_imports(path: Path, package_root: Path) -> set[Path]:
    """The package's source files `path` imports at module level (function-level imports cannot
    reach a compiled kernel's globals)."""
    import ast

    here = path.parent
    found = set()
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.ImportFrom) and node.level:
            base = here
            for _ in range(node.level - 1):
                base = base.parent
            module = base.joinpath(*node.module.split(".")) if node.module else base
            for alias in node.names:
                candidates = ((module / alias.name).with_suffix(".py"), module / alias.name / "__init__.py",
                              module.with_suffix(".py"), module / "__init__.py")
                found.update(next(([c] for c in candidates if c.is_file()), []))
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names = [node.module or ""] if isinstance(node, ast.ImportFrom) else [a.name for a in node.names]
            for name in names:
                parts = name.split(".")
                if parts[0] == package_root.name:
                    stem = package_root.parent.joinpath(*parts)
                    found.update(c for c in (stem.with_suffix(".py"), stem / "__init__.py") if c.is_file())
    return found


def _package_root() -> Path:
    return Path(__file__).resolve().parent


def _package_sources(root: Path | None = None) -> list[Path]:
    """The sources a cached kernel can depend on: the modules with compiled functions and,
    transitively, the package modules they import at module level."""
    root = _package_root() if root is None else root
    todo = [path for path in root.rglob("*.py") if _COMPILED.search(path.read_text(encoding="utf-8"))]
    seen: set[Path] = set()
    while todo:
        path = todo.pop()
        if path not in seen:
            seen.add(path)
            todo.extend(_module_imports(path, root) - seen)
    return sorted(seen)


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


def _sources_stat() -> str:
    """Every package source's size and modification time: while it is unchanged so is the
    digest, and checking it costs a directory walk (~1 ms) instead of parsing the sources."""
    root = _package_root()
    return "\n".join(f"{path.relative_to(root)} {stat.st_size} {stat.st_mtime_ns}"
                     for path in sorted(root.rglob("*.py")) for stat in [path.stat()])


def purge_stale_kernels() -> bool:
    """Drop the package's cached kernels and compile markers when the sources they depend on
    changed since they were cached; True when it purged. Costs ~1 ms once per process while no
    source changed (their sizes and times), ~0.3 s after an edit (the digest)."""
    global _purged
    _purged = True
    stamp = _marker("sources").with_suffix(".digest")
    try:
        recorded_digest, _, recorded_stat = stamp.read_text().partition("\n")
    except OSError:
        recorded_digest = recorded_stat = None
    stat = _sources_stat()
    if stat == recorded_stat:
        return False
    current = sources_digest()
    purged = current != recorded_digest
    if purged:
        for source in _package_sources():
            folder = _cache_dir_of(source)
            for cached in list(folder.glob(f"{source.stem}.*.nbi")) + list(folder.glob(f"{source.stem}.*.nbc")):
                cached.unlink(missing_ok=True)
        for marker in stamp.parent.glob("nonsmooth-rod-*.compiled"):
            marker.unlink(missing_ok=True)
    try:
        stamp.parent.mkdir(parents=True, exist_ok=True)
        stamp.write_text(f"{current}\n{stat}")
    except OSError:
        pass  # a read-only cache: numba cannot write there either
    return purged


__all__ = ["jit", "ENABLED", "one_blas_thread", "compiling", "compile_in_background", "start_compile_job", "compile_policy"]


# ---------------------------------------------------------------- BLAS threads
# The hold search (solvers/sticking.py) calls LAPACK (an SVD) on matrices of a few rows. With
# OpenBLAS's thread pool each such call wakes its threads, which then spin after it: on the
# 2-core machine that doubled the search's cost and slowed whatever ran next (MuJoCo's N = 16
# row measured twice its cost after one of our runs). A Moreau–Jean run therefore keeps BLAS on
# one thread (threadpoolctl, in the `fast` extra; without it this does nothing).
_blas = None
_blas_depth = 0  # nested uses (a sweep's batch around its runs) limit and restore once
_blas_restore: list = []  # (set_threads, threads) the outermost use restores on leaving


class _OneBlasThread:
    """one_blas_thread's context (one, shared: it holds no state of its own)."""

    __slots__ = ()

    def __enter__(self):
        global _blas, _blas_depth, _blas_restore
        _blas_depth += 1
        if _blas_depth == 1:
            if _blas is None:
                _blas = _blas_libraries()
            restore = []
            for get_threads, set_threads in _blas:
                threads = get_threads()
                if threads != 1:
                    set_threads(1)
                    restore.append((set_threads, threads))
            _blas_restore = restore
        return self

    def __exit__(self, exc_type, exc, tb):
        global _blas_depth
        _blas_depth -= 1
        if _blas_depth == 0:
            for set_threads, threads in _blas_restore:
                set_threads(threads)
        return False


_ONE_BLAS_THREAD = _OneBlasThread()


def one_blas_thread() -> _OneBlasThread:
    """Context manager: BLAS/LAPACK (numpy's and scipy's OpenBLAS, which numba's kernels call) on
    one thread inside, the previous limits restored after. The libraries and their thread-count
    functions are looked up once per process (threadpoolctl); entering then costs two ctypes calls
    per library and leaving one (~1 µs in all: threadpoolctl's own methods cost ~13 µs, 4
    yardsticks of a short run's fixed cost), and nested inside another use it is free — so a
    sweep wraps its whole batch once, not each short run. (One shared context, no object a use:
    a run's fixed cost counts every attribute.)"""
    return _ONE_BLAS_THREAD


def _blas_libraries() -> list:
    """(get, set) thread-count functions of each loaded BLAS library ([] without threadpoolctl):
    OpenBLAS's own C functions where threadpoolctl finds them (a run holds the limit on the one
    thread it runs on: threadpoolctl's bookkeeping of which Python thread controls the pool is
    for its own context managers), threadpoolctl's methods otherwise."""
    try:
        import scipy.linalg.cython_lapack  # noqa: F401  (the LAPACK numba's kernels call)
        from threadpoolctl import ThreadpoolController
    except ImportError:
        return []
    found = []
    for library in ThreadpoolController().select(user_api="blas").lib_controllers:
        symbol = getattr(library, "_get_symbol", None)
        direct = None
        if symbol is not None and library.internal_api == "openblas" and library.threading_layer != "openmp":
            direct = symbol("openblas_get_num_threads"), symbol("openblas_set_num_threads")
        found.append(direct if direct and None not in direct else (library.get_num_threads, library.set_num_threads))
    return found


# ---------------------------------------------------------------- when to compile
# Compiling a solver's loop costs ~1 min of CPU on a fresh install (benchmarks/bench_startup.py),
# far more than most first runs take interpreted (the same source, ~30x slower per step). So no
# run waits for the compiler longer than it would take to run without it: a run whose cache is
# cold starts interpreted, measures its own per-step cost on a few steps, and
#   * when the rest of it takes less than compiling would, goes on interpreted while a detached
#     process compiles that solver's loop into the on-disk cache for later runs ("background");
#   * otherwise compiles now (saying so once, with the time measured on this machine) and goes on
#     compiled from the step it reached.
# NONSMOOTH_ROD_COMPILE=wait makes every cold compiled run compile in-process first (the test
# suite and `nonsmooth-rod compile` use it, so what they measure is the compiled engine).
# A marker next to the cache records that a part (one solver's loop, or its step-wise entry) is
# compiled for this version of the sources; a file lock makes sure that only one process at a
# time compiles a part, so two workers starting together never compile the same kernels twice.
COMPILE_ESTIMATE_S = 60.0  # before any measurement here: 55 s CPU cold (lemke loop) on the 2-core machine
POLICIES = ("auto", "wait")
_notifier = None
_noticed: set = set()
_warm: set = set()  # parts known warm in this process: no filesystem check per call


def compile_policy() -> str:
    policy = os.environ.get("NONSMOOTH_ROD_COMPILE", "auto").strip().lower() or "auto"
    return policy if policy in POLICIES else "auto"


def _marker(part: str = "engine") -> Path:
    from . import __version__

    base = os.environ.get("NUMBA_CACHE_DIR") or str(Path(__file__).resolve().parent / "__pycache__")
    return Path(base) / f"nonsmooth-rod-{__version__}-{part}.compiled"


def engine_is_warm(part: str = "engine") -> bool:
    """True when the part's compiled kernels are (very likely) in the on-disk cache."""
    if not ENABLED or part in _warm:
        return True
    if not _purged:  # a marker of kernels compiled from older sources is dropped first
        purge_stale_kernels()
    if _marker(part).exists():
        _warm.add(part)
        return True
    return False


def compile_estimate_s(part: str) -> tuple[float, bool]:
    """(seconds, measured): the last compile time of `part` measured on this machine, or the
    default estimate when it was never compiled here."""
    try:
        return float(_marker(part).with_suffix(".seconds").read_text()), True
    except (OSError, ValueError):
        return COMPILE_ESTIMATE_S, False


def _record_compiled(part: str, seconds: float | None) -> None:
    try:
        marker = _marker(part)
        marker.parent.mkdir(parents=True, exist_ok=True)
        if seconds is not None:
            marker.with_suffix(".seconds").write_text(f"{seconds:.3f}\n")
        marker.touch()
        _warm.add(part)
    except OSError:
        pass  # a read-only cache: numba could not write there either


def set_compile_notifier(notify) -> None:
    """`notify(message)` is called once per part and process, before a compile that takes a while,
    and when a run goes on interpreted while the compile happens in the background (the CLI prints it)."""
    global _notifier
    _notifier = notify


def _say(key: str, message: str) -> None:
    if key in _noticed:
        return
    _noticed.add(key)
    import logging

    logging.getLogger("nonsmooth_rod").info(message)
    if _notifier is not None:
        _notifier(message)


class _part_lock:
    """An exclusive lock on compiling `part` (fcntl.flock on a file next to the marker; released
    with the process if it dies). blocking=False: `acquired` says whether it was taken."""

    def __init__(self, part: str, blocking: bool = True):
        self.path, self.blocking, self.acquired, self._file = _marker(part).with_suffix(".lock"), blocking, False, None

    def __enter__(self):
        try:
            import fcntl

            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._file = open(self.path, "a")
            fcntl.flock(self._file, fcntl.LOCK_EX | (0 if self.blocking else fcntl.LOCK_NB))
            self.acquired = True
        except (ImportError, OSError):
            self.acquired = self.blocking  # no locking here (read-only cache, no fcntl): go on alone
        return self

    def __exit__(self, exc_type, exc, tb):
        if self._file is not None:
            self._file.close()  # releases the lock; the file stays, so the lock is never held twice
        return False


class compiling:
    """Context manager around the first compiled call of `part` in a process: when the part is cold,
    says once what is compiled and how long it takes here, waits for any other process compiling it,
    runs `prepare(log)` (the loop's callees compiled on two cores first: _compile_split; `log`, a
    file beside the marker for a helper's output), and afterwards marks the part compiled with the
    time it took."""

    def __init__(self, part: str, what: str, prepare=None):
        self.part, self.what, self.prepare = part, what, prepare

    def __enter__(self):
        self.cold = ENABLED and not engine_is_warm(self.part)
        if not self.cold:
            return self
        import time

        self._lock = _part_lock(self.part).__enter__()
        if engine_is_warm(self.part):  # another process compiled it while we waited
            self.cold = False
            return self
        seconds, measured = compile_estimate_s(self.part)
        _say(self.part, f"compiling {self.what} (once per install): ~{seconds:.0f} s "
                        f"{'as measured on this machine' if measured else 'estimated'}")
        self._start = time.perf_counter()
        if self.prepare is not None:
            self.prepare(_marker(self.part).with_suffix(".helper.log"))
        return self

    def __exit__(self, exc_type, exc, tb):
        if self.cold:
            import time

            if exc_type is None:
                _record_compiled(self.part, time.perf_counter() - self._start)
            self._lock.__exit__(exc_type, exc, tb)
        elif hasattr(self, "_lock"):
            self._lock.__exit__(exc_type, exc, tb)
        return False


def start_compile_job(part: str, args: list[str]) -> bool:
    """Start a detached process that compiles `part` (python -m nonsmooth_rod._compile_job ARGS)
    unless some process is compiling it now; its pid is written beside the marker. True if started."""
    import subprocess
    import sys

    started = _jobs.get(part)
    if started is not None and started.poll() is None:
        return False  # this process's job is still starting or compiling (before it takes the lock)
    with _part_lock(part, blocking=False) as lock:
        if not lock.acquired:
            return False  # some process is compiling it now
    log = _marker(part).with_suffix(".log")
    try:
        log.parent.mkdir(parents=True, exist_ok=True)
        with open(log, "w") as out:
            job = subprocess.Popen([sys.executable, "-m", "nonsmooth_rod._compile_job", *args],
                                   stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT,
                                   start_new_session=True, close_fds=True)
        _marker(part).with_suffix(".pid").write_text(f"{job.pid}\n")
    except OSError:
        return False
    _jobs[part] = job
    return True


# The compile job this process started, by part: a run's next calls do not start another while it
# runs (it takes the part's lock only once it has imported: ~1 s in which the lock is free).
_jobs: dict = {}


def compile_in_background(part: str, args: list[str], what: str, seconds: float) -> bool:
    """start_compile_job, and say once that the run goes on interpreted meanwhile."""
    if not start_compile_job(part, args):
        return False
    _say(part + ":background", f"running interpreted: this run is shorter than compiling {what} "
                               f"(~{seconds:.0f} s), which goes on in the background for later runs")
    return True
