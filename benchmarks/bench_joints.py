"""The drift of joints over a long run (docs/joints.md, "Drift"): a double pendulum for 10⁶ steps;
and the pendulum striking a wall's rebound angle against its closed form at fine steps.

    python benchmarks/bench_joints.py [--steps 1000000] [--h 1e-4] [--quick]

Two uniform rods (1 m, 1 kg), the first pinned to the world at its end, the second pinned to the
first's free end, released both horizontal (chaotic from there): after each Moreau–Jean step the
positions are projected back onto the joints, so their violation stays at round-off of the
coordinates however long the run. Reports the largest violation |C(q)| over the kept samples
(one per --save-every seconds, and the last state), the energy lost (first order in h: the
scheme's dissipation) and the cost per step. Exits 1 if the violation exceeds DRIFT_LIMIT.

Then examples/scenes/pendulum_wall.toml (a rod pinned at its end, released horizontal, striking a
wall at the bottom with e = 0.5) at h = 1e-5 and 2e-6: the highest angle after the impact against
acos(1 − e²) (ω⁺ = −e ω⁻ and energy; first order in h). Exits 1 if at the finest step it is not
within REBOUND_LIMIT relative (the issue's 1e-6).
--quick: 10⁴ steps, and the rebound at h = 1e-4 only (a test runs it).
"""
from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

import nonsmooth_rod as nr
from nonsmooth_rod.model.joints import joint_violation

DRIFT_LIMIT = 1e-9  # m: the bound after 10⁶ steps
REBOUND_LIMIT = 1e-6  # relative, at the finest step
PENDULUM = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "pendulum_wall.toml"


def double_pendulum():
    """The scene and its start: both rods horizontal, at rest."""
    rods = [nr.RigidBody(1.0, 1.0 / 12, name=f"rod{i}") for i in (1, 2)]
    joints = [nr.Pin(0, (-0.5, 0.0), None, (0.0, 0.0), name="shoulder"),
              nr.Pin(1, (-0.5, 0.0), 0, (0.5, 0.0), name="elbow")]
    return nr.Scene(rods, gravity=9.81, joints=joints), np.array([0.5, 0.0, 0.0, 1.5, 0.0, 0.0])


def rebound_error(h: float) -> tuple[float, float]:
    """(the rebound's highest angle from the vertical, its error relative to acos(1 − e²)) at step h."""
    res = nr.simulate_scene(nr.load_scene(PENDULUM, [f"simulation.h={h}"]))
    k = int(np.searchsorted(res.t, res.impacts[0].t))
    angle = float(np.max(res.q[k:, 2]) + math.pi / 2)
    exact = math.acos(1.0 - 0.5 ** 2)
    return angle, angle / exact - 1.0


def rebound_rows(steps) -> float:
    """Prints the rebound angle at each step size; returns the error at the last (finest)."""
    error = math.nan
    for h in steps:
        started = time.process_time()
        angle, error = rebound_error(h)
        print(f"pendulum striking the wall, h = {h:g}: rebound {angle:.12f} rad, relative error {error:+.3e} "
              f"({time.process_time() - started:.1f} s CPU)")
    return error


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=1_000_000)
    parser.add_argument("--h", type=float, default=1e-4)
    parser.add_argument("--save-every", type=float, default=1e-2)
    parser.add_argument("--quick", action="store_true", help="10⁴ steps")
    args = parser.parse_args(argv)
    steps = 10_000 if args.quick else args.steps
    scene, q0 = double_pendulum()
    nr.simulate(scene, q0, np.zeros(6), 10 * args.h, h=args.h)  # warm-up (and compilation)
    started = time.process_time()
    result = nr.simulate(scene, q0, np.zeros(6), steps * args.h, h=args.h, save_every=args.save_every)
    cpu = time.process_time() - started
    drift = max(float(np.max(np.abs(joint_violation(scene.joints, 2, q)))) for q in result.q)
    energy = [scene.energy(result.q[i], result.v[i]) for i in (0, -1)]
    print(f"double pendulum, {result.steps} steps of h = {args.h:g} ({result.status}), "
          f"{cpu / max(result.steps, 1) * 1e6:.2f} us/step")
    print(f"largest joint violation over {len(result.t)} kept samples: {drift:.3g} m (limit {DRIFT_LIMIT:g})")
    print(f"energy lost: {energy[0] - energy[-1]:.4g} J of m g L = 9.81 J")
    finest = rebound_rows((1e-4,) if args.quick else (1e-5, 2e-6))
    rebound_ok = args.quick or abs(finest) <= REBOUND_LIMIT
    return 0 if result.status == "ok" and drift <= DRIFT_LIMIT and rebound_ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
