"""Cost per Moreau–Jean step of the rows and piles of `toys/stacks.py`, side by side with MuJoCo
(planar), PyBullet and pymunk in one run (issue 26), and the drift of a pile at rest.

    python benchmarks/bench_piles.py [--quick] [--repeats 3] [--steps 500] [--drift STEPS] [--only TEXT]

Scenes: a row of N balls on a floor, N = 2, 4, …, 256, the first rolling at 1 m/s into the others
(μ 0.3/0.2); a pyramid pile of 4 and of 8 rows of disks between two walls on a floor (μ 0.5/0.4,
every disk on the floor and the walls, every pair of disks declared: the broad phase drops the
pairs out of reach). Ours: `nr.simulate` with pgs (and lemke on the smaller scenes), CPU time of
the whole call per step (and, in the note, of its loop alone: `result.cpu_time_s`), median of
the repeats, h = 1 ms. The peers (benchmarks/planar_peers.py,
each optional, their settings printed) run the same geometry, μ, h and initial state. Every cost
is also given in yardsticks (one 3×3 numpy.linalg.solve in a Python loop, measured before each
scene): ratios are what to read on a shared machine. The last columns: ours ÷ MuJoCo.

`--drift STEPS`: the 8-row pile at rest for STEPS steps (10⁵ in the issue) with pgs, and the
largest |q − q0| over the run (goal: < 1e-10). `--quick`: N = 2, 8, the 4-row pile, 50 steps, one
repeat, drift over 200 steps of the 4-row pile (the test runs it). `--only TEXT`: only the scenes
whose name contains TEXT (e.g. `--only "N=16"`, `--only pile`), repeatable.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import nonsmooth_rod as nr
from nonsmooth_rod.toys import stacks

sys.path.insert(0, str(Path(__file__).resolve().parent))  # benchmarks/ for the yardstick and peers
import planar_peers  # noqa: E402
from yardstick import yardstick_us  # noqa: E402

LEMKE_MAX_BALLS = 16  # lemke's dense tableau grows as contacts³: rows beyond, and the 8-row pile, are pgs only


def scenes(quick: bool):
    """(name, (scene, q0, v0), peers' description, lemke too)."""
    for n in ((2, 8) if quick else (2, 4, 8, 16, 32, 64, 128, 256)):
        scene, q0, v0 = stacks.ball_row(n)
        yield f"ball row N={n}", (scene, q0, v0), _peer_scene(q0, v0, 0.3, None), n <= LEMKE_MAX_BALLS
    for rows in ((4,) if quick else (4, 8)):
        scene, q0, v0 = stacks.disk_pile(rows)
        left, right = stacks.pile_walls(rows)
        yield f"pile {rows} rows", (scene, q0, v0), _peer_scene(q0, v0, 0.5, (left.point[0], right.point[0])), \
            rows <= 4


def _peer_scene(q0, v0, mu, walls):
    return {"centres": list(zip(q0[0::3].tolist(), q0[1::3].tolist())),
            "v0": list(zip(v0[0::3].tolist(), v0[1::3].tolist(), v0[2::3].tolist())),
            "radius": stacks.BALL_RADIUS, "mass": stacks.BALL_MASS, "mu": mu, "walls": walls}


def ours_step_us(scene, q0, v0, solver, h, steps, repeats):
    """Median µs per step of the whole `nr.simulate` call and of its loop (`cpu_time_s`: the
    steps without the call's set-up and result), and the last run."""
    # repeat_rest off: a pile at rest would cost its first steps only (the peers step every step)
    run = nr.simulate(scene, q0, v0, h * steps, h=h, solver=solver, repeat_rest=False)  # compiles on first use
    whole, loop = [], []
    for _ in range(repeats):
        t0 = time.process_time()
        run = nr.simulate(scene, q0, v0, h * steps, h=h, solver=solver, repeat_rest=False)
        whole.append((time.process_time() - t0) / run.steps * 1e6)
        loop.append(run.cpu_time_s / run.steps * 1e6)
    return statistics.median(whole), statistics.median(loop), run


def drift(rows: int, steps: int, h: float = 1e-3):
    """Largest |q − q0| of a pile of `rows` rows at rest over `steps` pgs steps, and the run."""
    scene, q0, v0 = stacks.disk_pile(rows)
    run = nr.simulate(scene, q0, v0, steps * h, h=h, solver="pgs", save_every=steps * h / 100,
                      repeat_rest=False)  # every step solved: the drift of the solver, not of a repeat
    return float(np.max(np.abs(run.q - q0))), run


def table(quick: bool, steps: int, repeats: int, h: float = 1e-3, only=()):
    """Print one line per scene and engine; returns {scene: {engine: µs}} and the yardsticks."""
    costs, yards = {}, []
    print(f"{'scene':18s} {'contacts':>8s} {'engine':>10s} {'us/step':>9s} {'x yd':>7s} {'/ mujoco':>8s}  note")
    for name, (scene, q0, v0), peer_scene, with_lemke in scenes(quick):
        if only and not any(text in name for text in only):
            continue
        yard = yardstick_us(n=5000, repeats=3)
        yards.append(yard)
        row = {}
        for solver in ("pgs", "lemke") if with_lemke else ("pgs",):
            us, loop_us, run = ours_step_us(scene, q0, v0, solver, h, steps, repeats)
            row[solver] = us
            note = f"loop {loop_us:.1f} us ({loop_us / yard:.2f} yd), {run.stats['solver_iterations'] / run.steps:.1f} it/step"
            note += "" if run.status == "ok" else f"  {run.status}: {run.message[:60]}"
            row[solver + " note"] = note
        for peer, us in planar_peers.peers_step_us(peer_scene, h, steps, repeats):
            row[peer] = us
        mujoco = row.get("mujoco")
        for engine, us in row.items():
            if engine.endswith(" note"):
                continue
            ratio = f"{us / mujoco:8.2f}" if mujoco else f"{'':8s}"
            print(f"{name:18s} {len(scene.contacts):8d} {engine:>10s} {us:9.1f} {us / yard:7.2f} {ratio}  "
                  f"{row.get(engine + ' note', '')}")
        costs[name] = {k: v for k, v in row.items() if not k.endswith(" note")}
    return costs, yards


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--steps", type=int, default=500)
    parser.add_argument("--drift", type=int, default=0, metavar="STEPS")
    parser.add_argument("--only", action="append", default=[], metavar="TEXT",
                        help="only the scenes whose name contains TEXT (repeatable)")
    args = parser.parse_args(argv)
    steps, repeats = (50, 1) if args.quick else (args.steps, args.repeats)
    for peer, settings in planar_peers.PEER_SETTINGS.items():
        print(f"# {peer}: {settings}")
    _, yards = table(args.quick, steps, repeats, only=args.only)
    if yards:
        print(f"yardstick (3x3 numpy.linalg.solve in a Python loop): median {statistics.median(yards):.2f} us")
    if args.drift or args.quick:
        rows, n = (4, 200) if args.quick else (8, args.drift)
        largest, run = drift(rows, n)
        print(f"pile {rows} rows at rest, {n} steps, pgs: max |q - q0| = {largest:.3e} m ({run.status}, "
              f"{run.stats['solver_iterations'] / run.steps:.2f} sweeps/step)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
