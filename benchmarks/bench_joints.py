"""The drift of joints over a long run (docs/joints.md, "Drift"): a double pendulum for 10⁶ steps.

    python benchmarks/bench_joints.py [--steps 1000000] [--h 1e-4] [--quick]

Two uniform rods (1 m, 1 kg), the first pinned to the world at its end, the second pinned to the
first's free end, released both horizontal (chaotic from there): after each Moreau–Jean step the
positions are projected back onto the joints, so their violation stays at round-off of the
coordinates however long the run. Reports the largest violation |C(q)| over the kept samples
(one per --save-every seconds, and the last state), the energy lost (first order in h: the
scheme's dissipation) and the cost per step. Exits 1 if the violation exceeds DRIFT_LIMIT.
--quick: 10⁴ steps (a test runs it).
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import nonsmooth_rod as nr
from nonsmooth_rod.model.joints import joint_violation

DRIFT_LIMIT = 1e-9  # m: the bound after 10⁶ steps


def double_pendulum():
    """The scene and its start: both rods horizontal, at rest."""
    rods = [nr.RigidBody(1.0, 1.0 / 12, name=f"rod{i}") for i in (1, 2)]
    joints = [nr.Pin(0, (-0.5, 0.0), None, (0.0, 0.0), name="shoulder"),
              nr.Pin(1, (-0.5, 0.0), 0, (0.5, 0.0), name="elbow")]
    return nr.Scene(rods, gravity=9.81, joints=joints), np.array([0.5, 0.0, 0.0, 1.5, 0.0, 0.0])


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
    return 0 if result.status == "ok" and drift <= DRIFT_LIMIT else 1


if __name__ == "__main__":
    raise SystemExit(main())
