"""Compile the Moreau–Jean loop on two cores.

numba compiles a function's callees that are not inlined (each its own cached dispatcher) while it
types the function, one after the other, in one process: a cold compile of the loop kept one core
busy for ~2 min (`docs/performance.md`). The loop's callees are independent subtrees, so they are
split in two shares (`_compile_shares.py`, generated): a helper process
(`python -m nonsmooth_rod._compile_split 1`) compiles one share into numba's on-disk cache while
this process compiles the other, each with the exact signatures the loop's typing asks for; this
process then waits for the helper and compiles the loop itself (`CHAIN`, the functions that call
the shares), whose typing finds every callee compiled — in memory, or in the cache, which
`Dispatcher.compile` reads before it compiles.

Nothing here is needed for correctness: on one core, where a signature cannot be rebuilt (another
numba), or when the helper fails, the loop's typing compiles whatever is missing itself, as it
did before. `python -m nonsmooth_rod._loop_callees` writes `_compile_shares.py` again
from what the loop's typing asks for (`loop_callees`); tests/engine/test_compile_split.py checks
that it is still that.
"""
from __future__ import annotations

import importlib
import os
import sys
import time
from pathlib import Path

# The functions compiled last, in this process: each calls the shares (directly, or through an
# inlined function) — their own code cannot be compiled before their callees. `_by_group_split`
# calls `two_coefficient_into`, so it is compiled after it, not in a share.
CHAIN = (("nonsmooth_rod.integrators.moreau_jean_loop", "run_steps"),  # with _run inlined
         ("nonsmooth_rod.integrators.moreau_jean_loop", "run_arrays"),
         ("nonsmooth_rod.solvers.two_coefficient", "two_coefficient_into"),
         ("nonsmooth_rod.solvers.two_coefficient", "_by_group_split"))

# The helper's share, by function name (the rest of the loop's callees are this process's): the
# hold search's subtree, the broad phase's and the joints' begin and projection, ~45 s of CPU of a
# cold compile on the 2-core machine, against ~45 s for the other share (pgs_or_lemke_into,
# solve_interval_into and the loop's small callees); the chain after them is ~41 s (numba's compile
# events, docs/performance.md). The helper also pays its start (~2 s), so it takes no more.
HELPER_SHARE = frozenset({"_hold_search", "broad_candidates", "_joints_begin", "_joints_project"})
HELPER_TIMEOUT_S = 900.0  # a helper that hangs is killed: the loop compiles what is missing


def usable_cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def free_cores(window_s: float = 0.3) -> int:
    """Cores this process may use that nothing else keeps busy now: the machine's idle share over
    `window_s` (/proc/stat; else the 1-minute load average). A split pays only with a free core:
    in a fresh test suite both workers run while the loop compiles, and a helper there only
    contended with them (measured: the loop's compile 193 s split against ~110 s alone)."""
    cores = usable_cores()
    try:
        before = _cpu_times()
        time.sleep(window_s)
        after = _cpu_times()
        total, idle = after[0] - before[0], after[1] - before[1]
        busy = (os.cpu_count() or cores) * (1.0 - idle / total) if total > 0 else 0.0
    except (OSError, ValueError, IndexError):
        try:
            busy = os.getloadavg()[0]
        except (AttributeError, OSError):
            return cores
    return max(0, int(cores - busy + 0.25))  # a core three-quarters idle counts as free


def _cpu_times() -> tuple[int, int]:
    """(all, idle + iowait) jiffies of the machine since boot, from /proc/stat's first line."""
    with open("/proc/stat") as stat:
        fields = [int(x) for x in stat.readline().split()[1:]]
    return sum(fields), fields[3] + fields[4]


def _function(module: str, name: str):
    """module.name, numba loaded (a compiled kernel is then its dispatcher); None if there is none."""
    from . import _jit

    _jit.load_numba()
    try:
        return getattr(importlib.import_module(module), name, None)
    except ImportError:
        return None


SHARES_MODULE = "nonsmooth_rod._compile_shares"


def shares(module: str = SHARES_MODULE):
    """[[(dispatcher, argument types)...], ...]: the shipped shares (`module`'s SHARES) rebuilt with
    this numba, or None where they cannot be (a type this numba spells otherwise): the loop then
    compiles its callees itself."""
    try:
        from numba.core import sigutils

        table = importlib.import_module(module).SHARES
        return [[(_function(home, name), sigutils.normalize_signature(text)[0]) for home, name, text in share]
                for share in table]
    except Exception:  # noqa: BLE001 — any failure only means: compile in one process
        return None


def compile_share(share) -> None:
    """Each callee compiled (or loaded from the cache) for its signature; one that fails (an edited
    callee the shares do not know yet) is left to the loop's typing."""
    for dispatcher, args in share:
        try:
            dispatcher.compile(args)
        except Exception:  # noqa: BLE001
            pass


def in_cache(share) -> bool:
    """Every callee of `share` is in numba's cache already (the markers were lost, not the cache):
    no helper is worth starting. False where that cannot be told."""
    try:
        return all(dispatcher._cache.load_overload(args, dispatcher.targetctx) is not None
                   for dispatcher, args in share)
    except Exception:  # noqa: BLE001 — numba's cache reached otherwise: split as if cold
        return False


def _start_helper(index: int, module: str, log: Path | None):
    """The helper process compiling share `index`: same interpreter, same package (its folder
    first on the path), same numba cache (the environment); in this process group, so a job
    killed as a group takes its helper with it. Its output goes to `log` where that can be written."""
    import subprocess

    package_parent = str(Path(__file__).resolve().parent.parent)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in (package_parent, os.environ.get("PYTHONPATH")) if p))
    try:
        out = open(log, "w") if log is not None else subprocess.DEVNULL
    except OSError:
        out = subprocess.DEVNULL
    try:
        return subprocess.Popen([sys.executable, "-m", "nonsmooth_rod._compile_split", str(index), module], env=env,
                                stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT, close_fds=True)
    finally:
        if out is not subprocess.DEVNULL:
            out.close()


def start_share(index: int, module: str = SHARES_MODULE) -> bool:
    """Start the helper process compiling share `index` into the cache and return at once (a
    test suite starting the loop's compile job: see tests/conftest.py); False if it cannot be
    started or there is no such share here."""
    split = shares(module)
    if usable_cores() < 2 or split is None or len(split) <= index or in_cache(split[index]):
        return False
    try:
        _start_helper(index, module, None)
    except OSError:
        return False
    return True


def compile_callees(log: Path | None = None, module: str = SHARES_MODULE) -> bool:
    """Before the loop compiles cold: its callees compiled on two cores (the helper's share in a
    second process, the other here), returning once both are done. False when nothing was split
    (one core, or shares that cannot be rebuilt here): the loop's typing compiles them, as always."""
    import subprocess

    if usable_cores() < 2:
        return False
    split = shares(module)
    if split is not None and len(split) >= 2 and not in_cache(split[1]) and free_cores() < 2:
        return False  # the other core is busy (a test suite's workers): a helper would only contend
    if split is None or len(split) < 2 or in_cache(split[1]):
        return False
    try:
        helper = _start_helper(1, module, log)
    except OSError:
        return False
    try:
        compile_share(split[0])
    except BaseException:  # interrupted: the helper's work is not waited for
        helper.kill()
        raise
    try:
        helper.wait(timeout=HELPER_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        helper.kill()
    return True


def main(argv=None) -> int:
    """The helper: `python -m nonsmooth_rod._compile_split INDEX [MODULE]` compiles share INDEX
    (of MODULE's SHARES, the shipped ones by default)."""
    import time

    args = list(sys.argv[1:] if argv is None else argv)
    split = shares(*args[1:2])
    if split is None:
        print("the shares cannot be rebuilt with this numba: nothing compiled", flush=True)
        return 1
    start = time.perf_counter()
    compile_share(split[int(args[0])])
    print(f"compiled share {args[0]} in {time.perf_counter() - start:.1f} s", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
