"""The discrete energy balance of Moreau–Jean on random scenes (docs/friction.md, "Energy").

    python benchmarks/bench_energy.py [--scenes 200] [--steps 5000] [--h 2e-3] [--quick]

For constant M, gravity as the only applied force and θ = ½, each step changes the energy by
exactly the work of its contact impulses on the mean velocity, the Jacobian taken at the step's
start:

    E_{k+1} − E_k = ½ pᵀ H(q_k) v_k + ½ pᵀ H(q_k) v_{k+1}     ("start work" + "end work").

The end work is ≤ 0 for e = 0 and passive contacts (the laws hold at the end of the step), so
the energy grows only by the start work: a persistent contact's velocity at the step's start,
measured with the new Jacobian, is not the one the previous step made admissible (it differs by
(H(q_k) − H(q_{k−1})) v_k = O(h)), and p = O(h): O(h²) per step. This runs `--scenes` random
scenes (bodies dropped onto a floor, onto each other, a rod leaning on a ball; e = 0; random
μs ≥ μd) for `--steps` steps each (default 200 × 5000 = 10⁶ steps) and checks, step by step:

* the balance: |ΔE − start work − end work| ≤ BALANCE_TOL × the scene's energy scale;
* the end work ≤ 0 up to the solvers' tolerance: END_TOL × Σ|p| × the velocity scale;
* the start-work bound: ΔE ≤ start⁺ + the same tolerances;

and reports how many steps (and scenes) gain energy, the largest gain in one step, and the
largest start work. Exits 1 if a check fails. --quick: 12 scenes × 400 steps (a test runs it).
"""
from __future__ import annotations

import argparse
import math
import time

import numpy as np

import nonsmooth_rod as nr
from nonsmooth_rod.model.laws import ContactLaw

BALANCE_TOL = 1e-11  # round-off of E = ½ vᵀMv + m g y over a step, relative to the energy scale
END_TOL = 1e-7  # the end velocity's slip/gap is zero only to 1e-9·|q| (solvers, hold search)


def _law(rng):
    mu_s = rng.uniform(0.05, 0.8)
    return ContactLaw.of(mu_s, rng.uniform(0.3, 1.0) * mu_s, 0.0)


def random_scene(rng):
    """Balls on a floor (touching, or dropped a little), some stacked, and a rod with one end on
    the floor or in the air and its other end on a ball: (scene, q0, v0)."""
    n_balls = int(rng.integers(1, 4))
    radius = rng.uniform(0.03, 0.1, n_balls)
    mass = rng.uniform(0.1, 2.0, n_balls)
    bodies = [nr.RigidBody(m, 0.5 * m * r * r, f"ball{i}") for i, (m, r) in enumerate(zip(mass, radius))]
    contacts, q0 = [], []
    x = 0.0
    for i in range(n_balls):
        contacts.append(nr.DiskOnLine(i, (0.0, 0.0), nr.Line(), radius[i], _law(rng), f"floor{i}"))
        q0 += [x, radius[i] + (rng.uniform(0.0, 0.02) if rng.random() < 0.5 else 0.0), 0.0]
        if i:
            contacts.append(nr.DiskOnDisk(i, i - 1, radius[i], radius[i - 1], law=_law(rng), name=f"{i - 1}-{i}"))
        x += radius[i] + (radius[i + 1] if i + 1 < n_balls else 0.0) + rng.uniform(0.0, 0.01)
    length, rod_mass = rng.uniform(0.3, 1.0), rng.uniform(0.2, 2.0)
    rod = n_balls
    bodies.append(nr.RigidBody(rod_mass, rod_mass * length**2 / 12, "rod"))
    ball = int(rng.integers(0, n_balls))
    top = np.array([q0[3 * ball], q0[3 * ball + 1] + radius[ball]])  # the rod's upper end on the ball
    angle = rng.uniform(0.1, 0.5)
    centre = top + 0.5 * length * np.array([-math.cos(angle), -math.sin(angle)]) + [0.0, rng.uniform(0.0, 0.01)]
    centre[1] = max(centre[1], 0.5 * length * math.sin(angle) + rng.uniform(0.0, 0.01))
    q0 += [centre[0], centre[1], angle]
    contacts += [nr.PointOnLine(rod, (-length / 2, 0.0), nr.Line(), _law(rng), "rod-floor"),
                 nr.DiskOnDisk(rod, ball, 0.0, radius[ball], offset_a=(length / 2, 0.0), law=_law(rng),
                               name="rod-ball")]
    v0 = rng.normal(0.0, 0.3, 3 * len(bodies))
    v0[2::3] *= 3.0
    return nr.Scene(bodies, contacts), np.array(q0), v0


def energy_balance(scene, result):
    """Per step k: (ΔE, start work ½ pᵀH(q_k)v_k, end work ½ pᵀH(q_k)v_{k+1}, Σ|p|)."""
    q, v, h = result.q, result.v, result.stats["h"]
    p_n, p_t = result.normal_force[1:] * h, result.tangential_force[1:] * h
    energy = np.array([scene.energy(qk, vk) for qk, vk in zip(q, v)])
    start, end = np.zeros(len(q) - 1), np.zeros(len(q) - 1)
    for k in range(len(q) - 1):
        for i, c in enumerate(scene.kinematics(q[k], v[k])):
            if p_n[k, i] == 0.0 and p_t[k, i] == 0.0:
                continue
            start[k] += 0.5 * (p_n[k, i] * (c.H_N @ v[k]) + p_t[k, i] * (c.H_T @ v[k]))
            end[k] += 0.5 * (p_n[k, i] * (c.H_N @ v[k + 1]) + p_t[k, i] * (c.H_T @ v[k + 1]))
    return np.diff(energy), start, end, np.sum(np.abs(p_n) + np.abs(p_t), axis=1)


def check(scene, result):
    """The three checks of the module docstring on one run; returns a dict of figures."""
    d_energy, start, end, impulse = energy_balance(scene, result)
    energy = np.array([scene.energy(qk, vk) for qk, vk in zip(result.q, result.v)])
    scale = max(np.max(np.abs(energy)), np.max([scene.kinetic_energy(vk) for vk in result.v]), 1e-300)
    velocity = max(np.max(np.abs(result.v)), 1e-300)
    balance = np.abs(d_energy - start - end) <= BALANCE_TOL * scale
    end_ok = end <= END_TOL * impulse * velocity
    bound_ok = d_energy <= np.maximum(start, 0.0) + BALANCE_TOL * scale + END_TOL * impulse * velocity
    gains = d_energy > 1e-12 * scale
    return {"ok": bool(balance.all() and end_ok.all() and bound_ok.all()), "balance": bool(balance.all()),
            "end": bool(end_ok.all()), "bound": bool(bound_ok.all()), "gaining_steps": int(gains.sum()),
            "worst_gain": float(np.max(d_energy, initial=0.0)), "worst_start": float(np.max(start, initial=0.0)),
            "steps": len(d_energy)}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=200)
    parser.add_argument("--steps", type=int, default=5000)
    parser.add_argument("--h", type=float, default=2e-3)
    parser.add_argument("--solver", default="lemke")
    parser.add_argument("--seed", type=int, default=28)
    parser.add_argument("--quick", action="store_true", help="12 scenes × 400 steps")
    args = parser.parse_args(argv)
    scenes, steps = (12, 400) if args.quick else (args.scenes, args.steps)
    rng = np.random.default_rng(args.seed)
    wall = time.perf_counter()
    total, gaining_scenes, gaining_steps, failures, worst = 0, 0, 0, [], (0.0, -1)
    for s in range(scenes):
        scene, q0, v0 = random_scene(rng)
        result = nr.simulate(scene, q0, v0, steps * args.h, h=args.h, solver=args.solver)
        if result.status != "ok":
            failures.append(f"scene {s}: {result.message}")
            continue
        figures = check(scene, result)
        total += figures["steps"]
        gaining_steps += figures["gaining_steps"]
        gaining_scenes += figures["gaining_steps"] > 0
        worst = max(worst, (figures["worst_gain"], s))
        if not figures["ok"]:
            failures.append(f"scene {s}: balance {figures['balance']}, end work ≤ 0 {figures['end']}, "
                            f"bound {figures['bound']}")
    print(f"{total} steps of h = {args.h:g} on {scenes} random scenes ({args.solver}, e = 0, θ = ½), "
          f"{time.perf_counter() - wall:.0f} s")
    print(f"scenes gaining energy in some step (> 1e-12 of the scale): {gaining_scenes}; steps: {gaining_steps}")
    print(f"largest gain in one step: {worst[0]:.3g} J (scene {worst[1]})")
    print("every step: ΔE = start work + end work, end work ≤ 0, ΔE ≤ start work⁺: "
          + ("yes" if not failures else "NO"))
    for line in failures:
        print("  " + line)
    return 1 if failures else 0


if __name__ == "__main__":
    raise SystemExit(main())
