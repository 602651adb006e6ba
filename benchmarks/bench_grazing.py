"""Stick decisions near the rod's grazing T/N peak (issue 28): how far fixed-step Moreau–Jean's
T/N overshoots the exact rolling one, and which part of it a decision made on the end-of-step
state would remove; then the phases of μs = max T/N ± δ at fixed steps and with error control.

    python benchmarks/bench_grazing.py [--quick] [--out DIR]

Overshoot: the paper's rod rolling through the peak (μs = 0.6, μd = 0.2) at fixed h; per step,
the discrete ratio p_T/p_N of the step's impulses, and the smooth-phase ratio T/N that the exact
rolling equations (rod/closed_form.rolling) give at the end-of-step state (θ, θ̇). Each maximum
minus the exact peak (rod/hypotheses, rtol 1e-12), divided by h. The difference of the two is
what the step's own discretisation adds (the Jacobian of the step's start); the rest is the
error of the state itself, first order (the rolling rod loses ~5 % · h/s of its energy to the
projections of the steps), which no decision on the step's state can remove.

Phases (full run only): μs = max T/N ± δ, δ = 1e-3 … 1e-6, at h = 1e-3 (its break-aways confirmed
by the smooth phase, integrators/stick_decisions.py: docs/friction.md), with tol = 1e-4 and
1e-5, and with the hybrid method (Runge–Kutta of order 4 in each mode) at h = 1e-3 and 1e-2,
against the event-driven reference: right phase sequence, largest boundary error.
Writes DIR/grazing_overshoot.csv (and DIR/grazing_phases.csv) and prints markdown tables.
--quick: the overshoot at h = 1e-3 and 5e-4 (a test runs it).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import nonsmooth_rod as nr
from nonsmooth_rod.io import write_csv
from nonsmooth_rod.rod import closed_form
from nonsmooth_rod.rod.hypotheses import rolling_hypothesis
from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.rod.simulation import simulate as simulate_rod

STEPS = {"full": (1e-3, 5e-4, 2.5e-4), "quick": (1e-3, 5e-4)}
DELTAS = (1e-3, 1e-4, 1e-5, 1e-6, -1e-3, -1e-4, -1e-5, -1e-6)
RUNS = (("h", 1e-3), ("tol", 1e-4), ("tol", 1e-5), ("hybrid h", 1e-3), ("hybrid h", 1e-2))
ROLLING_PAST_THE_PEAK = 0.25  # s: the peak is at 0.158 s, the axis horizontal at 0.36 s


def peak() -> float:
    return rolling_hypothesis(RodProblem.paper(None, mu_s=0.3, mu_d=0.2)).T_over_N_max


def overshoot(h: float) -> dict:
    """(max discrete p_T/p_N − peak)/h and (max smooth-phase T/N of the end-of-step states − peak)/h."""
    problem = RodProblem.paper(None, mu_s=0.6, mu_d=0.2)
    q0, v0 = problem.initial_state()
    run = nr.simulate(problem.scene(), q0, v0, ROLLING_PAST_THE_PEAK, "moreau-jean", h=h)
    assert set(run.trajectory.modes[1:, 0]) == {"stick"}, "the rod must roll through the peak"
    discrete = np.asarray(run.tangential_force)[1:, 0] / np.asarray(run.normal_force)[1:, 0]
    smooth = []
    for theta, theta_dot in zip(run.q[1:, 2], run.v[1:, 2]):
        _, _, normal, tangential = closed_form.rolling(problem, theta, theta_dot)
        smooth.append(tangential / normal)
    top = peak()
    return {"h": h, "discrete_per_h": (float(np.max(discrete)) - top) / h,
            "end_state_per_h": (float(np.max(smooth)) - top) / h}


def phases(knob: str, value: float, delta: float) -> dict:
    problem = RodProblem.paper(None, mu_s=peak() + delta, mu_d=0.2)
    reference = simulate_rod(problem, "event-driven")
    method, _, name = knob.rpartition(" ")  # "hybrid h": the hybrid method's h (integrators/hybrid.py)
    run = simulate_rod(problem, method or "moreau-jean", **{name: value})
    expected, got = [p.mode for p in reference.phases], [p.mode for p in run.phases]
    error = max(abs(a.t_end - b.t_end) for a, b in zip(reference.phases, run.phases)) if got == expected else np.inf
    return {"knob": knob, "value": value, "delta": delta, "phases_ok": got == expected, "boundary_error_s": error,
            "work": run.result.stats.get("step_evaluations", run.result.steps)}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default="benchmark")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = [overshoot(h) for h in STEPS["quick" if args.quick else "full"]]
    columns = ("h", "discrete_per_h", "end_state_per_h")
    write_csv(out / "grazing_overshoot.csv", {c: [r[c] for r in rows] for c in columns}, columns)
    print(f"exact rolling peak of T/N: {peak():.12f}\n\n| h (s) | discrete p_T/p_N overshoot / h (1/s) | "
          "end-of-step state's smooth T/N overshoot / h (1/s) |\n|---|---|---|")
    for r in rows:
        print(f"| {r['h']:g} | {r['discrete_per_h']:.4f} | {r['end_state_per_h']:.4f} |")
    if args.quick:
        return 0
    table = [phases(knob, value, delta) for knob, value in RUNS for delta in DELTAS]
    columns = ("knob", "value", "delta", "phases_ok", "boundary_error_s", "work")
    write_csv(out / "grazing_phases.csv", {c: [r[c] for r in table] for c in columns}, columns)
    print("\n| run | " + " | ".join(f"δ = {d:+g}" for d in DELTAS) + " |\n|---|" + "---|" * len(DELTAS))
    for knob, value in RUNS:
        cells = [f"{r['boundary_error_s']:.1e}" if r["phases_ok"] else "wrong phases"
                 for r in table if r["knob"] == knob and r["value"] == value]
        print(f"| {knob} = {value:g} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
