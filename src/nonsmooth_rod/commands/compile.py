"""`nonsmooth-rod compile`: compile the engine ahead of time (for images and cluster workers)."""
from __future__ import annotations

import time


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
    """Run one tiny scene per compiled solver and contact kind; returns the seconds it took."""
    from ..driver import simulate
    from ..model.body import RigidBody
    from ..model.contacts import DiskOnDisk, DiskOnLine, Line
    from ..model.laws import ContactLaw
    from ..model.scene import Scene

    start = time.perf_counter()
    law = ContactLaw.of(0.3, 0.2)
    balls = [RigidBody(1.0, 1e-3, name=f"ball{i}") for i in range(2)]
    contacts = [DiskOnLine(0, (0.0, 0.0), Line(), 0.05, law, "floor0"),
                DiskOnLine(1, (0.0, 0.0), Line(), 0.05, law, "floor1"),
                DiskOnDisk(0, 1, 0.05, 0.05, law=law, name="pair")]
    scene = Scene(balls, contacts)
    q0, v0 = [0.0, 0.05, 0.0, 0.2, 0.05, 0.0], [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    from ..solvers import EXACT_SOLVERS

    for solver in EXACT_SOLVERS:  # the driver marks each solver's loop compiled
        simulate(scene, q0, v0, 0.01, method="moreau-jean", h=1e-3, solver=solver)
    return time.perf_counter() - start


def cmd_compile(args) -> int:
    from .. import _jit

    if not _jit.ENABLED:
        if not args.quiet:
            print("numba is not installed (or NONSMOOTH_ROD_NO_JIT is set): nothing to compile")
        return 0
    if not args.quiet:
        print(f"compiling the engine, once: ~{_jit.COMPILE_ESTIMATE_S} s", flush=True)
    seconds = warm_up()
    if not args.quiet:
        print(f"compiled in {seconds:.1f} s; cache markers in {_jit._marker().parent}")
    return 0
