"""The rod's cost per step in two builds of the package, side by side in one session.

    python benchmarks/bench_ab.py SRC_A SRC_B [--runs 20]

SRC_A, SRC_B: the `src` folders of two checkouts (say one at the previous commit, extracted with
`git archive`). One persistent process per build, each warm (compiled), runs the paper's rod
(case 2, h = 1e-4, release → ball B's impact) in turn with lemke and pgs, alternating which build
goes first; the driver measures the yardstick between rounds. On a loaded machine this is
what tells a few per cent apart: both builds see the same load. Prints medians (CPU time per
step) and their ratios to the yardstick.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from yardstick import yardstick_us  # noqa: E402

WORKER = """
import sys, time
from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.rod.problem import RodProblem
problem = RodProblem.paper(2); scene = problem.scene(); q0, v0 = problem.initial_state()
opts = {s: MoreauJeanOptions(h=1e-4, solver=s, stop_at_impact="B") for s in ("lemke", "pgs")}
for s in opts: MoreauJean(opts[s]).run(scene, q0, v0, 10.0)
print("ready", flush=True)
for line in sys.stdin:
    t0 = time.process_time(); res = MoreauJean(opts[line.strip()]).run(scene, q0, v0, 10.0)
    print((time.process_time() - t0) / res.steps * 1e6, flush=True)
"""
SOLVERS = ("lemke", "pgs")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("src_a")
    parser.add_argument("src_b")
    parser.add_argument("--runs", type=int, default=20)
    args = parser.parse_args(argv)
    env = dict(os.environ, MPLBACKEND="Agg", NONSMOOTH_ROD_COMPILE="wait")
    builds = {}
    for src in (args.src_a, args.src_b):
        p = subprocess.Popen([sys.executable, "-c", WORKER], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                             text=True, env=dict(env, PYTHONPATH=src))
        if p.stdout.readline().strip() != "ready":
            print(f"{src}: the worker did not start")
            return 1
        builds[src] = p
    times = {(src, s): [] for src in builds for s in SOLVERS}
    yardsticks = []
    for run in range(args.runs):
        yardsticks.append(yardstick_us(repeats=1))
        order = list(builds.items()) if run % 2 == 0 else list(reversed(builds.items()))
        for s in SOLVERS:
            for src, p in order:
                p.stdin.write(s + "\n")
                p.stdin.flush()
                times[(src, s)].append(float(p.stdout.readline()))
    y = statistics.median(yardsticks)
    print(f"yardstick: 3x3 numpy.linalg.solve in a Python loop: {y:.2f} us (median of {args.runs})")
    for (src, s), values in times.items():
        m = statistics.median(values)
        print(f"{src}  {s:<6} {m:6.2f} us/step  {m / y:5.2f}x yardstick  (min {min(values):.2f})")
    for p in builds.values():
        p.stdin.close()
        p.wait()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
