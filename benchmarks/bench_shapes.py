"""The cost of contacts found from shapes against the same contacts declared by hand.

    python benchmarks/bench_shapes.py [--boxes 5] [--steps 20000] [--repeat 3] [--quick]

A tower of `--boxes` boxes (0.4 × 0.3 m, μs = 0.5, μd = 0.4) on a floor, at rest, run by the
compiled Moreau–Jean loop (lemke, h = 1 ms): once with the contacts `find_contacts` lists for
every pair of shapes (32 candidates per pair of boxes, 4 per box on the floor; the broad phase
leaves the far pairs out), once with only the contacts that touch declared by hand (each box's
two bottom corners on the top of the box below, or on the floor). Prints µs per step of each
(best of --repeat runs, after a warm-up run that compiles) and the overhead of finding, the
positions' largest change over the run (the tower holds: zero creep), and exits 1 if the two
runs' trajectories differ by more than round-off. --quick: 400 steps, one repeat.
"""
from __future__ import annotations

import argparse
import sys
import time

import numpy as np

import nonsmooth_rod as nr

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


def _timed(scene, q0, steps: int, repeat: int):
    best, result = np.inf, None
    for _ in range(repeat):
        started = time.perf_counter()
        result = nr.simulate(scene, q0, np.zeros_like(q0), steps * 1e-3, "moreau-jean", h=1e-3, save_every=0.1)
        best = min(best, time.perf_counter() - started)
    return best / steps * 1e6, result


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--boxes", type=int, default=5)
    parser.add_argument("--steps", type=int, default=20000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args(argv)
    steps, repeat = (400, 1) if args.quick else (args.steps, args.repeat)
    rows = {}
    for found in (False, True):
        scene, q0 = tower(args.boxes, found)
        nr.simulate(scene, q0, np.zeros_like(q0), 0.01, "moreau-jean", h=1e-3)  # compile, warm
        rows[found] = (len(scene.contacts), *_timed(scene, q0, steps, repeat), q0)
    for found, (nc, us, result, q0) in rows.items():
        creep = float(np.abs(result.trajectory.q - q0).max())
        print(f"{'found   ' if found else 'declared'}  {nc:4d} contacts  {us:8.2f} µs/step  creep {creep:.1e} m")
    overhead = rows[True][1] / rows[False][1] - 1.0
    print(f"finding the contacts costs {100 * overhead:+.1f} % per step ({args.boxes} boxes, {steps} steps)")
    same = np.allclose(rows[True][2].trajectory.q, rows[False][2].trajectory.q, rtol=0, atol=1e-12)
    if not same:
        print("the found and the declared runs differ", file=sys.stderr)
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
