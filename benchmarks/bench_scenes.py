"""Microseconds per Moreau–Jean step on every kind of scene, and the engine's cold compile time.

    python benchmarks/bench_scenes.py [--quick] [--repeats 5] [--no-compile-time] [--max-balls 256] [--only NAME]
    python benchmarks/bench_scenes.py --fixed-cost [--repeats 300]    # the fixed cost of a call alone

Scenes: the paper's rod, each toy, a frictionless ladder (2 contacts, 1 body), a row of N balls
on a floor (N − 1 disk–disk and N disk–floor contacts, the first ball rolling into the others),
and a pyramid pile of disks on a floor — with lemke and pgs (lemke only up to 32 contacts: its
dense tableau grows as contacts³). Each run is timed whole, through `nr.simulate` (CPU time of
the call / steps, median of the repeats; the loop's own share, `result.cpu_time_s`, beside it),
next to the yardstick, one 3×3 numpy.linalg.solve in a Python loop, timed again just
before each scene (the shared machine's speed drifts within a run); ratios are what to read.
MuJoCo (mj_step) steps the ball rows and the pile when `mujoco` is installed (optional extra
`bench`); PyBullet likewise when `pybullet` is.

Issue 25's targets, per step through `nr.simulate`: the paper's rod ≤ 0.3 yardsticks at
h = 1e-4, one-contact toys ≤ 0.2, two-contact toys ≤ 0.4; and a 50-step run's whole call
≤ 1.2× its loop (the section "targets" below the table).

The cold compile time is a subprocess with an empty NUMBA_CACHE_DIR running one short rod run
(issue 16's target: ≤ 5 s on an idle 2-core machine).
"""
from __future__ import annotations

import argparse
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import nonsmooth_rod as nr
from nonsmooth_rod import toys
from nonsmooth_rod.toys import stacks
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import Line, PointOnLine
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.model.scene import Scene
from nonsmooth_rod.rod.problem import RodProblem

sys.path.insert(0, str(Path(__file__).resolve().parent))  # benchmarks/ for the yardstick
import other_engines  # noqa: E402  (benchmarks/other_engines.py)
from yardstick import yardstick_us  # noqa: E402  (benchmarks/yardstick.py)

LEMKE_MAX_CONTACTS = 32


def ladder():
    law = ContactLaw.of(0.0, 0.0)
    phi = math.radians(60.0)
    contacts = [PointOnLine(0, (0.5, 0.0), Line((0.0, 0.0), -math.pi / 2), law, "top"),
                PointOnLine(0, (-0.5, 0.0), Line(), law, "bottom")]
    q0 = np.array([0.25, 0.5 * math.sin(phi), math.pi - phi])
    return Scene([RigidBody(1.0, 1.0 / 12)], contacts), q0, np.zeros(3)


def scenes(max_balls: int, quick: bool):
    rod = RodProblem.paper(2)
    yield "rod (paper case 2)", (rod.scene(), *rod.initial_state())
    for name in ("BouncingBall", "BlockOnIncline", "PushedBlock", "DiskOnIncline", "BeltOscillator",
                 "RockingBlock", "PainleveRod", "BallRow"):
        toy = getattr(toys, name)()
        yield f"toy {name}", (toy.scene(), *toy.initial_state())
    yield "ladder", ladder()
    n = 2
    while n <= max_balls:
        yield f"ball row N={n}", stacks.ball_row(n)  # the same scenes the tests run
        n *= 4 if quick else 2
    yield "pile 4 rows", stacks.disk_pile(4)
    if not quick:
        yield "pile 8 rows", stacks.disk_pile(8)


def other_engines_us(name, q0, h, steps, repeats):
    """(engine, µs per step) of MuJoCo and PyBullet on the same ball row or pile (when installed)."""
    if not name.startswith(("ball row", "pile")):
        return []
    centres = list(zip(q0[0::3].tolist(), q0[1::3].tolist()))
    first = 1.0 if name.startswith("ball row") else 0.0
    out = []
    for engine, step in (("mujoco", other_engines.mujoco_step_us), ("bullet", other_engines.pybullet_step_us)):
        cost = step(centres, stacks.BALL_RADIUS, stacks.BALL_MASS, h, steps, repeats, first_speed=first)
        if cost is not None:
            out.append((engine, cost))
    return out


def step_us(scene, q0, v0, solver, h, steps, repeats):
    """(whole call, loop) µs per step of `nr.simulate` (medians of the repeats), and the last run."""
    # repeat_rest off: a scene at rest (the pile) would cost its first steps only; this times steps
    run = nr.simulate(scene, q0, v0, h * steps, method="moreau-jean", h=h, solver=solver,
                      repeat_rest=False)  # compiles on first use
    if run.status != "ok":
        return math.nan, math.nan, run
    whole, loop = [], []
    for _ in range(repeats):
        t0 = time.process_time()
        run = nr.simulate(scene, q0, v0, h * steps, method="moreau-jean", h=h, solver=solver, repeat_rest=False)
        whole.append((time.process_time() - t0) / run.steps * 1e6)
        loop.append(run.cpu_time_s / run.steps * 1e6)
    return statistics.median(whole), statistics.median(loop), run


ONE_CONTACT = ("BouncingBall", "DiskOnIncline", "PainleveRod")
TWO_CONTACTS = ("BlockOnIncline", "PushedBlock", "BeltOscillator", "RockingBlock")


def targets(repeats: int, quick: bool) -> None:
    """Issue 25's per-step targets through nr.simulate, and whole/loop of 50-step runs."""
    rod = RodProblem.paper(2)
    cases = [("rod, h = 1e-4", rod.scene(), *rod.initial_state(), 1e-4, 500 if quick else 4000, 0.3)]
    for name in ONE_CONTACT + TWO_CONTACTS:
        toy = getattr(toys, name)()
        cases.append((f"toy {name}", toy.scene(), *toy.initial_state(), 1e-3, 200 if quick else 500,
                      0.2 if name in ONE_CONTACT else 0.4))
    print(f"{'targets (issue 25)':28s} {'solver':>6s} {'whole x yd':>10s} {'target':>6s} {'50 steps whole/loop':>20s}")
    for name, scene, q0, v0, h, steps, target in cases:
        yard = yardstick_us(n=5000, repeats=3)
        for solver in ("lemke", "pgs"):
            whole, _, run = step_us(scene, q0, v0, solver, h, steps, repeats)
            short_whole, short_loop, _ = step_us(scene, q0, v0, solver, h, 50, max(repeats, 5))
            print(f"{name:28s} {solver:>6s} {whole / yard:10.2f} {target:6.1f} {short_whole / short_loop:20.2f}"
                  f"{'' if run.status == 'ok' else '  ' + run.status}")


def call_us(scene, q0, v0, solver, h, steps, calls, blocks=7):
    """CPU µs of one whole `nr.simulate` call of `steps` steps, timed over blocks of `calls` calls
    (median of the blocks): a clock read costs ~0.5 µs, and timing each call alone would add two
    to what a one-step call is measured to cost."""
    args = dict(method="moreau-jean", h=h, solver=solver, repeat_rest=False)
    for _ in range(max(10, calls // 10)):
        nr.simulate(scene, q0, v0, h * steps, **args)
    times = []
    for _ in range(blocks):
        t0 = time.process_time()
        for _ in range(calls):
            nr.simulate(scene, q0, v0, h * steps, **args)
        times.append((time.process_time() - t0) / calls * 1e6)
    return statistics.median(times)


def fixed_cost(repeats: int) -> None:
    """Issue 25's fixed cost of a call: 50-step one-body runs through nr.simulate, the whole call
    against its loop (`result.cpu_time_s`, which also counts taking the samples from the loop's
    records), the part outside it, and a one-step call (what a call costs besides its steps:
    target ≤ 10 yardsticks; timed in blocks of `repeats` calls, `call_us`), in yardsticks; CPU time,
    medians of `repeats` calls after a few warm ones."""
    print(f"{'fixed cost, 50 steps':28s} {'whole x yd':>10s} {'loop x yd':>9s} {'outside x yd':>12s} "
          f"{'whole/loop':>10s} {'1 step x yd':>11s}")
    for name in ONE_CONTACT + ("BlockOnIncline",):
        toy = getattr(toys, name)()
        scene, (q0, v0) = toy.scene(), toy.initial_state()
        whole, loop, _ = step_us(scene, q0, v0, "lemke", 1e-3, 50, repeats)
        one = call_us(scene, q0, v0, "lemke", 1e-3, 1, repeats)
        yard = yardstick_us(n=5000, repeats=3)
        print(f"toy {name:24s} {whole * 50 / yard:10.1f} {loop * 50 / yard:9.1f} {(whole - loop) * 50 / yard:12.1f} "
              f"{whole / loop:10.2f} {one / yard:11.1f}")


def cold_compile_seconds() -> float:
    """Wall time of a fresh process with an empty numba cache running one short rod run, minus
    the same process with a warm cache (imports and the run itself)."""
    code = ("from nonsmooth_rod.rod.problem import RodProblem;"
            "from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions;"
            "p = RodProblem.paper(2); q0, v0 = p.initial_state();"
            "MoreauJean(MoreauJeanOptions(h=1e-2)).run(p.scene(), q0, v0, 0.05)")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([os.path.join(os.path.dirname(__file__), "..", "src"),
                                                         os.environ.get("PYTHONPATH", "")]))
    env["NONSMOOTH_ROD_COMPILE"] = "wait"  # the compile itself, not a run that goes on interpreted
    with tempfile.TemporaryDirectory() as cache:
        env["NUMBA_CACHE_DIR"] = cache
        walls = []
        for _ in range(2):  # cold, then warm (cache hit)
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-c", code], env=env, check=True)
            walls.append(time.perf_counter() - t0)
    return walls[0], walls[1]


def plot_rows(rows_cost: dict, path: str) -> None:
    """Cost per step against the number of balls of a row, every engine, log–log, in yardsticks."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = {"lemke": "ours, lemke", "pgs": "ours, pgs", "mujoco": "MuJoCo mj_step", "bullet": "PyBullet stepSimulation"}
    fig, ax = plt.subplots(figsize=(6, 4.2), layout="constrained")
    for key, points in rows_cost.items():
        n, us = zip(*points)
        ax.loglog(n, us, "o-", label=labels.get(key, key))
    ax.set(xlabel="balls in the row N (2N − 1 contacts)", ylabel="cost per step [× yardstick]",
           title="a row of N balls on a floor, h = 1 ms")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="few steps, N = 2, 8, 32, one pile, 2 repeats")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--max-balls", type=int, default=None)
    parser.add_argument("--no-compile-time", action="store_true")
    parser.add_argument("--only", default="", help="run only the scenes whose name contains this")
    parser.add_argument("--plot", default=None, metavar="PNG", help="log–log plot of cost per step against N (rows)")
    parser.add_argument("--fixed-cost", action="store_true",
                        help="only the fixed cost of a call: 50-step one-body runs, whole against loop")
    args = parser.parse_args(argv)
    if args.fixed_cost:
        fixed_cost(max(args.repeats, 100))
        return 0
    rows_cost = {}  # engine/solver → [(N balls, yardsticks per step)] for the ball rows
    repeats = 2 if args.quick else args.repeats
    max_balls = args.max_balls or (32 if args.quick else 256)
    h, steps = 1e-3, (50 if args.quick else 500)
    yards = []  # the yardstick again before each scene: the shared machine's speed drifts in a run
    print(f"{'scene':28s} {'contacts':>8s} {'solver':>6s} {'us/step':>10s} {'x yardstick':>11s} {'loop x yd':>9s}  compiled")
    for name, (scene, q0, v0) in scenes(max_balls, args.quick):
        if args.only not in name:
            continue
        yard = yardstick_us(n=5000, repeats=3)
        yards.append(yard)
        nc = len(scene.contacts)
        for solver in ("lemke", "pgs"):
            if solver == "lemke" and nc > LEMKE_MAX_CONTACTS:
                continue
            us, loop_us, run = step_us(scene, q0, v0, solver, h, steps, repeats)
            note = "" if run.status == "ok" else f"  {run.status}: {run.message[:60]}"
            print(f"{name:28s} {nc:8d} {solver:>6s} {us:10.1f} {us / yard:11.2f} {loop_us / yard:9.2f}  "
                  f"{run.stats['compiled']}{note}")
            if name.startswith("ball row"):
                rows_cost.setdefault(solver, []).append((len(scene.bodies), us / yard))
        for engine, cost in other_engines_us(name, q0, h, steps, repeats):
            print(f"{name:28s} {nc:8d} {engine:>6s} {cost:10.1f} {cost / yard:11.2f}  (its own step)")
            if name.startswith("ball row"):
                rows_cost.setdefault(engine, []).append((len(scene.bodies), cost / yard))
    yard = statistics.median(yards) if yards else yardstick_us(repeats=repeats)
    print(f"yardstick (3x3 numpy.linalg.solve in a Python loop, measured before each scene): median {yard:.2f} us, "
          f"{min(yards, default=yard):.2f}-{max(yards, default=yard):.2f}")
    if args.plot:
        plot_rows(rows_cost, args.plot)
    if not args.only:
        targets(repeats, args.quick)
    if not args.no_compile_time:
        cold, warm = cold_compile_seconds()
        print(f"first run, empty numba cache: {cold:.1f} s ({cold * 1e6 / yard:.2g} yardsticks); "
              f"with the cache: {warm:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
