"""The woodpecker toy's limit cycle against the published model and Siconos' reference run.

    python benchmarks/bench_woodpecker.py [--t-end 1.0] [--quick]

Runs the toy's planar scene (Moreau–Jean, several steps h) with the exact geometry and linearised
as published (geometry="linearised": LinearRelation contacts with the published constant rows, a
LinearJoint hinge), and the three-coordinate model on its own (toys/woodpecker_reduced.py:
linearised as published, and with the exact geometry), and
prints per run the limit cycle's period and the sleeve's drop per cycle (the last whole cycle),
the mean descent speed over the whole cycles and the contacts closing in one cycle, next to
Siconos' reference run (examples/mechanics/Woodpecker/Woodpecker.ref). --quick: 0.3 s at
h = 1e-4 only (the linearised toy at 5e-5; a test runs it).
"""
from __future__ import annotations

import argparse

import numpy as np

import nonsmooth_rod as nr
from nonsmooth_rod.toys.woodpecker import Woodpecker, limit_cycle
from nonsmooth_rod.toys.woodpecker_reduced import SICONOS, run_reduced


def _line(label: str, cycle) -> str:
    if not len(cycle.periods):
        return f"{label:38s} no whole cycle"
    return (f"{label:38s} period {cycle.periods[-1]:.5f} s  drop {1e3 * cycle.descents[-1]:6.3f} mm  "
            f"mean speed {cycle.mean_speed:.4f} m/s  cycle {' '.join(cycle.sequences[-1])}")


def _reduced(t_end: float, h: float, linear: bool):
    t, q, _, closings = run_reduced(Woodpecker(), t_end, h, linear)
    times, names = [c[0] for c in closings], [c[1] for c in closings]
    return limit_cycle(None, times, names, np.interp(times, t, q[:, 0]))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=1.0)
    parser.add_argument("--quick", action="store_true", help="0.3 s, h = 1e-4 only")
    args = parser.parse_args(argv)
    t_end = 0.3 if args.quick else args.t_end
    steps = (1e-4,) if args.quick else (2e-4, 1e-4, 5e-5, 2e-5)
    siconos = limit_cycle(None, SICONOS["beak_times"], ["beak", "beak"], SICONOS["heights"])
    print(_line("Siconos' reference (linearised)", siconos).replace("cycle beak", "cycle " +
                                                                    " ".join(SICONOS["sequence"])))
    # the linearised toy's cycles alternate at h = 1e-4 (0.1444/0.1467 s): its quick run takes 5e-5
    linearised_steps = (5e-5,) if args.quick else (1e-4, 5e-5, 2e-5)
    for geometry in ("exact", "linearised"):
        toy = Woodpecker(geometry=geometry)
        for h in (steps if geometry == "exact" else linearised_steps):
            result = nr.simulate(toy.scene(), *toy.initial_state(), t_end, "moreau-jean", h=h)
            print(_line(f"toy {geometry}, Moreau–Jean h = {h:g}", limit_cycle(result)))
    h_reduced = steps[-1] if args.quick else 2 * steps[-1]
    for linear in (True, False):
        label = f"3-coordinate {'linearised' if linear else 'exact'}, h = {h_reduced:g}"
        print(_line(label, _reduced(t_end, h_reduced, linear)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
