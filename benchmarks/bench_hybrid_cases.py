"""The hybrid method (integrators/hybrid.py) and error-controlled Moreau–Jean (integrators/
adaptive.py, `tol=`) on 25 rods with (μs, μd) drawn over 0.05–0.6 (μd ≤ μs, seed 0), against the
event-driven reference at rtol 1e-12: the phase sequence of ball A, the largest phase boundary
error and ball B's impact error, the work and the cost, for each h (hybrid) and each tol.

    python benchmarks/bench_hybrid_cases.py [--h 1e-2 5e-2] [--tol 1e-5 1e-6] [--fixed-h 1e-3]
                                            [--cases 0 1 ...] [--window H] [--positions] [--quick] [--out DIR]

Prints a markdown table (docs/error_control.md quotes it), one row per run; with --out, also
DIR/hybrid_cases.csv, one row per case and run. Work: steps (hybrid) or step evaluations (tol,
every step of every window run, taken back or not); cost: CPU time of the whole call, median over
the cases, in yardsticks measured in the same run (benchmarks/yardstick.py). --quick: cases 1, 5 and 9
(ball A's three sequences among the 25: slip−; stick, slip+; stick, slip−, slip+), hybrid h = 5e-2
and tol = 1e-6 (a test runs it). --window: the tol runs' first and largest window (default 1e-2 s).
--positions: for each tol run and case, also the largest |q − q_ref| (x_O, y_O, θ together) over
0–0.1, 0.1–0.2, 0.2–0.3 s and 0.3 s to ball B's impact, at the run's accepted times, against the
reference's samples every 1e-4 s (cubic Hermite in q, v). --fixed-h: Moreau–Jean at these fixed
steps (its stick decisions by the smooth phase, integrators/stick_decisions.py). Exits 1 if a
phase sequence is wrong, or if a tol run has a boundary or the impact off by more than 10 tol.
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicHermiteSpline

sys.path.insert(0, str(Path(__file__).resolve().parent))

from yardstick import yardstick_us  # noqa: E402

from nonsmooth_rod.io import write_csv  # noqa: E402
from nonsmooth_rod.rod.problem import RodProblem  # noqa: E402
from nonsmooth_rod.rod.simulation import simulate  # noqa: E402

N_CASES = 25
QUICK_CASES = (1, 5, 9)
TOL_BOUND = 10  # a tol run must have every boundary and the impact within TOL_BOUND · tol (issue 28: 1e-5 at 1e-6)
SPANS = ((0.0, 0.1), (0.1, 0.2), (0.2, 0.3), (0.3, math.inf))  # s: ball A sticks until 0.30 s in case 0
COLUMNS = ("run", "value", "case", "mu_s", "mu_d", "phases", "reference_phases", "ok", "boundary_error_s",
           "impact_error_s", "work", "cpu_s")


def cases(seed: int = 0) -> list[tuple[float, float]]:
    rng = np.random.default_rng(seed)
    pairs = rng.uniform(0.05, 0.6, size=(N_CASES, 2))
    return [(float(max(a, b)), float(min(a, b))) for a, b in pairs]


def position_errors(run, reference) -> list[float]:
    """The largest |q − q_ref| in each of SPANS, at the run's samples before ball B's impact."""
    ref = reference.result.trajectory
    t_ref, first = np.unique(ref.t, return_index=True)
    exact = CubicHermiteSpline(t_ref, ref.q[first], ref.v[first], axis=0)
    t, q = run.result.trajectory.t, run.result.trajectory.q
    before = t < min(reference.impact["t"] if reference.impact else math.inf, t_ref[-1])
    error = np.max(np.abs(q[before] - exact(t[before])), axis=1)
    return [float(error[(t[before] >= a) & (t[before] < b)].max(initial=0.0)) for a, b in SPANS]


def compare(mu_s: float, mu_d: float, reference, run_name: str, value: float, window: float | None = None) -> dict:
    """One run ("hybrid" with h = value, "fixed": Moreau–Jean with h = value, or "tol": Moreau–Jean
    with tol = value, largest window `window`) against the reference."""
    problem = RodProblem.paper(None, mu_s=mu_s, mu_d=mu_d)
    started = time.process_time()
    if run_name == "tol":
        run = simulate(problem, "moreau-jean", tol=value, **({"h": window} if window else {}))
    else:
        run = simulate(problem, "hybrid" if run_name == "hybrid" else "moreau-jean", h=value)
    cpu = time.process_time() - started
    got, expected = [p.mode for p in run.phases], [p.mode for p in reference.phases]
    ok = got == expected
    boundary = max(abs(a.t_end - b.t_end) for a, b in zip(run.phases, reference.phases)) if ok else np.inf
    impact = abs(run.impact["t"] - reference.impact["t"]) if run.impact and reference.impact else np.nan
    return {"run": run_name, "value": value, "mu_s": mu_s, "mu_d": mu_d, "phases": " ".join(got),
            "reference_phases": " ".join(expected), "ok": ok, "boundary_error_s": boundary, "impact_error_s": impact,
            "work": run.result.stats.get("step_evaluations", run.result.steps), "cpu_s": cpu,
            "positions": position_errors(run, reference) if run_name == "tol" else None}


def row(rows: list[dict], yardstick: float) -> str:
    r0 = rows[0]
    knob = {"hybrid": "hybrid h", "fixed": "Moreau–Jean h", "tol": "Moreau–Jean tol"}[r0["run"]] + f" = {r0['value']:g}"
    wrong = [r["case"] for r in rows if not r["ok"]]
    return (f"| {knob} | {len(rows) - len(wrong)}/{len(rows)}" + (f" (wrong: {wrong})" if wrong else "") +
            f" | {max(r['boundary_error_s'] for r in rows):.1e} | {np.nanmax([r['impact_error_s'] for r in rows]):.1e}"
            f" | {np.median([r['work'] for r in rows]):.0f} ({max(r['work'] for r in rows)})"
            f" | {np.median([r['cpu_s'] for r in rows]) * 1e6 / yardstick:.0f} |")


def positions_table(rows: list[dict], window: float) -> str:
    """The tol runs' largest position error in each span, one markdown row a run and case."""
    spans = " | ".join(f"{a:g}–{b:g} s" if b < math.inf else f"{a:g} s–impact" for a, b in SPANS)
    lines = [f"\n| run | case | {spans} | boundary (s) | impact (s) | evaluations |",
             "|---|---|" + "---|" * (len(SPANS) + 3)]
    for r in (r for r in rows if r["positions"] is not None):
        lines.append(f"| tol = {r['value']:g}, window {window:g} | {r['case']} | " +
                     " | ".join(f"{e:.1e}" for e in r["positions"]) +
                     f" | {r['boundary_error_s']:.1e} | {r['impact_error_s']:.1e} | {r['work']} |")
    return "\n".join(lines)


def missed(r: dict) -> bool:
    if not r["ok"]:
        return True
    bound = TOL_BOUND * r["value"] if r["run"] == "tol" else math.inf
    return not (r["boundary_error_s"] <= bound and r["impact_error_s"] <= bound)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--h", type=float, nargs="*", default=None, help="hybrid steps (default 1e-2 5e-2)")
    parser.add_argument("--tol", type=float, nargs="*", default=[], help="Moreau–Jean tolerances")
    parser.add_argument("--fixed-h", type=float, nargs="*", default=[], help="Moreau–Jean fixed steps")
    parser.add_argument("--cases", type=int, nargs="+", default=None, help="case indices (default all 25)")
    parser.add_argument("--window", type=float, default=None, help="tol runs' largest window (s)")
    parser.add_argument("--positions", action="store_true", help="tol runs' position errors by span")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default=None)
    args = parser.parse_args(argv)
    steps = args.h if args.h is not None else ([5e-2] if args.quick else [1e-2, 5e-2])
    tols = args.tol or ([1e-6] if args.quick else [])
    chosen = args.cases if args.cases is not None else (list(QUICK_CASES) if args.quick else list(range(N_CASES)))
    all_cases = cases()
    references = {i: simulate(RodProblem.paper(None, mu_s=all_cases[i][0], mu_d=all_cases[i][1]), "event-driven",
                              output_dt=1e-4 if args.positions else 1e-3) for i in chosen}
    if tols or args.fixed_h:
        simulate(RodProblem.paper(), "moreau-jean", tol=1e-2)  # warm: compile or load the loop once
    simulate(RodProblem.paper(), "hybrid")  # warm: its kernels and imports
    runs = [("hybrid", h) for h in steps] + [("tol", t) for t in tols] + [("fixed", h) for h in args.fixed_h]
    table = []
    for name, value in runs:
        table.append([dict(compare(*all_cases[i], references[i], name, value, args.window), case=i) for i in chosen])
    yardstick = yardstick_us()
    print(f"yardstick {yardstick:.2f} µs (the machine is shared: compare columns, not absolute times)\n\n"
          "| run | right phase sequences | largest boundary error (s) | largest impact error (s) | "
          "work: median (largest) | yardsticks (median) |\n|---|---|---|---|---|---|")
    for rows in table:
        print(row(rows, yardstick))
    flat = [r for rows in table for r in rows]
    if args.positions:
        print(positions_table(flat, args.window or 1e-2))
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        write_csv(out / "hybrid_cases.csv", {c: [r[c] for r in flat] for c in COLUMNS}, COLUMNS)
    for r in flat:
        if missed(r):
            print(f"case {r['case']} (μs {r['mu_s']:.4f}, μd {r['mu_d']:.4f}) {r['run']} {r['value']:g}: "
                  f"{r['phases']} (reference {r['reference_phases']}), boundary {r['boundary_error_s']:.2e} s, "
                  f"impact {r['impact_error_s']:.2e} s")
    return 1 if any(missed(r) for r in flat) else 0


if __name__ == "__main__":
    sys.exit(main())
