"""CPU time of the event-driven reference on a block resting on a floor, against Moreau–Jean.

    python benchmarks/bench_event_driven_rest.py [--t-end 100] [--repeats 3] [--quick]

A 0.2 m × 0.1 m block (two corners, PointOnLine, μs = 0.5, μd = 0.4, e = 0) rests on the floor
from t = 0. Event-driven (default options, samples every 1 ms) runs to t_end; Moreau–Jean at
h = 1e-3 (MoreauJean(MoreauJeanOptions(h=1e-3)).run) covers the same scene and span. The target
(issue 17): event-driven ≤ 100 × Moreau–Jean. A second row holds the block under a constant
applied force given as a function of time, which the integrator cannot assume constant: it
integrates, with steps that grow freely. Medians of the repeats; in the same run the yardstick
(one 3×3 numpy.linalg.solve in a Python loop).
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from nonsmooth_rod.integrators.event_driven import EventDriven, EventDrivenOptions
from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import Line, PointOnLine
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.model.scene import Scene

sys.path.insert(0, str(Path(__file__).resolve().parent))
from yardstick import yardstick_us  # noqa: E402

WIDTH, HEIGHT, MASS = 0.2, 0.1, 1.0


def resting_block(applied_force=None) -> tuple[Scene, np.ndarray, np.ndarray]:
    body = RigidBody(MASS, MASS * (WIDTH**2 + HEIGHT**2) / 12.0, name="block")
    law = ContactLaw.of(0.5, 0.4, 0.0)
    corners = [PointOnLine(0, (-WIDTH / 2, -HEIGHT / 2), Line(), law, name="left"),
               PointOnLine(0, (WIDTH / 2, -HEIGHT / 2), Line(), law, name="right")]
    scene = Scene([body], corners, applied_force=applied_force)
    return scene, np.array([0.0, HEIGHT / 2, 0.0]), np.zeros(3)


def sideways_push(t, q, v):
    """0.1 N along +x at the floor line: well inside the friction cone, constant in fact."""
    return np.array([0.1, 0.0, 0.1 * HEIGHT / 2])


def cpu_seconds(integrator, scene, q0, v0, t_end, repeats) -> tuple[float, object]:
    times, result = [], None
    for _ in range(repeats):
        t0 = time.process_time()
        result = integrator.run(scene, q0, v0, t_end)
        times.append(time.process_time() - t0)
    return statistics.median(times), result


def measure(t_end: float, repeats: int) -> list[dict]:
    rows = []
    for label, force in (("at rest", None), ("applied force", sideways_push)):
        scene, q0, v0 = resting_block(force)
        mj = MoreauJean(MoreauJeanOptions(h=1e-3))
        mj.run(scene, q0, v0, min(t_end, 0.01))  # warm-up (JIT compilation)
        mj_s, mj_res = cpu_seconds(mj, scene, q0, v0, t_end, repeats)
        ed_s, ed_res = cpu_seconds(EventDriven(EventDrivenOptions()), scene, q0, v0, t_end, repeats)
        drift = float(np.max(np.abs(ed_res.trajectory.q - q0)))
        rows.append({"scene": label, "ed_s": ed_s, "mj_s": mj_s, "ratio": ed_s / mj_s, "ed_steps": ed_res.steps,
                     "mj_steps": mj_res.steps, "ed_status": ed_res.status, "mj_status": mj_res.status,
                     "ed_drift_m": drift, "samples": len(ed_res.trajectory.t)})
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=100.0)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="t_end = 0.1 s, one repeat")
    args = parser.parse_args(argv)
    t_end, repeats = (0.1, 1) if args.quick else (args.t_end, args.repeats)
    ys = yardstick_us(n=2000 if args.quick else 20000, repeats=repeats)
    print(f"yardstick: 3x3 numpy.linalg.solve in a Python loop: {ys:.2f} us")
    print(f"block resting on a floor for {t_end:g} s; CPU seconds, median of {repeats}:")
    print(f"{'scene':<15}{'event-driven':>13}{'ED steps':>10}{'MJ h=1e-3':>11}{'ED/MJ':>8}{'ED drift m':>12}")
    rows = measure(t_end, repeats)
    for r in rows:
        print(f"{r['scene']:<15}{r['ed_s']:>13.4f}{r['ed_steps']:>10d}{r['mj_s']:>11.4f}{r['ratio']:>8.2f}"
              f"{r['ed_drift_m']:>12.2e}")
    worst = max(r["ratio"] for r in rows)
    print(f"target: event-driven <= 100 x Moreau-Jean: {'met' if worst <= 100 else 'NOT met'} (worst {worst:.2f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
