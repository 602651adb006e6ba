"""The rod's cost per step in two builds of the package, side by side in one session.

    python benchmarks/bench_ab.py SRC_A SRC_B [--runs 20]
    python benchmarks/bench_ab.py SRC_A SRC_B --targets [--runs 7]


SRC_A, SRC_B: the `src` folders of two checkouts (say one at the previous commit, extracted with
`git archive`). One persistent process per build, each warm (compiled), runs the paper's rod
(case 2, h = 1e-4, release → ball B's impact) in turn with lemke and pgs, alternating which build
goes first; the driver measures the yardstick between rounds. On a loaded machine this is
what tells a few per cent apart: both builds see the same load. Prints medians (CPU time per
step) and their ratios to the yardstick.

--targets: issue 25's cases instead (bench_scenes.py's targets: the rod, 500 steps at h = 1e-4,
and the one- and two-contact toys, 200 steps at h = 1e-3), each call through `nr.simulate`, the
median of 3 calls a round; prints the whole call and the loop's share (`result.cpu_time_s`) per
step in yardsticks, medians over the rounds.
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
TARGET_CASES = ("rod", "BouncingBall", "DiskOnIncline", "PainleveRod", "BlockOnIncline", "PushedBlock",
                "BeltOscillator", "RockingBlock")
TARGETS_WORKER = """
import statistics, sys, time
import nonsmooth_rod as nr
from nonsmooth_rod import toys
from nonsmooth_rod.rod.problem import RodProblem
rod = RodProblem.paper(2)
cases = {"rod": (rod.scene(), *rod.initial_state(), 1e-4, 500)}
for name in %r[1:]:
    toy = getattr(toys, name)()
    cases[name] = (toy.scene(), *toy.initial_state(), 1e-3, 200)
def run(name, solver):
    scene, q0, v0, h, steps = cases[name]
    return nr.simulate(scene, q0, v0, h * steps, method="moreau-jean", h=h, solver=solver, repeat_rest=False)
for name in cases:
    for s in %r:
        run(name, s)
print("ready", flush=True)
for line in sys.stdin:
    name, s = line.split()
    times = []
    for _ in range(3):
        t0 = time.process_time(); res = run(name, s); t = time.process_time() - t0
        times.append((t / res.steps * 1e6, res.cpu_time_s / res.steps * 1e6))
    times.sort()
    print(*times[1], flush=True)
""" % (TARGET_CASES, SOLVERS)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("src_a")
    parser.add_argument("src_b")
    parser.add_argument("--runs", type=int, default=20)
    parser.add_argument("--targets", action="store_true", help="issue 25's cases through nr.simulate")
    args = parser.parse_args(argv)
    env = dict(os.environ, MPLBACKEND="Agg", NONSMOOTH_ROD_COMPILE="wait")
    builds = {}
    for src in (args.src_a, args.src_b):
        p = subprocess.Popen([sys.executable, "-c", TARGETS_WORKER if args.targets else WORKER],
                             stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=dict(env, PYTHONPATH=src))
        if p.stdout.readline().strip() != "ready":
            print(f"{src}: the worker did not start")
            return 1
        builds[src] = p
    if args.targets:
        targets(builds, args.runs)
        return _close(builds)
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
    return _close(builds)


def _close(builds) -> int:
    for p in builds.values():
        p.stdin.close()
        p.wait()
    return 0


def targets(builds, runs) -> None:
    """Issue 25's cases in both builds, alternated, a yardstick each round: whole call / loop per
    step in yardsticks (medians over the rounds)."""
    ratios = {}
    for run in range(runs):
        y = yardstick_us(n=5000, repeats=3)
        order = list(builds.items()) if run % 2 == 0 else list(reversed(builds.items()))
        for name in TARGET_CASES:
            for s in SOLVERS:
                for src, p in order:
                    p.stdin.write(f"{name} {s}\n")
                    p.stdin.flush()
                    whole, loop = map(float, p.stdout.readline().split())
                    ratios.setdefault((name, s, src), []).append((whole / y, loop / y))
    print(f"{'case':16s} {'solver':6s}  " + "  ".join(f"{'build ' + str(b + 1) + ' whole / loop x yd':>26s}"
                                                      for b in range(len(builds))))
    for name in TARGET_CASES:
        for s in SOLVERS:
            cells = []
            for src in builds:
                whole = statistics.median(w for w, _ in ratios[(name, s, src)])
                loop = statistics.median(lo for _, lo in ratios[(name, s, src)])
                cells.append(f"{whole:19.2f} / {loop:5.2f}")
            print(f"{name:16s} {s:6s}  " + "  ".join(cells))
    print("  ".join(f"build {b + 1}: {src}" for b, src in enumerate(builds)))


if __name__ == "__main__":
    raise SystemExit(main())
