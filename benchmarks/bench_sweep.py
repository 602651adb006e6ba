"""Regime-map sweeps: cost per point, simulate()'s fixed cost, and the 100 × 100 map's wall time.

    PYTHONPATH=src python benchmarks/bench_sweep.py [--quick] [--jobs 2] [--out FILE.json]

1. The yardstick: one 3×3 numpy.linalg.solve in a Python loop (µs), timed in the same run.
2. Cost per point in one process (classify_point: problem, simulation, scenario, row), CPU ms,
   for Moreau–Jean (lemke, compiled) at h = 1e-3 and 2e-3 and for the event-driven reference.
3. A whole rod simulate() against its integrator's own CPU time at h = 1e-2, 1e-3, 1e-4
   (issue 16 asks ≤ 1.5 at h = 1e-3): the rolling hypothesis is no longer computed per call.
4. The CLI map `nonsmooth-rod sweep --mu-s 0.1:0.5:N --mu-d-ratio 0.5:1.0:N` (N = 100: 10⁴ full
   motions; --quick: N = 20) in a fresh process and folder: wall time, the CPU seconds of the
   process and its workers, and the accuracy check it reports (sweep.json).

The machine is shared: the load average is printed with the numbers; on a loaded machine the
CPU seconds divided by the cores is the better estimate of the idle wall time.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from nonsmooth_rod.rod.problem import RodProblem  # noqa: E402
from nonsmooth_rod.rod.regime import (  # noqa: E402
    REFERENCE,
    SweepSettings,
    classify_point,
    warm_engine,
)
from nonsmooth_rod.rod.simulation import simulate  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))  # benchmarks/ for the yardstick
from yardstick import yardstick_us  # noqa: E402  (benchmarks/yardstick.py)


def per_point_ms(settings: SweepSettings, n: int, repeats: int = 3) -> float:
    base = RodProblem.paper()
    warm_engine(settings)
    mu = np.linspace(0.1, 0.5, n)
    points = [{"mu_s": m, "mu_d": 0.75 * m, "theta0_deg": 60.0} for m in mu]
    times = []
    for _ in range(repeats):
        t0 = time.process_time()
        for pt in points:
            classify_point(base, pt, settings)
        times.append((time.process_time() - t0) / n * 1e3)
    return statistics.median(times)


def whole_vs_integrator(h: float, repeats: int) -> tuple[float, float]:
    """(whole simulate() CPU ms, integrator CPU ms), medians."""
    problem = RodProblem.paper()
    simulate(problem, "moreau-jean", h=h)
    whole, inner = [], []
    for _ in range(repeats):
        t0 = time.process_time()
        run = simulate(problem, "moreau-jean", h=h)
        whole.append((time.process_time() - t0) * 1e3)
        inner.append(run.result.cpu_time_s * 1e3)
    return statistics.median(whole), statistics.median(inner)


def cli_map(n: int, jobs: int, plot: bool) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "map"
        argv = [sys.executable, "-m", "nonsmooth_rod.cli", "sweep", "--mu-s", f"0.1:0.5:{n}", "--mu-d-ratio",
                f"0.5:1.0:{n}", "--jobs", str(jobs), "--out", str(out), "--quiet"] + ([] if plot else ["--no-plot"])
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        import nonsmooth_rod  # the copy this process imports: another would compile the engine again

        package_root = str(Path(nonsmooth_rod.__file__).resolve().parents[1])
        proc = subprocess.run(argv, env=os.environ | {"PYTHONPATH": package_root}, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if proc.returncode != 0:
            raise SystemExit(f"sweep failed ({proc.returncode}): {proc.stderr[-2000:]}")
        record = json.loads((out / "sweep.json").read_text())
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"points": record["counts"]["points"], "wall_s": wall, "cpu_s": cpu,
            "compute_wall_s": record["counts"]["compute_wall_s"], "accuracy": record["accuracy"], "plot": plot}


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sizes (a test runs this)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", default=None, help="write the numbers as JSON here")
    ap.add_argument("--skip-map", action="store_true", help="leave out the CLI map (a fresh process)")
    args = ap.parse_args(argv)
    n_pts, reps, n_map = (20, 3, 10) if args.quick else (200, 15, 100)
    report = {"load_average": os.getloadavg(), "cores": os.cpu_count(), "yardstick_us": yardstick_us()}
    y = report["yardstick_us"]
    print(f"load average {report['load_average'][0]:.2f} on {report['cores']} cores; "
          f"yardstick (3×3 solve) {y:.2f} µs")
    report["per_point_ms"] = {}
    for label, settings, n in (("moreau-jean h=1e-3", SweepSettings(h=1e-3), n_pts),
                               ("moreau-jean h=2e-3", SweepSettings(h=2e-3), n_pts),
                               ("event-driven", REFERENCE, max(4, n_pts // 10))):
        ms = per_point_ms(settings, n)
        report["per_point_ms"][label] = ms
        print(f"per point, {label:20s} {ms:7.3f} ms CPU  = {ms * 1e3 / y:9.0f} yardsticks  "
              f"({1e3 / ms:6.0f} points/s/core)")
    report["simulate_ratio"] = {}
    for h in (1e-2, 1e-3, 1e-4):
        whole, inner = whole_vs_integrator(h, reps if h > 1e-4 else max(3, reps // 3))
        report["simulate_ratio"][f"{h:g}"] = {"whole_ms": whole, "integrator_ms": inner, "ratio": whole / inner}
        print(f"simulate() at h = {h:g}: whole {whole:.3f} ms, integrator {inner:.3f} ms, ratio {whole / inner:.2f}")
    report["map"] = []
    for plot in () if args.skip_map else (False, True):
        res = cli_map(n_map, args.jobs, plot)
        report["map"].append(res)
        acc = res["accuracy"]
        print(f"CLI map {res['points']} points, {args.jobs} jobs, plot={plot}: wall {res['wall_s']:.2f} s "
              f"(points {res['compute_wall_s']:.2f} s, {res['points'] / res['compute_wall_s']:.0f} points/s), "
              f"CPU {res['cpu_s']:.2f} s; accuracy: scenario {acc.get('scenario_agree')}/{acc.get('checked')}, "
              f"|Δt| ≤ {max(acc.get('max_abs_error_t_transition_s', 0), acc.get('max_abs_error_t_impact_s', 0)):.2g}"
              " s "
              f"(tolerance {acc.get('time_tolerance_s')} s)")
    if args.out:
        Path(args.out).write_text(json.dumps(report, indent=2, default=float) + "\n")
    return report


if __name__ == "__main__":
    main()
