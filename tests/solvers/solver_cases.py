"""Random step problems of a planar rigid body (3 DOF) with 1–2 contacts, for the solver tests.

W = Hᵀ M⁻¹ H from a random mass/inertia and contact geometry; q = Hᵀ v for a random free
velocity v (a physical step's q always lies in range(Hᵀ) = range(W), which is what makes the
singular two-contact problems solvable). Intervals are the integrator's shifted ones,
lo = c − μs, hi = c + μs with c = (μs − μd)·s, s ∈ {−1, 0, 1}.
"""
from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

from nonsmooth_rod.solvers.problem import PlanarFrictionProblem


def contact_jacobian(positions, normals) -> np.ndarray:
    """H (3 × 2n_c): columns (n, r×n), (t, r×t) per contact, t = n rotated by +90°."""
    columns = []
    for (rx, ry), (nx, ny) in zip(positions, normals):
        tx, ty = -ny, nx
        columns.append([nx, ny, rx * ny - ry * nx])
        columns.append([tx, ty, rx * ty - ry * tx])
    return np.array(columns, dtype=float).T


def step_problem(mass, inertia, positions, normals, velocity, lo, hi) -> PlanarFrictionProblem:
    H = contact_jacobian(positions, normals)
    M_inv = np.diag([1.0 / mass, 1.0 / mass, 1.0 / inertia])
    W = H.T @ M_inv @ H
    W = 0.5 * (W + W.T)
    q = H.T @ np.asarray(velocity, dtype=float)
    return PlanarFrictionProblem(W, q, lo, hi)


def unit(angle):
    return (float(np.cos(angle)), float(np.sin(angle)))


finite = dict(allow_nan=False, allow_infinity=False, allow_subnormal=False)


@st.composite
def intervals(draw, n_contacts):
    lo, hi = [], []
    for _ in range(n_contacts):
        mu_s = draw(st.floats(0.0, 2.0, **finite))
        mu_d = draw(st.floats(0.0, 1.0, **finite)) * mu_s
        sign = draw(st.sampled_from([-1.0, 0.0, 1.0]))
        center = (mu_s - mu_d) * sign
        lo.append(center - mu_s)
        hi.append(center + mu_s)
    return np.minimum(lo, 0.0), np.maximum(hi, 0.0)


@st.composite
def friction_steps(draw, n_contacts=None, kind=None):
    """Random step problem: 1–2 contacts, each a disk contact or a body corner."""
    if n_contacts is None:
        n_contacts = draw(st.integers(1, 2))
    mass = draw(st.floats(0.1, 10.0, **finite))
    inertia = mass * draw(st.floats(0.01, 1.0, **finite))
    positions, normals = [], []
    for _ in range(n_contacts):
        normal = unit(draw(st.floats(0.0, 2 * np.pi, **finite)))
        contact_kind = kind or draw(st.sampled_from(["disk", "corner"]))
        if contact_kind == "disk":
            # contact point a radius below the disk centre, centre of mass slightly off-centre
            radius = draw(st.floats(0.05, 1.0, **finite))
            offset = [draw(st.floats(-0.3, 0.3, **finite)) * radius for _ in range(2)]
            positions.append((-radius * normal[0] + offset[0], -radius * normal[1] + offset[1]))
        else:
            positions.append(tuple(draw(st.floats(-1.0, 1.0, **finite)) for _ in range(2)))
        normals.append(normal)
    velocity = [draw(st.floats(-3.0, 3.0, **finite)) for _ in range(3)]
    lo, hi = draw(intervals(n_contacts))
    return step_problem(mass, inertia, positions, normals, velocity, lo, hi)


def random_step(rng, n_contacts, kind="corner", mu_max=2.0):
    """The same family as `friction_steps`, from a numpy Generator (for sweeps and benchmarks)."""
    mass = rng.uniform(0.1, 10.0)
    inertia = mass * rng.uniform(0.01, 1.0)
    positions, normals = [], []
    for _ in range(n_contacts):
        normal = unit(rng.uniform(0, 2 * np.pi))
        if kind == "disk":
            radius = rng.uniform(0.05, 1.0)
            offset = rng.uniform(-0.3, 0.3, 2) * radius
            positions.append((-radius * normal[0] + offset[0], -radius * normal[1] + offset[1]))
        else:
            positions.append(tuple(rng.uniform(-1.0, 1.0, 2)))
        normals.append(normal)
    mu_s = rng.uniform(0, mu_max, n_contacts)
    mu_d = rng.uniform(0, 1, n_contacts) * mu_s
    center = (mu_s - mu_d) * rng.choice([-1.0, 0.0, 1.0], n_contacts)
    return step_problem(
        mass, inertia, positions, normals, rng.uniform(-3, 3, 3),
        np.minimum(center - mu_s, 0.0), np.maximum(center + mu_s, 0.0),
    )


def block_on_incline(angle, mu, velocity=(0.0, 0.0, 0.0), gravity_impulse=0.0981, half_width=0.5,
                     half_height=0.25, mass=1.0):
    """A box resting with its two lower corners on an incline: 4×4 W of rank 3.

    The incline's normal is tilted by ``angle``; the free velocity is ``velocity`` plus one
    step's gravity impulse (per unit mass). Both corners stick when tan(angle) < μ, and the
    split of the tangential impulse between them is statically indeterminate.
    """
    normal = (-np.sin(angle), np.cos(angle))
    tangent = (-normal[1], normal[0])
    positions = [
        (sign * half_width * tangent[0] - half_height * normal[0],
         sign * half_width * tangent[1] - half_height * normal[1])
        for sign in (-1.0, 1.0)
    ]
    inertia = mass * ((2 * half_width) ** 2 + (2 * half_height) ** 2) / 12.0
    v = np.asarray(velocity, dtype=float) + np.array([0.0, -gravity_impulse, 0.0])
    mu = np.full(2, mu)
    return step_problem(mass, inertia, positions, [normal, normal], v, -mu, mu)
