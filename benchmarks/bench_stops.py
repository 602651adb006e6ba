"""What a stop early in a run costs, for every method: CPU of a run whose stop condition holds at
5 % of t_end over the CPU of the whole run (issue 22: at most 10 %).

    python benchmarks/bench_stops.py [--quick] [--repeat 5]

The scene: a ball falling from rest towards a floor it does not reach within t_end (its contact
watched all the way: gaps, indicators, penalty forces). The stop: y below y0 − g (0.05 t_end)²/2,
which the exact fall reaches at 5 % of t_end. Each method keeps and stops while it runs
(integrators/sampling.py), so the stopped run should cost ~5 % plus its fixed start. CPU time
(process time) around nr.simulate, median of the repeats; the stopped run's time is checked
against the closed form (its first kept sample at or past sqrt(2Δh/g)). Exits 1 if a ratio is
above 10 %.
"""
from __future__ import annotations

import argparse
import math
import statistics
import sys
import time

import nonsmooth_rod as nr
from nonsmooth_rod import _jit

G = 9.81
T_END = 2.0
HEIGHT = 100.0  # the ball falls 19.6 m in T_END: the floor is never reached
STOP_FRACTION = 0.05
STOP_TIME = STOP_FRACTION * T_END + 3.7e-5  # off every method's sample grid: no tie with round-off
LIMIT = 0.10


def scene() -> nr.Scene:
    ball = nr.RigidBody(1.0, 0.004, name="ball")
    floor = nr.DiskOnLine(0, (0.0, 0.0), nr.Line(), 0.1, nr.ContactLaw.of(0.5, 0.5), name="floor")
    return nr.Scene([ball], [floor], gravity=G)


def cases(quick: bool) -> dict:
    """Each method's options: about the same sample count, enough work that the fixed start of a
    run is small beside it (Moreau–Jean interpreted, without numba, takes fewer steps)."""
    finer = 1.0 if quick else 0.1
    return {"moreau-jean": {"h": (1e-5 if _jit.ENABLED else 2e-4) * finer}, "event-driven": {"output_dt": 1e-4 * finer},
            "hybrid": {"h": 1e-3 * finer}, "regularized": {"output_dt": 2e-4 * finer}}


def drop_in(t: float) -> float:
    """The fall (m) the exact motion makes in t."""
    return 0.5 * G * t**2


def run(method: str, options: dict, stop: bool):
    dh = drop_in(STOP_TIME)
    condition = (lambda t, q, v: q[1] < HEIGHT - dh) if stop else None
    started = time.process_time()
    result = nr.simulate(scene(), [0.0, HEIGHT, 0.0], [0.0, 0.0, 0.0], T_END, method=method, stop=condition,
                         **options)
    return time.process_time() - started, result


def measure(method: str, options: dict, repeat: int) -> dict:
    run(method, options, True)  # warm: imports, a compiled loop's cache
    full = []
    for _ in range(repeat):
        cpu, whole = run(method, options, False)
        full.append(cpu)
    stopped = []
    for _ in range(repeat):
        cpu, result = run(method, options, True)
        stopped.append(cpu)
    t_star = math.sqrt(2.0 * drop_in(STOP_TIME) / G)
    return {"method": method, "options": options, "full_s": statistics.median(full),
            "stopped_s": statistics.median(stopped), "status": str(result.status), "t_stop": float(result.t[-1]),
            "t_star": t_star, "samples": len(result.t), "reached_full": reached(whole, options), "reached_stopped": reached(result, options)}


def reached(result, options: dict) -> float:
    """The time a run integrated to (the ODE methods' t_final; Moreau–Jean's steps of h from 0),
    whatever samples it kept: a stop that only trimmed the result would reach t_end."""
    return float(result.stats["t_final"]) if "t_final" in result.stats else result.steps * options["h"]


def table(rows: list) -> str:
    lines = ["| method | options | full run CPU (s) | stop at 5 % CPU (s) | ratio | stop time − sqrt(2Δh/g) (s) |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        options = ", ".join(f"{k} = {v:g}" for k, v in r["options"].items())
        lines.append(f"| {r['method']} | {options} | {r['full_s']:.3f} | {r['stopped_s']:.4f} | "
                     f"{r['stopped_s'] / r['full_s']:.3f} | {r['t_stop'] - r['t_star']:.2e} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="runs of 2000–20 000 samples (a test runs this)")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    rows = [measure(method, options, args.repeat) for method, options in cases(args.quick).items()]
    print(f"numba {'on' if _jit.ENABLED else 'off'}; CPU time, median of {args.repeat}")
    print(table(rows))
    worst = max(r["stopped_s"] / r["full_s"] for r in rows)
    return 0 if worst <= LIMIT and all(r["status"] == "stopped" for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
