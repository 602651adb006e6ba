"""`nonsmooth-rod compile`: compile the engine ahead of time (for images and cluster workers)."""
from __future__ import annotations


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "compile", help="compile the Moreau–Jean engine now, into numba's on-disk cache",
        description="Compile every compiled kernel of the engine once, so that later runs (and every "
                    "worker of a sweep) load it from the cache instead of compiling. The cache is next to "
                    "the package, or in NUMBA_CACHE_DIR, or in ~/.cache/nonsmooth-rod/numba where the "
                    "package folder is read-only.")
    p.add_argument("--quiet", action="store_true", help="print nothing")
    p.set_defaults(handler=cmd_compile)


def warm_up() -> float:
    """Compile the loop (whole runs, and runs with Python force callbacks one step a call), every
    exact solver in it; returns the seconds it took."""
    from .._compile_job import warm_up as compile_parts
    from ..solvers import EXACT_SOLVERS

    return compile_parts(EXACT_SOLVERS)


def cmd_compile(args) -> int:
    from .. import _jit

    if not _jit.ENABLED:
        if not args.quiet:
            print("numba is not installed (or NONSMOOTH_ROD_NO_JIT is set): nothing to compile")
        return 0
    if not args.quiet:
        _jit.set_compile_notifier(lambda message: print(f"nonsmooth-rod: {message}", flush=True))
        print("compiling the Moreau–Jean loop (every exact solver) into the cache", flush=True)
    seconds = warm_up()
    if not args.quiet:
        print(f"compiled in {seconds:.1f} s; cache markers in {_jit._marker().parent}")
    return 0
