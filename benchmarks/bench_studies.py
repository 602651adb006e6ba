"""Studies of any scene: a map's cost per point, and the fit's coverage on synthetic data.

    PYTHONPATH=src python benchmarks/bench_studies.py [--quick] [--jobs 2] [--repeats 100] [--skip-map]
                                                      [--skip-fit] [--skip-posterior] [--out FILE.json]

1. Maps: the ladder (examples/scenes/ladder.toml) over (floor μs, wall μs), N × N points
   (N = 100: 10⁴ runs; --quick: N = 20), with `jobs` workers: wall time, points/s and points/s
   per core (compute time only, the compile cache warm).
2. Fits: the paper's rod (examples/scenes/paper_rod.toml) at (μs, μd) = (0.28, 0.20): ball A's
   slip onset and ball B's impact time from the event-driven reference, plus Gaussian noise of
   the stated sigma (2 ms and 1 ms), fitted from (0.275, 0.15) `repeats` times (--quick: 20):
   the fraction of repeats whose estimate lies within 1 and 2 standard uncertainties of the
   truth, for each key, against 68.3 % and 95.4 % (the rate a linear model predicts).
3. Posterior (MCMC, emcee): the bouncing ball's restitution e from its two impact times (the
   second measured 1.5 ms late, σ = 2 ms). t2 = t1 (1 + 2e) is linear in e, so the posterior
   (flat prior) is the Gaussian of mean (t2/t1 − 1)/2 and sd σ/(2 t1): the chain's mean and sd
   against it, its acceptance and autocorrelation, runs per second (16 walkers × 600 steps;
   --quick: 6 × 40).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from nonsmooth_rod.scenefile import parse_scene, simulate_scene  # noqa: E402
from nonsmooth_rod.studies.fitting import fit  # noqa: E402
from nonsmooth_rod.studies.maps import scene_data, sweep  # noqa: E402
from nonsmooth_rod.studies.measurements import Measurements  # noqa: E402
from nonsmooth_rod.studies.outcome import contact_events  # noqa: E402

SCENES = ROOT / "examples" / "scenes"
ROD = SCENES / "paper_rod.toml"
TRUTH = {"contacts.A.law.mu_s": 0.28, "contacts.A.law.mu_d": 0.20}
SIGMA = {"slip": 2e-3, "impact": 1e-3}
START = ["contacts.A.law.mu_s=0.275", "contacts.A.law.mu_d=0.15"]
REFERENCE = ["simulation.method=event-driven", "simulation.event-driven.rtol=1e-9",
             "simulation.event-driven.atol=1e-9"]


def rod_event_times(mu_s: float, mu_d: float) -> dict:
    """Ball A's first slip and ball B's impact from the event-driven reference."""
    data, source = scene_data(ROD, REFERENCE + [f"contacts.A.law.mu_s={mu_s}", f"contacts.A.law.mu_d={mu_d}"])
    result = simulate_scene(parse_scene(data, source))
    first = {}
    for kind, contact, t in contact_events(result):
        first.setdefault((kind, contact), t)
    return {"slip": first[("slip", "A")], "impact": first[("impact", "B")]}


def noisy_events(exact: dict, rng) -> Measurements:
    return Measurements(events=[
        {"kind": "slip", "contact": "A", "t": exact["slip"] + rng.normal(0, SIGMA["slip"]), "sigma": SIGMA["slip"]},
        {"kind": "impact", "contact": "B", "t": exact["impact"] + rng.normal(0, SIGMA["impact"]),
         "sigma": SIGMA["impact"]}])


def coverage(repeats: int, seed: int = 2024) -> dict:
    """Fit `repeats` noisy copies of the rod's events; how often the truth lies within k σ."""
    exact = rod_event_times(*TRUTH.values())
    rng = np.random.default_rng(seed)
    z = {p: [] for p in TRUTH}
    started = time.perf_counter()
    for _ in range(repeats):
        r = fit(ROD, noisy_events(exact, rng), list(TRUTH), sets=REFERENCE[1:] + START, method="event-driven")
        for k, p in enumerate(r.paths):
            z[p].append((r.estimate[k] - TRUTH[p]) / r.uncertainty[k])
    seconds = time.perf_counter() - started
    out = {"repeats": repeats, "seconds_per_fit": seconds / repeats, "exact_times_s": exact}
    for p, values in z.items():
        a = np.abs(np.array(values))
        out[p] = {"within_1_sigma": int(np.sum(a <= 1)), "within_2_sigma": int(np.sum(a <= 2)),
                  "max_abs_z": float(a.max())}
    return out


BALL = SCENES / "bouncing_ball.toml"
BALL_SETS = ["simulation.t_end=0.95", "simulation.event-driven.rtol=1e-8", "simulation.event-driven.atol=1e-8"]
BALL_SIGMA, BALL_LATE = 2e-3, 1.5e-3


def restitution_posterior(walkers: int, steps: int, seed: int = 1) -> dict:
    """The ball's e by MCMC from its impact times, against the closed-form Gaussian posterior."""
    t1 = math.sqrt(2 * 1.0 / 9.81)  # dropped from 1 m (examples/scenes/bouncing_ball.toml)
    t2 = t1 * (1 + 2 * 0.5) + BALL_LATE
    measured = Measurements(events=[{"kind": "impact", "contact": "floor", "t": t1, "sigma": BALL_SIGMA},
                                    {"kind": "impact", "contact": "floor", "t": t2, "sigma": BALL_SIGMA}])
    started = time.perf_counter()
    r = fit(BALL, measured, ["contacts.floor.law.restitution"], sets=BALL_SETS, method="event-driven",
            posterior=True, walkers=walkers, posterior_steps=steps, seed=seed)
    seconds = time.perf_counter() - started
    post = r.posterior
    return {"walkers": walkers, "steps": steps, "seconds": seconds, "runs_per_s": post.evaluations / seconds,
            "closed_form_mean": (t2 / t1 - 1) / 2, "closed_form_sd": BALL_SIGMA / (2 * t1),
            "estimate": float(r.estimate[0]), "jacobian_sd": float(r.uncertainty[0]),
            "posterior_mean": float(post.mean[0]), "posterior_sd": float(post.sd[0]), "acceptance": post.acceptance,
            "autocorrelation_steps": float(post.autocorrelation[0]), "samples": int(post.samples.shape[0])}


def map_rate(n: int, jobs: int) -> dict:
    """The ladder's n × n map: wall time and points/s (per core)."""
    with tempfile.TemporaryDirectory() as tmp:
        started = time.perf_counter()
        r = sweep(SCENES / "ladder.toml", [f"contacts.foot.law.mu_s=0.1:0.5:{n}", f"contacts.top.law.mu_s=0:0.4:{n}"],
                  tmp, sets=["contacts.*.law.mu_d=0"], jobs=jobs, plot=False)
        wall = time.perf_counter() - started
    rate = r.computed / r.compute_s
    return {"points": r.computed, "jobs": jobs, "wall_s": wall, "compute_s": r.compute_s, "points_per_s": rate,
            "points_per_s_per_core": rate / jobs, "regimes": r.regimes}


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a 20 × 20 map and 20 fits")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=None, help="fits (default 100, --quick 20)")
    ap.add_argument("--skip-map", action="store_true")
    ap.add_argument("--skip-fit", action="store_true")
    ap.add_argument("--skip-posterior", action="store_true")
    ap.add_argument("--out", default=None, help="write the report as JSON")
    args = ap.parse_args(argv)
    repeats = args.repeats or (20 if args.quick else 100)
    report = {"load_average": os.getloadavg()}
    if not args.skip_map:
        report["map"] = map_rate(20 if args.quick else 100, args.jobs)
        m = report["map"]
        print(f"map of the ladder: {m['points']} points, {m['wall_s']:.2f} s wall, {m['points_per_s']:,.0f} points/s "
              f"on {m['jobs']} workers ({m['points_per_s_per_core']:,.0f} per core)")
    if not args.skip_fit:
        report["fit"] = c = coverage(repeats)
        print(f"fit of the rod: {repeats} repeats, {c['seconds_per_fit']:.2f} s per fit")
        for p in TRUTH:
            print(f"  {p}: within 1σ {c[p]['within_1_sigma']}/{repeats} (68.3 % expected), within 2σ "
                  f"{c[p]['within_2_sigma']}/{repeats} (95.4 %)")
    if not args.skip_posterior:
        report["posterior"] = m = restitution_posterior(*((6, 40) if args.quick else (16, 600)))
        print(f"posterior of the ball's e: {m['walkers']} walkers × {m['steps']} steps, {m['seconds']:.1f} s "
              f"({m['runs_per_s']:.0f} runs/s), acceptance {m['acceptance']:.2f}, autocorrelation "
              f"{m['autocorrelation_steps']:.3g} steps\n  mean {m['posterior_mean']:.5f} "
              f"sd {m['posterior_sd']:.5f} (closed form {m['closed_form_mean']:.5f}, {m['closed_form_sd']:.5f}; "
              f"Jacobian sd {m['jacobian_sd']:.5f})")
    if args.out:
        Path(args.out).write_text(json.dumps(report, indent=1, default=str))
    return report


if __name__ == "__main__":
    main()
