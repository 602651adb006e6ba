"""Work–precision of Moreau–Jean with error control (`tol=`) against fixed steps, and of the hybrid
method (Runge–Kutta of order 4 in each smooth mode, integrators/hybrid.py) at fixed h, on the
paper's rod (case 2), measured against the event-driven reference at rtol 1e-12.

    python benchmarks/bench_error_control.py [--quick] [--out DIR]

For each run: the impact time error of ball B, max |x_O error| before the impact, the largest
phase boundary error, the work (steps; step evaluations with tol) and the CPU time of the whole
call in yardsticks (one 3×3 numpy.linalg.solve from Python, timed in this run: benchmarks/
yardstick.py), best of REPEATS (quick: one run); runs are named by method and knob (hybrid h = ...). Writes DIR/error_control.csv and DIR/error_control.png (error
against cost) and prints the table as markdown (docs/error_control.md quotes it). Full: tol
1e-3 … 1e-6 and h 1e-3 … 1e-5 (~1 minute compiled), hybrid h 0.1 … 1e-2; --quick: two of each
and hybrid h = 5e-2 (a test runs it).
Exits 1 if a tol run misses its tolerance on the impact time or on x_O.
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from yardstick import yardstick_us  # noqa: E402

from nonsmooth_rod.io import write_csv  # noqa: E402
from nonsmooth_rod.rod import study  # noqa: E402
from nonsmooth_rod.rod.simulation import simulate  # noqa: E402

FULL = {"tol": (1e-3, 1e-4, 1e-5, 1e-6), "h": (1e-3, 1e-4, 3e-5, 1e-5), "hybrid h": (1e-1, 5e-2, 2e-2, 1e-2)}
QUICK = {"tol": (1e-3, 1e-4), "h": (1e-3, 1e-4), "hybrid h": (5e-2,)}
KNOBS = ("h", "tol", "hybrid h")
REPEATS = 3
COLUMNS = ("knob", "value", "impact_error_s", "x_O_error_m", "boundary_error_s", "phases_ok", "work", "cpu_s",
           "yardsticks", "error_estimate", "impact_error_estimate_s")


def measure(reference, knob: str, value: float, repeats: int = REPEATS) -> dict:
    best = math.inf
    for _ in range(repeats):  # the whole call, best of REPEATS (the machine is shared)
        started = time.process_time()
        method, _, name = knob.rpartition(" ")  # "hybrid h": the hybrid method's h
        run = simulate(reference.problem, method or "moreau-jean", **{name: value})
        best = min(best, time.process_time() - started)
    m = study.measure(run, reference)
    stats = run.result.stats
    impact = next((e for e in run.result.events if e.kind == "impact" and e.contact == "B"), None)
    return {"knob": knob, "value": value, "impact_error_s": m["impact_error_s"], "x_O_error_m": m["x_O_error_m"],
            "boundary_error_s": m["phase_boundary_error_s"], "phases_ok": m["phase_sequence_ok"],
            "work": stats.get("step_evaluations", run.result.steps), "cpu_s": best,
            "error_estimate": stats.get("error_estimate", math.nan),
            "impact_error_estimate_s": impact.detail.get("error", math.nan) if impact else math.nan}


def markdown(rows: list[dict], yardstick: float) -> str:
    lines = [f"yardstick {yardstick:.2f} µs", "",
             "| run | impact error (s) | x_O error (m) | boundary error (s) | work | yardsticks | estimate (m) |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['knob']} = {r['value']:g} | {r['impact_error_s']:.2e} | {r['x_O_error_m']:.2e} | "
                     f"{r['boundary_error_s']:.2e} | {r['work']} | {r['yardsticks']:.0f} | "
                     f"{r['error_estimate']:.2e} |")
    return "\n".join(lines)


def plot(rows: list[dict], path: Path) -> None:
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, column, label in zip(axes, ("impact_error_s", "x_O_error_m"),
                                 ("impact time error of ball B (s)", "max |x_O error| before it (m)")):
        for knob, style, name in (("h", "o-", "Moreau–Jean, fixed h"), ("tol", "s-", "Moreau–Jean, tol"),
                                  ("hybrid h", "^-", "hybrid (RK4 between events), h")):
            sel = [r for r in rows if r["knob"] == knob]
            ax.loglog([r["yardsticks"] for r in sel], [r[column] for r in sel], style, label=name)
        ax.set_xlabel("cost of the whole call (yardsticks)")
        ax.set_ylabel(label)
        ax.legend()
    fig.suptitle("The rod, case 2, against the event-driven reference")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default="benchmark")
    args = parser.parse_args(argv)
    grid = QUICK if args.quick else FULL
    reference = study.reference(2)
    simulate(reference.problem, "moreau-jean", tol=1e-2)  # warm: compile or load the loop once
    simulate(reference.problem, "hybrid")  # warm: its imports
    rows = [measure(reference, knob, value, 1 if args.quick else REPEATS) for knob in KNOBS
            for value in grid[knob]]
    yardstick = yardstick_us()
    for r in rows:
        r["yardsticks"] = r["cpu_s"] * 1e6 / yardstick
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_csv(out / "error_control.csv", {c: [r[c] for r in rows] for c in COLUMNS}, COLUMNS)
    plot(rows, out / "error_control.png")
    print(markdown(rows, yardstick))
    missed = [r for r in rows if r["knob"] == "tol" and not (r["impact_error_s"] <= r["value"]
                                                              and r["x_O_error_m"] <= r["value"])]
    for r in missed:
        print(f"tol = {r['value']:g} missed: impact error {r['impact_error_s']:.2e} s, x_O {r['x_O_error_m']:.2e} m")
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
