"""Housner's rocking block (e = 0) with error control against the event-driven reference (issue 28).

    python benchmarks/bench_rocking.py [--quick] [--tol TOL | --hybrid H] [--resolution D] [--out DIR]

For slenderness α = 11° … 41° (half-height 0.3 m, tilt 10°, 3 s): the impacts of the reference
(rtol = atol = 1e-11) and of Moreau–Jean with `tol` (default 1e-6), both counted by the one rule
of integrators/accumulation.py at the resolution D (default: tol) — an impact counts when the
flight ending in it rose above D —, the time of each one's last impact, the largest
|θ̇⁺/θ̇⁻| − (1 − 1.5 sin²α) over the counted impacts and the first one off by more than 1e-4
with its |θ̇⁻|. Writes DIR/rocking.csv and prints markdown (docs/error_control.md quotes it).
--quick: α = 41° only (a test runs it). --hybrid H: the hybrid method (Runge–Kutta of order 4
between events, integrators/hybrid.py) at step H instead of tol (evaluations: its steps).
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import nonsmooth_rod as nr
from nonsmooth_rod import toys
from nonsmooth_rod.io import write_csv

ALPHAS = {"full": (11.0, 18.43, 26.0, 33.0, 41.0), "quick": (41.0,)}
T_END = 3.0
RATIO_TOL = 1e-4
COLUMNS = ("alpha_deg", "resolution", "reference_impacts", "reference_last_s", "impacts", "last_s", "evaluations",
           "unresolved_impacts", "ratio_error_max", "first_off", "first_off_rate")


def block(alpha_deg: float) -> toys.RockingBlock:
    return toys.RockingBlock(half_width=0.3 * math.tan(math.radians(alpha_deg)), half_height=0.3)


def ratio_errors(toy: toys.RockingBlock, result) -> list[tuple[float, float]]:
    """(|θ̇⁻|, |ratio − Housner's|) at each impact."""
    return [(abs(before), abs(abs(after / before) - toy.ratio)) for _, before, after in toys.impact_rate_pairs(result)]


def measure(alpha_deg: float, tol: float, hybrid_h: float | None = None, resolution: float | None = None) -> dict:
    toy = block(alpha_deg)
    q0, v0 = toy.initial_state()
    resolution = tol if resolution is None else resolution
    reference = nr.simulate(toy.scene(), q0, v0, T_END, "event-driven", rtol=1e-11, atol=1e-11, resolution=resolution)
    run = (nr.simulate(toy.scene(), q0, v0, T_END, "moreau-jean", tol=tol, resolution=resolution) if hybrid_h is None
           else nr.simulate(toy.scene(), q0, v0, T_END, "hybrid", h=hybrid_h, resolution=resolution))
    errors = ratio_errors(toy, run)
    off = next((k for k, (_, e) in enumerate(errors) if e > RATIO_TOL), None)
    return {"alpha_deg": alpha_deg, "resolution": resolution, "reference_impacts": len(reference.impacts),
            "reference_last_s": reference.impacts[-1].t, "impacts": len(run.impacts), "last_s": run.impacts[-1].t,
            "evaluations": run.stats.get("step_evaluations", run.steps),
            "unresolved_impacts": run.stats["unresolved_impacts"], "ratio_error_max": max(e for _, e in errors),
            "first_off": -1 if off is None else off + 1, "first_off_rate": math.nan if off is None else errors[off][0]}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--tol", type=float, default=1e-6)
    parser.add_argument("--hybrid", type=float, default=None, metavar="H")
    parser.add_argument("--resolution", type=float, default=None, metavar="D", help="m (default: tol)")
    parser.add_argument("--out", default="benchmark")
    args = parser.parse_args(argv)
    rows = [measure(a, args.tol, args.hybrid, args.resolution) for a in ALPHAS["quick" if args.quick else "full"]]
    run_name = f"tol = {args.tol:g}" if args.hybrid is None else f"hybrid h = {args.hybrid:g}"
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_csv(out / "rocking.csv", {c: [r[c] for r in rows] for c in COLUMNS}, COLUMNS)
    print(f"resolution {rows[0]['resolution']:g} m\n")
    print(f"| α | reference impacts (last, s) | {run_name} impacts (last, s) | evaluations | unresolved | "
          f"ratio error, every impact | first impact off by > {RATIO_TOL:g} (its |θ̇|) |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        off = "none" if r["first_off"] < 0 else f"#{r['first_off']} ({r['first_off_rate']:.1e} rad/s)"
        print(f"| {r['alpha_deg']:g}° | {r['reference_impacts']} ({r['reference_last_s']:.4f}) | {r['impacts']} "
              f"({r['last_s']:.4f}) | {r['evaluations']} | {r['unresolved_impacts']} | ≤ {r['ratio_error_max']:.1e} "
              f"| {off} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
