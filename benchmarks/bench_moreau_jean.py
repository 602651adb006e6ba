"""Microseconds per Moreau–Jean step on the paper's rod, per one-step solver.

    python benchmarks/bench_moreau_jean.py [--repeats 7] [--quick]

Every exact solver compiled (the default) and interpreted (`fast=False`: the same source without
numba), and the QP backends (Python). Whole runs (release → ball B's impact, case 2, h = 1e-4,
~3750 steps) are timed, the CPU time
divided by the steps; the median of the repeats is reported. In the same run, the yardstick:
one 3×3 numpy.linalg.solve in a plain Python loop. This machine is noisy: read the ratios.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.solvers import available_solvers

sys.path.insert(0, str(Path(__file__).resolve().parent))  # benchmarks/ for the yardstick
from yardstick import yardstick_us  # noqa: E402  (benchmarks/yardstick.py)


def step_us(solver: str, h: float = 1e-4, repeats: int = 7, fast: bool = True) -> tuple[float, int, str]:
    problem = RodProblem.paper(2)
    scene = problem.scene()
    q0, v0 = problem.initial_state()
    options = MoreauJeanOptions(h=h, solver=solver, stop_at_impact="B", fast=fast)
    warm = MoreauJean(options).run(scene, q0, v0, 10.0)  # warm-up (and JIT compilation)
    if warm.status != "ok":
        return float("nan"), warm.steps, warm.message
    times, steps = [], 0
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = MoreauJean(options).run(scene, q0, v0, 10.0)
        elapsed = time.perf_counter() - t0
        steps = res.steps
        times.append(elapsed / steps * 1e6)
    return statistics.median(times), steps, "ok"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--quick", action="store_true", help="3 repeats, h = 1e-3, exact solvers only")
    parser.add_argument("--solvers", default=None, help="comma-separated subset of the solvers (default: all)")
    args = parser.parse_args(argv)
    repeats = 3 if args.quick else args.repeats
    h = 1e-3 if args.quick else 1e-4
    ys = yardstick_us(repeats=repeats)
    print(f"yardstick: 3x3 numpy.linalg.solve in a Python loop: {ys:.2f} us")
    print(f"Moreau-Jean on the rod (case 2, h = {h:g}, whole run to ball B's impact), median of {repeats}:")
    print(f"{'solver':<26}{'us/step':>10}{'x yardstick':>13}{'steps':>8}")
    exact = ("lemke", "pgs", "enum")  # compiled (the whole run one call), and the same source interpreted
    rows = [(f"{name} (compiled)", name, True) for name in exact]
    rows += [(f"{name} (interpreted)" if name in exact else f"{name} (Python QP)", name, False)
             for name in available_solvers()
             if not (args.quick and (name.endswith("-relaxed") or name not in exact))]
    if args.solvers:
        wanted = set(args.solvers.split(","))
        rows = [row for row in rows if row[1] in wanted]
    for label, solver, fast in rows:
        us, steps, status = step_us(solver, h=h, repeats=repeats, fast=fast)
        note = "" if status == "ok" else f"  FAILED: {status}"
        print(f"{label:<26}{us:>10.2f}{us / ys:>13.2f}{steps:>8d}{note}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
