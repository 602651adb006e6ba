"""The cost of contacts found from shapes against the same contacts declared by hand, and the
box scenes beside pymunk and MuJoCo.

    python benchmarks/bench_shapes.py [--boxes 5] [--steps 20000] [--repeat 5] [--quick]
    python benchmarks/bench_shapes.py --peers [--repeat 3] [--quick]

A tower of `--boxes` boxes (0.4 × 0.3 m, μs = 0.5, μd = 0.4) on a floor, at rest, run by the
compiled Moreau–Jean loop (lemke, h = 1 ms): once with the contacts `find_contacts` lists for
every pair of shapes (32 candidates per pair of boxes, 4 per box on the floor; the broad phase
leaves the far pairs out), once with only the contacts that touch declared by hand (each box's
two bottom corners on the top of the box below, or on the floor: the very contacts, in the
same order, that the found run keeps at the flush corners, model/collision.py). Prints CPU µs
per step of each (median of --repeat runs, the two alternated, after a warm-up run that
compiles) and the overhead of finding, the positions' largest change over the run (the tower
holds: zero creep), and exits 1 if the two runs' trajectories differ by more than round-off.
--quick: 400 steps, one repeat.

--peers: the tower of 5 boxes at rest (1000 steps), the row of 20 dominoes toppling
(toys.Dominoes, pushed at 1.1 J*, 2500 steps) and a heap of 50 boxes dropped into a bin
(toys.BoxHeap, 2000 steps), h = 1 ms, contacts found (every pair of shapes; the dominoes: each
with its neighbours and the floor), CPU time per step of the whole `nr.simulate` call (lemke,
repeat_rest off: every step solved, as the peers step), median of --repeat; beside MuJoCo
(planar) and pymunk (benchmarks/planar_peers.py, their settings printed), which step the same
boxes, masses, friction, h and initial state and find their contacts themselves. Run it with a
Python that has the peers (docs/performance.md). Each of ours also gives the deepest overlap of
any two boxes or a box and a line over the run (separating axes: physics, not speed). --quick:
a tenth of the steps, the heap of 20 boxes, one repeat.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import nonsmooth_rod as nr
from nonsmooth_rod.model.collision import deepest_overlap
from nonsmooth_rod.toys.box_heap import BoxHeap
from nonsmooth_rod.toys.dominoes import Dominoes

sys.path.insert(0, str(Path(__file__).resolve().parent))  # benchmarks/ for the peers
import planar_peers  # noqa: E402

W, H = 0.4, 0.3


def tower(n: int, found: bool):
    """(scene, q0) of a tower of n boxes, with found or hand-declared contacts."""
    bodies = [nr.RigidBody(1.0, (W * W + H * H) / 12.0, name=f"box{k}") for k in range(n)]
    law, floor, box = nr.ContactLaw.of(0.5, 0.4), nr.Line(), nr.Polygon.rectangle(W, H)
    if found:
        contacts = nr.find_contacts(bodies, {b.name: box for b in bodies}, {"floor": floor}, nr.PairLaws(default=law))
    else:
        contacts = [nr.PointOnLine(0, box.vertices[i], floor, law, name=f"box0.v{i}/floor") for i in (0, 1)]
        for k in range(1, n):
            for i in (0, 1):
                contacts.append(nr.VertexOnEdge(k, box.vertices[i], k - 1, *box.edge(2), cone=box.cone(i), law=law,
                                                name=f"box{k}.v{i}/box{k - 1}.e2"))
    q0 = np.zeros(3 * n)
    q0[1::3] = H / 2 + H * np.arange(n)
    return nr.Scene(bodies, contacts), q0


def _timed(scene, q0, steps: int):
    """(CPU µs per step, result) of one run: CPU time, which the other processes of a loaded
    machine disturb far less than the wall clock."""
    started = time.process_time()
    result = nr.simulate(scene, q0, np.zeros_like(q0), steps * 1e-3, "moreau-jean", h=1e-3, save_every=0.1)
    return (time.process_time() - started) / steps * 1e6, result


def peer_scenes(quick: bool):
    """(name, scene, q0, v0, shapes, lines, steps, peers' scene dict) of the tower, the dominoes, the heap."""
    scene, q0 = tower(5, True)
    shapes = {b.name: nr.Polygon.rectangle(W, H) for b in scene.bodies}
    yield ("tower 5 boxes", scene, q0, np.zeros_like(q0), shapes, [nr.Line()], 1000,
           _boxes_for_peers(q0, np.zeros_like(q0), W, H, 1.0, 0.5, 0.5, [nr.Line()]))
    toy = Dominoes()
    q0, v0 = toy.initial_state()
    yield ("dominoes 20", toy.scene(), q0, v0, toy.shapes(), [nr.Line()], 2500,
           _boxes_for_peers(q0, v0, toy.thickness, toy.height, toy.mass, toy.mu_dominoes, toy.mu_floor, [nr.Line()]))
    heap = BoxHeap(n=20 if quick else 50)
    q0, v0 = heap.initial_state()
    lines = list(heap.obstacles().values())
    yield (f"heap {heap.n} boxes", heap.scene(), q0, v0, heap.shapes(), lines, 2000,
           _boxes_for_peers(q0, v0, heap.width, heap.height, heap.mass, heap.mu_s, heap.mu_s, lines))


def _boxes_for_peers(q0, v0, width, height, mass, mu, mu_line, lines):
    return {"boxes": [tuple(q0[k:k + 3]) + tuple(v0[k:k + 3]) for k in range(0, q0.size, 3)], "width": width,
            "height": height, "mass": mass, "mu": mu, "mu_line": mu_line, "depth": 0.05,
            "lines": [(line.point, line.angle) for line in lines]}


def peers_table(quick: bool, repeat: int, h: float = 1e-3) -> None:
    for peer, settings in planar_peers.BOX_PEER_SETTINGS.items():
        print(f"# {peer}: {settings}")
    print(f"{'scene':16s} {'contacts':>8s} {'engine':>10s} {'us/step':>9s} {'/ mujoco':>8s}  note")
    for name, scene, q0, v0, shapes, lines, steps, peer_scene in peer_scenes(quick):
        steps = steps // 10 if quick else steps
        nr.simulate(scene, q0, v0, 0.01, "moreau-jean", h=h)  # compile, warm
        costs, run = [], None
        for _ in range(repeat):
            started = time.process_time()
            run = nr.simulate(scene, q0, v0, steps * h, "moreau-jean", h=h, save_every=0.01, repeat_rest=False)
            costs.append((time.process_time() - started) / steps * 1e6)
        row = {"ours lemke": statistics.median(costs)}
        overlap = deepest_overlap(scene.bodies, shapes, run.trajectory.q, lines)
        note = f"{run.status}, deepest overlap {overlap:.1e} m"
        row.update(planar_peers.box_peers_step_us(peer_scene, h, steps, repeat))
        mujoco = row.get("mujoco")
        for engine, us in row.items():
            ratio = f"{us / mujoco:8.2f}" if mujoco else f"{'':8s}"
            print(f"{name:16s} {len(scene.contacts):8d} {engine:>10s} {us:9.1f} {ratio}  "
                  f"{note if engine.startswith('ours') else ''}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--boxes", type=int, default=5)
    parser.add_argument("--steps", type=int, default=20000)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--peers", action="store_true")
    args = parser.parse_args(argv)
    if args.peers:
        peers_table(args.quick, 1 if args.quick else args.repeat)
        return 0
    steps, repeat = (400, 1) if args.quick else (args.steps, args.repeat)
    cases = {"declared": tower(args.boxes, False), "found": tower(args.boxes, True)}
    for scene, q0 in cases.values():
        nr.simulate(scene, q0, np.zeros_like(q0), 0.01, "moreau-jean", h=1e-3)  # compile, warm
    costs, results = {name: [] for name in cases}, {}
    for _ in range(repeat):  # alternated: the two see the same load
        for name, (scene, q0) in cases.items():
            us, results[name] = _timed(scene, q0, steps)
            costs[name].append(us)
    us = {name: statistics.median(c) for name, c in costs.items()}
    for name, (scene, q0) in cases.items():
        creep = float(np.abs(results[name].trajectory.q - q0).max())
        print(f"{name:8s}  {len(scene.contacts):4d} contacts  {us[name]:8.2f} µs/step  creep {creep:.1e} m")
    print(f"finding the contacts costs {100 * (us['found'] / us['declared'] - 1.0):+.1f} % per step "
          f"({args.boxes} boxes, {steps} steps, CPU time, median of {repeat})")
    same = np.allclose(results["found"].trajectory.q, results["declared"].trajectory.q, rtol=0, atol=1e-12)
    if not same:
        print("the found and the declared runs differ", file=sys.stderr)
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
