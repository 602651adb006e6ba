"""Micro-benchmark of the one-step solvers: µs per solve, 1-contact and 2-contact steps,
and the cost of a pgs sweep on a row of balls with 1 … 1999 contacts (O(contacts) per sweep).

    python benchmarks/bench_solvers.py [--repeats 7] [--problems 50] [--quick]

Each solver runs over the same set of random steps of a planar rigid body (seeded: corner
contacts, μ ≤ 1, shifted two-coefficient intervals); the time per solve is the median over
repeats of (loop time / number of problems). Solves that raise are counted and excluded
from the loop (their count is printed). Yardstick: numpy.linalg.solve of a 3×3 system in
the same kind of Python loop.

Scaling: N balls in a row on a floor, each touching the floor and its neighbours (2N − 1
contacts), falling and sliding (random horizontal velocities, μ = 0.3); the Delassus matrix
is block-sparse (`delassus.py` block layout, built in O(N)). Reported: µs per
`pgs_block` sweep (sweep + u + residual), that per contact, and the ratio to the yardstick.
Before the kernels, pgs ran in Python over a dense W: 2.4 s per sweep at 2020 contacts.
`--quick` runs a few problems, one repeat and rows of up to 199 contacts (for the test).
"""
from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from nonsmooth_rod.solvers import SolverError, available_solvers, solve
from nonsmooth_rod.solvers.gauss_seidel import pgs_block
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


def row_of_balls(n_balls: int, rng, radius=0.05, mass=0.1, h=1e-3, mu=0.3):
    """Block-sparse step problem of N balls on a floor in a row (module docstring).

    Returns (indptr, indices, blocks, q, lo, hi). Per contact: the 2×3 Jacobian rows (N, T)
    on each body it touches; W_ij = Σ_b G_ib M_b⁻¹ G_jbᵀ over the bodies both touch.
    """
    inverse_mass = np.diag([1 / mass, 1 / mass, 1 / (0.4 * mass * radius**2)])
    jacobians = []  # per contact: [(body, 2×3 rows), ...]
    for i in range(n_balls):
        jacobians.append([(i, np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, -radius]]))])  # floor
        if i + 1 < n_balls:  # ball i → ball i+1: normal (1, 0), tangent (0, 1)
            jacobians.append([(i + 1, np.array([[1.0, 0.0, 0.0], [0.0, 1.0, -radius]])),
                              (i, np.array([[-1.0, 0.0, 0.0], [0.0, -1.0, -radius]]))])
    by_body = [[] for _ in range(n_balls)]
    for c, parts in enumerate(jacobians):
        for body, G in parts:
            by_body[body].append((c, G))
    velocity = np.zeros((n_balls, 3))
    velocity[:, 0] = rng.uniform(-1.0, 1.0, n_balls)
    velocity[:, 1] = -0.1 - 9.81 * h
    indptr, indices, blocks, q = [0], [], [], []
    for c, parts in enumerate(jacobians):
        row = {}
        for body, G in parts:
            for d, G_other in by_body[body]:
                row[d] = row.get(d, 0.0) + G @ inverse_mass @ G_other.T
        for d in sorted(row):
            indices.append(d)
            blocks.append(row[d])
        indptr.append(len(indices))
        q.extend(sum(G @ velocity[body] for body, G in parts))
    n_contacts = len(jacobians)
    return (np.array(indptr, dtype=np.int64), np.array(indices, dtype=np.int64), np.array(blocks),
            np.array(q), np.full(n_contacts, -mu), np.full(n_contacts, mu))


def sweep_time_us(problem, sweeps: int, repeats: int) -> float:
    """Median over repeats of µs per pgs_block sweep (unreachable rtol: exactly `sweeps` sweeps)."""
    indptr, indices, blocks, q, lo, hi = problem
    samples = []
    for _ in range(repeats):
        p, u = np.zeros(q.shape[0]), np.zeros(q.shape[0])
        start = time.perf_counter()
        status, done, residual = pgs_block(indptr, indices, blocks, q, lo, hi, p, u, 1e-300, sweeps)
        samples.append((time.perf_counter() - start) / done * 1e6)
    return statistics.median(samples)


def scaling_table(ball_counts, repeats: int, yardstick: float, rng) -> None:
    sweep_time_us(row_of_balls(2, rng), 1, 1)  # compile
    print(f"\npgs sweep on a row of balls (block-sparse W), median of {repeats}:")
    print(f"{'contacts':>9}{'µs/sweep':>12}{'ns/contact':>12}{'× yardstick':>13}")
    for n_balls in ball_counts:
        problem = row_of_balls(n_balls, rng)
        n_contacts = problem[3].shape[0] // 2
        sweeps = max(5, 20000 // n_contacts)
        us = sweep_time_us(problem, sweeps, repeats)
        print(f"{n_contacts:>9}{us:>12.2f}{1e3 * us / n_contacts:>12.1f}{us / yardstick:>13.2f}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--problems", type=int, default=50)
    parser.add_argument("--quick", action="store_true", help="few problems, 1 repeat, rows ≤ 199 contacts")
    args = parser.parse_args()
    if args.quick:
        args.repeats, args.problems = 1, 5
    ball_counts = (1, 2, 5, 25, 100) if args.quick else (1, 2, 5, 10, 25, 50, 100, 250, 500, 1000)

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
    scaling_table(ball_counts, args.repeats, yardstick, rng)


if __name__ == "__main__":
    main()
