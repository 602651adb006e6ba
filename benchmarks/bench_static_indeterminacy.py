"""Drift of bodies the static coefficients hold, over 1e5 Moreau–Jean steps, every exact solver.

    python benchmarks/bench_static_indeterminacy.py [--steps 100000] [--quick]

Issue 14's bar: |Δq| < 1e-10 after 1e5 steps for each toy that statics can hold (ladder just
above its critical angle, block on two corners just below tan α = μs, rod wedged between two
walls, pyramid of three disks). Prints max |q − q0| over the run, whether every contact stuck in
every step, and the CPU time; exits 1 if any toy moved. --quick: 50 steps (a test runs it).
"""
from __future__ import annotations

import argparse
import math
import time

import numpy as np

from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.toys import BlockOnIncline, DiskPyramid, Ladder, WedgedRod

HOLD_TOL = 1e-10


def held_toys():
    ladder = Ladder()
    return {
        "ladder, beta* + 0.2 deg": Ladder(angle=ladder.critical_angle() + math.radians(0.2)),
        "block, tan a = 0.999 mu_s": BlockOnIncline(angle=math.atan(0.5 * 0.999), mu_s=0.5, mu_d=0.4),
        "wedged rod, tan phi < mu_s": WedgedRod(angle=math.atan(0.5) - 0.01, mu_s=0.5, mu_d=0.4),
        "disk pyramid": DiskPyramid(mu_disks=0.34, mu_disks_d=0.27, mu_floor=0.12, mu_floor_d=0.1),
    }


def drift(toy, solver: str, h: float, steps: int, fast: bool):
    scene = toy.scene()
    q0, v0 = toy.initial_state()
    t0 = time.process_time()
    res = MoreauJean(MoreauJeanOptions(h=h, solver=solver, fast=fast)).run(scene, q0, v0, steps * h)
    cpu = time.process_time() - t0
    moved = float(np.max(np.abs(res.trajectory.q - q0)))
    stuck = set(res.trajectory.modes[1:].ravel()) == {"stick"}
    return moved, stuck and res.steps == steps, cpu, res.stats["compiled"]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=100_000)
    parser.add_argument("--h", type=float, default=1e-3)
    parser.add_argument("--quick", action="store_true", help="50 steps")
    args = parser.parse_args(argv)
    steps = 50 if args.quick else args.steps
    print(f"max |q - q0| over {steps} steps of h = {args.h:g} (bar: {HOLD_TOL:g})")
    print(f"{'toy':<28}{'solver':<18}{'max|dq|':>10}{'all stick':>11}{'cpu s':>8}")
    failed = 0
    for name, toy in held_toys().items():
        for solver, fast in (("lemke", True), ("lemke", False), ("pgs", False), ("enum", False)):
            moved, stuck, cpu, compiled = drift(toy, solver, args.h, steps, fast)
            label = solver + (" (compiled)" if compiled else "")
            failed += not (moved < HOLD_TOL and stuck)
            print(f"{name:<28}{label:<18}{moved:>10.2e}{str(stuck):>11}{cpu:>8.1f}")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
