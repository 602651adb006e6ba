"""Micro-benchmark of the one-step solvers: µs per solve, 1-contact and 2-contact steps.

    python benchmarks/bench_solvers.py [--repeats 7] [--problems 50]

Each solver runs over the same set of random steps of a planar rigid body (seeded: corner
contacts, μ ≤ 1, shifted two-coefficient intervals); the time per solve is the median over
repeats of (loop time / number of problems). Solves that raise are counted and excluded
from the loop (their count is printed). Yardstick: numpy.linalg.solve of a 3×3 system in
the same kind of Python loop.
"""
from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from nonsmooth_rod.solvers import SolverError, available_solvers, solve
from nonsmooth_rod.solvers.problem import PlanarFrictionProblem


def random_step(rng, n_contacts: int) -> PlanarFrictionProblem:
    """W = Hᵀ M⁻¹ H of a rigid body (3 DOF) with corner contacts, q = Hᵀ v."""
    mass = rng.uniform(0.1, 10.0)
    inertia = mass * rng.uniform(0.01, 1.0)
    columns = []
    for _ in range(n_contacts):
        angle = rng.uniform(0, 2 * np.pi)
        (nx, ny), (rx, ry) = (np.cos(angle), np.sin(angle)), rng.uniform(-1, 1, 2)
        tx, ty = -ny, nx
        columns += [[nx, ny, rx * ny - ry * nx], [tx, ty, rx * ty - ry * tx]]
    H = np.array(columns).T
    W = H.T @ np.diag([1 / mass, 1 / mass, 1 / inertia]) @ H
    mu_s = rng.uniform(0, 1, n_contacts)
    mu_d = rng.uniform(0.5, 1, n_contacts) * mu_s
    center = (mu_s - mu_d) * rng.choice([-1.0, 0.0, 1.0], n_contacts)
    return PlanarFrictionProblem(0.5 * (W + W.T), H.T @ rng.uniform(-3, 3, 3), center - mu_s, center + mu_s)


def time_per_call(call, items, repeats: int) -> float:
    """Median over repeats of the mean µs per call over items."""
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        for item in items:
            call(item)
        samples.append((time.perf_counter() - start) / len(items) * 1e6)
    return statistics.median(samples)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--problems", type=int, default=50)
    args = parser.parse_args()

    rng = np.random.default_rng(12345)
    problem_sets = {n: [random_step(rng, n) for _ in range(args.problems)] for n in (1, 2)}
    variants = [(name, name, {}) for name in available_solvers()]
    variants.insert(1, ("lemke (cone LCP)", "lemke", {"formulation": "cone"}))
    variants.insert(2, ("lemke (pure Python)", "lemke", {"jit": False}))

    print(f"{'solver':<22}{'1 contact':>14}{'2 contacts':>14}   (µs per solve, median of {args.repeats})")
    for label, name, options in variants:
        cells = []
        for n_contacts, problems in problem_sets.items():
            solvable = []
            for problem in problems:
                try:
                    solve(problem, name, **options)  # also warms up (numba compile, imports)
                    solvable.append(problem)
                except SolverError:
                    pass
            # the QP solvers take milliseconds: fewer repeats keep the script short
            repeats = args.repeats if name in ("lemke", "pgs", "enum") else max(1, args.repeats // 3)
            seconds = time_per_call(lambda p: solve(p, name, **options), solvable, repeats)
            failed = len(problems) - len(solvable)
            cells.append(f"{seconds:10.1f}" + (f" ({failed}✗)" if failed else "    "))
        print(f"{label:<22}{cells[0]:>14}{cells[1]:>14}")

    A = np.array([[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]])
    rhs = [rng.normal(size=3) for _ in range(args.problems)]
    yardstick = time_per_call(lambda b: np.linalg.solve(A, b), rhs, args.repeats)
    print(f"{'yardstick: 3×3 numpy.linalg.solve':<36}{yardstick:>10.1f} µs")


if __name__ == "__main__":
    main()
