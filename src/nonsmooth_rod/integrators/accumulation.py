"""Which impacts of an accumulation are resolved: one rule for every method (issue 28).

Impacts with a coefficient below one accumulate (a bouncing ball; Housner's rocking block, whose
corners take turns, each impact multiplying the speed by 1 − 1.5 sin²α): ever slower, ever
closer, infinitely many before a finite time. How many a method reports depends on where it
stops resolving them, so the count is only defined at a stated resolution.

The rule, in positions: at a resolution δ (m), an impact is *resolved* when the flight that ends
in it could rise higher than δ, i.e. when its closing speed (the contact's normal velocity just
before it) exceeds that of a fall from δ under the scene's acceleration scale a — the largest
|M⁻¹ f| of its applied forces and gravity at rest:

    u > u_δ = √(2 a δ)                                        (`speed_floor`, `resolved`)

A method resolving positions to δ cannot tell slower impacts apart from resting contact.

* The event-driven reference and the hybrid method (integrators/event_driven.py) apply it ahead:
  after an impact, when every contact leaving the obstacle does so slower than u_δ, the next
  impact (its closing speed that rebound's, energy being kept in a flight this low) is not
  resolved — the remaining impacts, a geometric series of flights 2u/|g̈| times rⁿ (r = the
  impact's ratio of leaving to closing speed), are summed to the accumulation time
  (`accumulation_time`), and the contacts are at rest relative to the obstacle from there
  (`limit_state`: the M-orthogonal projection of q on zero gap and of v on zero normal velocity
  at the contacts taking part, zero slip too where the slip is below u_δ — the series' limit,
  to the resolution).
* Moreau–Jean (fixed steps or tol) resolves the accumulation in its steps by itself; its reported
  impacts are those the rule calls resolved (the others are applied and counted in
  stats["unresolved_impacts"]).

`resolution = 0` (the default everywhere) resolves every impact: the methods as before.
"""
from __future__ import annotations

import math

import numpy as np


def speed_floor(scene, t: float, q, resolution: float) -> float:
    """u_δ = √(2 a δ): the closing speed of a fall from `resolution` (m) under the scene's
    acceleration scale a = max |M⁻¹ f(t, q, 0)| (gravity and the applied forces at rest)."""
    if resolution <= 0.0:
        return 0.0
    f = scene.force(t, np.asarray(q, dtype=float), np.zeros(scene.n_dof))
    return math.sqrt(2.0 * float(np.max(np.abs(scene.inverse_mass_diagonal * f), initial=0.0)) * resolution)


def resolved(closing_speed: float, floor: float) -> bool:
    """Whether an impact closing at `closing_speed` (m/s, ≥ 0) is resolved at the floor u_δ."""
    return floor <= 0.0 or closing_speed > floor


def closing_speed(scene, contact: int, q, v_before) -> float:
    """How fast contact `contact` closes at (q, v_before): −(H_N v − the obstacle's normal velocity), ≥ 0."""
    k = scene.contacts[contact].kinematics(np.asarray(q, dtype=float), np.asarray(v_before, dtype=float), scene.n_dof)
    return max(0.0, -float(k.H_N @ v_before) + k.normal_velocity)


def impact_resolved(scene, contact: int, t: float, q, v_before, resolution: float) -> bool:
    """The rule for a method's recorded impact (Moreau–Jean's): its closing speed above u_δ at
    the impact's time and configuration."""
    return resolution <= 0.0 or resolved(closing_speed(scene, contact, q, v_before),
                                         speed_floor(scene, t, q, resolution))


def accumulation_time(t: float, leaving_speed: float, normal_acceleration: float, ratio: float) -> float | None:
    """When the impacts after one at t accumulate: a contact leaving at `leaving_speed` under
    `normal_acceleration` (< 0) flies 2u/|g̈|, each next flight `ratio` times the one before;
    None when they do not accumulate (no return, or a ratio ≥ 1)."""
    if not (normal_acceleration < 0.0 and 0.0 <= ratio < 1.0):
        return None
    return t + (2.0 * leaving_speed / -normal_acceleration) / (1.0 - ratio)


def limit_state(minv, normal_rows: list, gaps, tangent_rows: list, q, v) -> tuple[np.ndarray, np.ndarray]:
    """The series' limit, to the resolution: (q, v) moved M-orthogonally onto zero gap at the
    touching contacts (rows H_N, `gaps`: first order, the gaps being below the resolution) and v
    onto zero normal velocity there, zero slip too along `tangent_rows`."""
    q, v = np.array(q, dtype=float), np.array(v, dtype=float)
    if not normal_rows:
        return q, v
    q = q - _projection(minv, np.array(normal_rows), np.asarray(gaps, dtype=float))
    H = np.array(list(normal_rows) + list(tangent_rows))
    return q, v - _projection(minv, H, H @ v)


def _projection(minv, H, residual) -> np.ndarray:
    """M⁻¹Hᵀ(H M⁻¹ Hᵀ)⁺ r: the M-orthogonal step taking H x to H x − r."""
    return minv * (H.T @ np.linalg.lstsq((H * minv) @ H.T, residual, rcond=None)[0])
