"""The woodpecker toy's three-coordinate model, integrated on its own: the reference for the toy.

Glocker's model of the toy (toys/woodpecker.py) in its coordinates q = (y, φ_M, φ_S), with none of
the engine's parts (no bodies, joints, contact kernels or one-step solvers): its mass matrix,
forces and contact rows written out, integrated by Moreau's midpoint time-stepping with a
projected Gauss–Seidel on the three contacts' impulses (Newton's law normally, Coulomb's
tangentially). Two versions:

* ``linear=True`` — the published model (Glocker 1995; Siconos' WoodPecker.cpp): mass matrix,
  gravity and contact rows linearised in the angles. It reproduces the trajectory Siconos ships
  (`SICONOS`, below) — a check that the parameters are read the way they were published;
* ``linear=False`` — the same three coordinates with the exact geometry: what the toy's planar
  scene (sleeve, carriage, bird, pins, slider) should do.

`run_reduced` returns the samples and the contacts' closings, which `woodpecker.limit_cycle`
turns into periods, impact sequences and descents.
"""
from __future__ import annotations

import math

import numpy as np

from .woodpecker import CONTACTS, Woodpecker

# Siconos' reference trajectory of the published model (examples/mechanics/Woodpecker/Woodpecker.ref
# in siconos/siconos-tutorials: Moreau–Jean θ = ½, h = 2e-5 s, from the published start): the beak
# hits the pole in the steps ending at these times, the sleeve's height y there, and in between
# the contacts close in this order (their gaps: the beak, lower edge, upper edge = contacts 1, 2, 3).
SICONOS = {
    "beak_times": (0.08104, 0.22710),  # s: one period 0.14606 s
    "heights": (-0.00733862, -0.02681536),  # m: 19.477 mm a period, 0.13335 m/s
    "sequence": ["beak", "upper", "lower", "lower", "upper"],  # the last: a graze before the next beak
    "step": 2e-5,
}


def _rows(toy: Woodpecker, q, linear: bool):
    """Bird's centre-of-mass Jacobian (2×3), and per contact: gap, normal row, tangent row."""
    y, pm, ps = q
    lm, lg, r, hm, hs, ls = (toy.hinge_offset, toy.bird_offset, toy.sleeve_radius, toy.sleeve_half_height,
                             toy.beak_height, toy.beak_back)
    if linear:  # Siconos' WoodPecker.cpp: H1, H2, H3 and the constant mass matrix
        bird = np.array([[0.0, 0.0, 0.0], [1.0, lm, lg]])
        gaps = [lm + lg - ls - toy.pole_radius - hs * ps, r - toy.pole_radius + hm * pm, r - toy.pole_radius - hm * pm]
        normals = [np.array([0.0, 0.0, -hs]), np.array([0.0, hm, 0.0]), np.array([0.0, -hm, 0.0])]
        tangents = [np.array([1.0, lm, lg - ls]), np.array([1.0, r, 0.0]), np.array([1.0, r, 0.0])]
        return bird, np.array(gaps), normals, tangents
    cm, sm, cs, ss = math.cos(pm), math.sin(pm), math.cos(ps), math.sin(ps)
    bird = np.array([[0.0, -lm * sm, -lg * ss], [1.0, lm * cm, lg * cs]])
    beak_x = lm * cm + lg * cs - ls * cs - hs * ss
    gaps = [beak_x - toy.pole_radius]
    normals = [np.array([0.0, -lm * sm, -lg * ss + ls * ss - hs * cs])]
    tangents = [np.array([1.0, lm * cm, lg * cs - ls * cs - hs * ss])]
    for py in (-hm, hm):  # the sleeve's lower and upper inner edges (r_M, ∓h_M)
        gaps.append(r * cm - py * sm - toy.pole_radius)
        normals.append(np.array([0.0, -r * sm - py * cm, 0.0]))
        tangents.append(np.array([1.0, r * cm - py * sm, 0.0]))
    return bird, np.array(gaps), normals, tangents


def _dynamics(toy: Woodpecker, q, v, linear: bool):
    """M(q), the forces f(q, v) (gravity, spring, the bird's centripetal terms) and the contact rows."""
    bird, gaps, normals, tangents = _rows(toy, q, linear)
    m = np.diag([toy.sleeve_mass, toy.sleeve_inertia, toy.bird_inertia]) + toy.bird_mass * bird.T @ bird
    spring = toy.spring_stiffness * (q[1] - q[2])
    f = np.array([-toy.sleeve_mass * toy.g, -spring, spring]) - toy.bird_mass * toy.g * bird[1]
    if not linear:  # −m_S Jᵀ J̇ v: the bird's centripetal accelerations
        lm, lg = toy.hinge_offset, toy.bird_offset
        jdot_v = np.array([-lm * math.cos(q[1]) * v[1] ** 2 - lg * math.cos(q[2]) * v[2] ** 2,
                           -lm * math.sin(q[1]) * v[1] ** 2 - lg * math.sin(q[2]) * v[2] ** 2])
        f -= toy.bird_mass * bird.T @ jdot_v
    return m, f, gaps, normals, tangents


def _impulses(w_inv, v_free, v, rows, restitution, mu, sweeps: int = 500):
    """Projected Gauss–Seidel on the closed contacts' impulses: (p_N, p_T) per contact, and the
    velocity they leave, v_free + W Σ (n p_N + t p_T)."""
    p = np.zeros((len(rows), 2))
    v_now = v_free.copy()
    for _ in range(sweeps):
        change = 0.0
        for k, (normal, tangent) in enumerate(rows):
            for j, row in ((0, normal), (1, tangent)):
                u = row @ v_now + (restitution[k] * (normal @ v) if j == 0 else 0.0)
                new = p[k, j] - u / (row @ w_inv @ row)
                new = max(0.0, new) if j == 0 else min(mu * p[k, 0], max(-mu * p[k, 0], new))
                v_now += w_inv @ row * (new - p[k, j])
                change, p[k, j] = max(change, abs(new - p[k, j])), new
        if change < 1e-15:
            break
    return p, v_now


def run_reduced(toy: Woodpecker, t_end: float, h: float, linear: bool):
    """(t, q (n, 3), v (n, 3), closings): the model from the toy's `start` (linear) or
    `exact_start` (exact geometry, as the toy's scene); closings are
    (t, contact name) of each contact that takes an impulse in a step after a step without."""
    restitution = (toy.beak_restitution, toy.sleeve_restitution, toy.sleeve_restitution)
    start = toy.start if linear else toy.exact_start
    q, v = np.array(start[:3], dtype=float), np.array(start[3:], dtype=float)
    n = int(round(t_end / h))
    qs, vs, closings, was_closed = [q], [v], [], set()
    for step in range(1, n + 1):
        mid = q + 0.5 * h * v
        m, f, gaps, normals, tangents = _dynamics(toy, mid, v, linear)
        w_inv = np.linalg.inv(m)
        v_free = v + h * w_inv @ f
        active = [k for k in range(3) if gaps[k] <= 0.0]
        rows = [(normals[k], tangents[k]) for k in active]
        p, v = _impulses(w_inv, v_free, v, rows, [restitution[k] for k in active], toy.mu)
        q = mid + 0.5 * h * v
        closed = {active[i] for i in range(len(active)) if p[i][0] > 0.0}
        closings += [(step * h, CONTACTS[k]) for k in sorted(closed - was_closed)]
        was_closed = closed
        qs.append(q)
        vs.append(v)
    return np.arange(n + 1) * h, np.array(qs), np.array(vs), closings
