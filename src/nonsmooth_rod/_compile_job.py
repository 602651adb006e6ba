"""Compile parts of the Moreau–Jean engine into numba's on-disk cache.

`python -m nonsmooth_rod._compile_job` (the loop, which runs whole runs and, one step a call,
runs with Python force callbacks; every exact solver is compiled into it) and
`python -m nonsmooth_rod._compile_job --python-step SOLVER` (the step kernels around a Python
solver) are what a cold run starts in the background (`_jit.compile_in_background`);
`nonsmooth-rod compile` calls `warm_up`. Each part compiles under its lock and is marked when done;
the loop's callees compile on two cores first where there are two (`_compile_split`).
"""
from __future__ import annotations

import os
import sys
import time

from .solvers.registry import DEFAULT_SOLVER


def _tiny_scene():
    """Two balls on a floor touching each other: every contact kind the loop packs."""
    from .model.body import RigidBody
    from .model.contacts import DiskOnDisk, DiskOnLine, Line
    from .model.laws import ContactLaw
    from .model.scene import Scene

    law = ContactLaw.of(0.3, 0.2)
    balls = [RigidBody(1.0, 1e-3, name=f"ball{i}") for i in range(2)]
    contacts = [DiskOnLine(0, (0.0, 0.0), Line(), 0.05, law, "floor0"),
                DiskOnLine(1, (0.0, 0.0), Line(), 0.05, law, "floor1"),
                DiskOnDisk(0, 1, 0.05, 0.05, law=law, name="pair")]
    return Scene(balls, contacts)


def warm_up(solvers=(DEFAULT_SOLVER,)) -> float:
    """Compile the loop by running a tiny scene with each solver (the first compiles, the others
    load or are already there); returns the seconds it took."""
    previous = os.environ.get("NONSMOOTH_ROD_COMPILE")
    os.environ["NONSMOOTH_ROD_COMPILE"] = "wait"  # compile here and now, not in yet another process
    try:
        from .driver import simulate

        start = time.perf_counter()
        q0, v0 = [0.0, 0.05, 0.0, 0.2, 0.05, 0.0], [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        for solver in solvers:
            simulate(_tiny_scene(), q0, v0, 0.01, method="moreau-jean", h=1e-3, solver=solver)
        return time.perf_counter() - start
    finally:
        if previous is None:
            os.environ.pop("NONSMOOTH_ROD_COMPILE", None)
        else:
            os.environ["NONSMOOTH_ROD_COMPILE"] = previous


def warm_up_python_step(solver: str) -> float:
    """Compile the step kernels the loop runs around a Python (QP) solver."""
    from .driver import simulate

    start = time.perf_counter()
    q0, v0 = [0.0, 0.05, 0.0, 0.2, 0.05, 0.0], [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    simulate(_tiny_scene(), q0, v0, 0.003, method="moreau-jean", h=1e-3, solver=solver)
    return time.perf_counter() - start


def main(argv=None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    solvers = [a for a in args if not a.startswith("--")]
    if "--python-step" in args:
        os.environ["NONSMOOTH_ROD_COMPILE"] = "wait"
        seconds = sum(warm_up_python_step(solver) for solver in solvers)
        print(f"compiled the step kernels around {', '.join(solvers)} in {seconds:.1f} s", flush=True)
        return 0
    from ._compile_split import usable_cores

    if usable_cores() < 2:
        # one core (this process's affinity, as the split counts them): the user's interpreted run goes first. With two or more the run and the compile
        # each have a core, and a niced compile would only finish later — every run after waits for
        # it (on a fresh install the test suite's two workers sat idle behind a niced compile)
        try:
            os.nice(5)
        except (AttributeError, OSError):
            pass
    seconds = warm_up()
    print(f"compiled the Moreau–Jean loop in {seconds:.1f} s", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
