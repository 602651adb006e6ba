"""The hybrid method (integrators/hybrid.py) on 25 rods with (μs, μd) drawn over 0.05–0.6 (μd ≤ μs,
seed 0), against the event-driven reference at rtol 1e-12: the phase sequence of ball A, the
largest phase boundary error and ball B's impact error, at each h.

    python benchmarks/bench_hybrid_cases.py [--h 1e-2 5e-2]

Prints a markdown table (docs/error_control.md quotes it); exits 1 if a phase sequence is wrong.
"""
from __future__ import annotations

import argparse
import sys

import numpy as np

from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.rod.simulation import simulate

N_CASES = 25


def cases(seed: int = 0) -> list[tuple[float, float]]:
    rng = np.random.default_rng(seed)
    pairs = rng.uniform(0.05, 0.6, size=(N_CASES, 2))
    return [(float(max(a, b)), float(min(a, b))) for a, b in pairs]


def compare(mu_s: float, mu_d: float, reference, h: float) -> dict:
    run = simulate(RodProblem.paper(None, mu_s=mu_s, mu_d=mu_d), "hybrid", h=h)
    ok = [p.mode for p in run.phases] == [p.mode for p in reference.phases]
    boundary = max(abs(a.t_end - b.t_end) for a, b in zip(run.phases, reference.phases)) if ok else np.inf
    impact = abs(run.impact["t"] - reference.impact["t"]) if run.impact and reference.impact else np.nan
    return {"ok": ok, "boundary": boundary, "impact": impact, "steps": run.result.steps}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--h", type=float, nargs="+", default=[1e-2, 5e-2])
    args = parser.parse_args(argv)
    references = {c: simulate(RodProblem.paper(None, mu_s=c[0], mu_d=c[1]), "event-driven") for c in cases()}
    print("| h (s) | right phase sequences | largest boundary error (s) | largest impact error (s) | steps (median) |\n"
          "|---|---|---|---|---|")
    wrong = 0
    for h in args.h:
        rows = [compare(*c, ref, h) for c, ref in references.items()]
        wrong += sum(not r["ok"] for r in rows)
        print(f"| {h:g} | {sum(r['ok'] for r in rows)}/{len(rows)} | {max(r['boundary'] for r in rows):.1e} | "
              f"{np.nanmax([r['impact'] for r in rows]):.1e} | {np.median([r['steps'] for r in rows]):.0f} |")
    return 1 if wrong else 0


if __name__ == "__main__":
    sys.exit(main())
