"""`nonsmooth-rod compile`: compile the engine ahead of time (for images and cluster workers)."""
from __future__ import annotations



def register(subparsers) -> None:
    p = subparsers.add_parser(
        "compile", help="compile the Moreau–Jean engine now, into numba's on-disk cache",
        description="Compile every compiled kernel of the engine once, so that later runs (and every "
                    "worker of a sweep) load it from the cache instead of compiling. The cache is next to "
                    "the package, or in NUMBA_CACHE_DIR, or in ~/.cache/nonsmooth-rod/numba where the "
                    "package folder is read-only.")
    p.add_argument("--solver", action="append", metavar="NAME",
                   help="compile this solver's loop and step-wise entry only (repeatable; default: every "
                        "exact solver)")
    p.add_argument("--quiet", action="store_true", help="print nothing")
    p.set_defaults(handler=cmd_compile)


def warm_up(solvers=None) -> float:
    """Compile the solvers' loops and step-wise entries (default: every exact solver); returns the
    seconds it took."""
    from .._compile_job import warm_up as compile_parts
    from ..solvers import EXACT_SOLVERS

    return compile_parts(solvers or EXACT_SOLVERS, loop=True, step=True)


def cmd_compile(args) -> int:
    from .. import _jit

    if not _jit.ENABLED:
        if not args.quiet:
            print("numba is not installed (or NONSMOOTH_ROD_NO_JIT is set): nothing to compile")
        return 0
    if not args.quiet:
        _jit.set_compile_notifier(lambda message: print(f"nonsmooth-rod: {message}", flush=True))
        print("compiling every solver's loop and step-wise entry into the cache", flush=True)
    from ..solvers import EXACT_SOLVERS
    from ..validation import InputError

    for solver in args.solver or ():
        if solver not in EXACT_SOLVERS:
            raise InputError(f"--solver: {solver!r} is not compiled; compiled solvers: {', '.join(EXACT_SOLVERS)}")
    seconds = warm_up(args.solver)
    if not args.quiet:
        print(f"compiled in {seconds:.1f} s; cache markers in {_jit._marker().parent}")
    return 0
