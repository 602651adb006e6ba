"""Where a two-contact toy's step goes: the whole step through `nr.simulate` against the solve of
its coupled pair alone (issue 25's two-contact target, 0.4 yardsticks a step).

    python benchmarks/bench_two_contact_solve.py [--rounds 5] [--quick]

For each two-contact toy and exact solver: the whole call's CPU time per step (200 steps at
h = 1e-3, `repeat_rest=False`, median of --rounds calls), and the solver's kernel
(`solve_interval_into`, what `two_coefficient._solve` runs for a group of two contacts) on the
toy's own two-contact problems — W = (H_N; H_T) M⁻¹ (H_N; H_T)ᵀ and q = H v_free − w at every
fifth state of its run where both contacts are within reach, under the interval of the slip guess
the step starts from (the sign of each contact's slip) —
repeated in a compiled loop of its own (a plain loop with numba off). Prints both and their
difference (the step without the solve) in yardsticks measured in the same run. What it showed
(docs/performance.md "A two-contact step: the solve is not most of it"): even a free solve
leaves the blocks at or above the target. --quick: one round, 20 repetitions.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from yardstick import yardstick_us  # noqa: E402

import nonsmooth_rod as nr  # noqa: E402
from nonsmooth_rod import _jit, toys  # noqa: E402
from nonsmooth_rod.model.packing import pack_scene  # noqa: E402
from nonsmooth_rod.solvers.kernels import solve_interval_into  # noqa: E402
from nonsmooth_rod.solvers.registry import SOLVER_CODES  # noqa: E402

TWO_CONTACTS = ("BlockOnIncline", "PushedBlock", "BeltOscillator", "RockingBlock")
H, STEPS = 1e-3, 200


def two_contact_problems(toy):
    """(Ws, qs, los, his) stacked: the toy's coupled-pair problems along a lemke run."""
    scene, (q0, v0) = toy.scene(), toy.initial_state()
    packed = pack_scene(scene)
    run = nr.simulate(scene, q0, v0, H * STEPS, method="moreau-jean", h=H, solver="lemke")
    n_dof = packed.minv.shape[0]
    Ws, qs, los, his = [], [], [], []
    for q, v in zip(run.trajectory.q[::5], run.trajectory.v[::5]):
        kins = [contact.kinematics(q, v, n_dof) for contact in scene.contacts]
        if len(kins) != 2 or not all(kin.gap < 1e-3 for kin in kins):
            continue
        Hm = np.array([row for kin in kins for row in (kin.H_N, kin.H_T)])
        w = np.array([x for kin in kins for x in (kin.normal_velocity, kin.surface_velocity)])
        W = Hm @ np.diag(packed.minv) @ Hm.T
        q_step = Hm @ (v + H * packed.minv * packed.weight) - w
        slip = Hm[1::2] @ v - w[1::2]  # the step's slip guess: the sign of each contact's slip at its start
        guess = np.where(np.abs(slip) > 1e-9, np.sign(slip), 0.0)
        friction = [contact.law.friction for contact in scene.contacts]
        shift = np.array([f.mu_s - f.mu_d for f in friction]) * guess
        mu_s = np.array([f.mu_s for f in friction])
        Ws.append(W), qs.append(q_step), los.append(shift - mu_s), his.append(shift + mu_s)
    return np.array(Ws), np.array(qs), np.array(los), np.array(his)


def _solve_many(code, Ws, qs, los, his, reps, p, u, floats, ints, rtol, max_iter):
    # rtol, max_iter passed in, not written here: a literal 0 would make numba compile the loop's
    # solve_interval_into (and its solvers) once more for Literal[int](0) instead of loading its code
    total = 0.0
    for _ in range(reps):
        for k in range(Ws.shape[0]):
            solve_interval_into(code, Ws[k], qs[k], los[k], his[k], p, u, rtol, max_iter, floats, ints)
            total += p[0]
    return total


if _jit.ENABLED:
    import numba

    _solve_many = numba.njit(_solve_many)


def solve_us(code, problems, reps, rounds):
    """CPU µs of one solve, the median over rounds of the mean over the problems."""
    Ws, qs, los, his = problems
    p, u = np.zeros(4), np.zeros(4)
    floats, ints = np.zeros(4096), np.zeros(512, dtype=np.int64)
    _solve_many(code, Ws, qs, los, his, 1, p, u, floats, ints, 0.0, 0)  # compile, warm
    times = []
    for _ in range(rounds):
        t0 = time.process_time()
        _solve_many(code, Ws, qs, los, his, reps, p, u, floats, ints, 0.0, 0)
        times.append((time.process_time() - t0) / (reps * Ws.shape[0]) * 1e6)
    return statistics.median(times)


def step_us(toy, solver, rounds):
    """CPU µs a step of the whole call through nr.simulate (median of rounds, after a warm call)."""
    scene, (q0, v0) = toy.scene(), toy.initial_state()
    times = []
    for _ in range(rounds + 1):
        t0 = time.process_time()
        run = nr.simulate(scene, q0, v0, H * STEPS, method="moreau-jean", h=H, solver=solver, repeat_rest=False)
        times.append((time.process_time() - t0) / run.steps * 1e6)
    return statistics.median(times[1:])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args(argv)
    rounds, reps = (1, 20) if args.quick else (args.rounds, 2000)
    print(f"{'toy':16s} {'solver':>6s} {'problems':>8s} {'step x yd':>9s} {'solve x yd':>10s} "
          f"{'step - solve':>12s} {'compiled':>8s}")
    for name in TWO_CONTACTS:
        toy = getattr(toys, name)()
        problems = two_contact_problems(toy)
        for solver in ("lemke", "pgs"):
            yard = yardstick_us(n=5000, repeats=3)
            step = step_us(toy, solver, rounds)
            solve = solve_us(SOLVER_CODES[solver], problems, reps, rounds) if len(problems[0]) else float("nan")
            print(f"{name:16s} {solver:>6s} {len(problems[0]):8d} {step / yard:9.2f} {solve / yard:10.2f} "
                  f"{(step - solve) / yard:12.2f} {str(_jit.ENABLED):>8s}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
