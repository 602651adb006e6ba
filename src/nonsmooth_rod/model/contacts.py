"""Contact relations: gap functions and their Jacobians (Siconos' "relations").

A relation maps the generalised velocity v of the scene (3 entries per body: ẋ, ẏ, θ̇ of the
centre of mass) to the local velocities of one contact,

    u_N = H_N · v,        u_T = H_T · v − (tangential velocity of the obstacle),

and gives the gap g (≥ 0 when separated) and the velocity-product terms Ḣ v that an
acceleration-level (event-driven) formulation needs: g̈ = H_N · a + Ḣ_N v.
The obstacle is a fixed straight line (horizontal or inclined), possibly moving along itself
(a conveyor belt), or the disk of another body.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..validation import InputError, require_finite, require_index, require_nonnegative, require_point
from .body import cross2, rotate
from .laws import ContactLaw


@dataclass(frozen=True)
class Line:
    """A fixed straight obstacle through `point`, bodies staying on the side its normal points to.

    `angle` is the inclination of the line to +x (radians, counter-clockwise); the normal is the
    tangent turned by +90°, so angle = 0 is the floor y = point[1] with normal +y and tangent +x.
    `velocity` lets the surface move along its tangent (a belt) without moving the line.
    """

    point: tuple[float, float] = (0.0, 0.0)
    angle: float = 0.0
    velocity: float = 0.0

    def __post_init__(self):
        require_finite("line angle", self.angle)
        require_finite("line velocity", self.velocity)
        object.__setattr__(self, "point", require_point("line point", self.point))

    @property
    def tangent(self) -> tuple[float, float]:
        return (math.cos(self.angle), math.sin(self.angle))

    @property
    def normal(self) -> tuple[float, float]:
        return (-math.sin(self.angle), math.cos(self.angle))


def _contact_name(name) -> str:
    if not isinstance(name, str) or not name:
        raise InputError(f"a contact name must be a non-empty string, got {name!r}")
    return name


def _require_type(name: str, value, cls) -> None:
    if not isinstance(value, cls):
        raise InputError(f"{name} must be a {cls.__name__}, got {type(value).__name__}")


@dataclass
class ContactKinematics:
    """Everything a step needs from one contact at the current configuration."""

    gap: float
    H_N: np.ndarray  # row over the scene's generalised velocity
    H_T: np.ndarray
    drift_N: float  # Ḣ_N v
    drift_T: float  # Ḣ_T v
    surface_velocity: float = 0.0  # subtracted from H_T v to get the slip velocity


@dataclass
class DiskOnLine:
    """A disk (ball) of radius `radius` fixed on `body` touching a fixed Line.

    `offset` is the disk centre in the body frame, relative to the centre of mass; a radius of
    zero makes it a point (a corner). Name the contact for output ("A", "B", "corner-left", ...).
    """

    body: int
    offset: tuple[float, float]
    line: Line = field(default_factory=Line)
    radius: float = 0.0
    law: ContactLaw = field(default_factory=ContactLaw)
    name: str = "contact"

    def __post_init__(self):
        self.name = _contact_name(self.name)
        self.body = require_index(f"contact {self.name!r} body", self.body)
        self.offset = require_point(f"contact {self.name!r} offset", self.offset)
        self.radius = require_nonnegative(f"contact {self.name!r} radius", self.radius)
        _require_type(f"contact {self.name!r} line", self.line, Line)
        _require_type(f"contact {self.name!r} law", self.law, ContactLaw)

    @property
    def bodies(self) -> tuple[int, ...]:
        return (self.body,)

    def kinematics(self, q: np.ndarray, v: np.ndarray, n_dof: int) -> ContactKinematics:
        i = 3 * self.body
        x, y, th = q[i], q[i + 1], q[i + 2]
        om = v[i + 2]
        d = rotate(th, self.offset)
        n = self.line.normal
        t = self.line.tangent
        rho = (d[0] - self.radius * n[0], d[1] - self.radius * n[1])
        gap = n[0] * (x + d[0] - self.line.point[0]) + n[1] * (y + d[1] - self.line.point[1]) - self.radius
        H_N = np.zeros(n_dof)
        H_T = np.zeros(n_dof)
        H_N[i : i + 3] = (n[0], n[1], cross2(rho, n))
        H_T[i : i + 3] = (t[0], t[1], cross2(rho, t))
        # d/dt (ρ × n) = −θ̇ (d · n): the lever arm turns with the body, the line does not.
        drift_N = -om * om * (d[0] * n[0] + d[1] * n[1])
        drift_T = -om * om * (d[0] * t[0] + d[1] * t[1])
        return ContactKinematics(gap, H_N, H_T, drift_N, drift_T, self.line.velocity)


def PointOnLine(body: int, offset, line: Line | None = None, law: ContactLaw | None = None, name="corner"):
    """A body-fixed point (a corner) touching a line: a disk of radius zero."""
    return DiskOnLine(body, tuple(offset), line or Line(), 0.0, law or ContactLaw(), name)


@dataclass
class DiskOnDisk:
    """Disk `offset_a`/`radius_a` of body a against disk `offset_b`/`radius_b` of body b.

    The normal points from b's disk centre to a's; the tangent is the normal turned by −90°.
    """

    body_a: int
    body_b: int
    radius_a: float
    radius_b: float
    offset_a: tuple[float, float] = (0.0, 0.0)
    offset_b: tuple[float, float] = (0.0, 0.0)
    law: ContactLaw = field(default_factory=ContactLaw)
    name: str = "disk-disk"

    def __post_init__(self):
        self.name = _contact_name(self.name)
        self.body_a = require_index(f"contact {self.name!r} body_a", self.body_a)
        self.body_b = require_index(f"contact {self.name!r} body_b", self.body_b)
        self.radius_a = require_nonnegative(f"contact {self.name!r} radius_a", self.radius_a)
        self.radius_b = require_nonnegative(f"contact {self.name!r} radius_b", self.radius_b)
        self.offset_a = require_point(f"contact {self.name!r} offset_a", self.offset_a)
        self.offset_b = require_point(f"contact {self.name!r} offset_b", self.offset_b)
        _require_type(f"contact {self.name!r} law", self.law, ContactLaw)
        if self.body_a == self.body_b:
            raise InputError(f"contact {self.name!r}: a disk–disk contact joins two different bodies, "
                             f"got body_a = body_b = {self.body_a}")

    @property
    def bodies(self) -> tuple[int, ...]:
        return (self.body_a, self.body_b)

    def kinematics(self, q: np.ndarray, v: np.ndarray, n_dof: int) -> ContactKinematics:
        ia, ib = 3 * self.body_a, 3 * self.body_b
        da = rotate(q[ia + 2], self.offset_a)
        db = rotate(q[ib + 2], self.offset_b)
        ca = (q[ia] + da[0], q[ia + 1] + da[1])
        cb = (q[ib] + db[0], q[ib + 1] + db[1])
        dx, dy = ca[0] - cb[0], ca[1] - cb[1]
        dist = math.hypot(dx, dy)
        if dist == 0.0:
            raise InputError(f"{self.name}: disk centres coincide, the contact normal is undefined")
        n = (dx / dist, dy / dist)
        t = (n[1], -n[0])
        gap = dist - self.radius_a - self.radius_b
        rho_a = (da[0] - self.radius_a * n[0], da[1] - self.radius_a * n[1])
        rho_b = (db[0] + self.radius_b * n[0], db[1] + self.radius_b * n[1])
        H_N = np.zeros(n_dof)
        H_T = np.zeros(n_dof)
        H_N[ia : ia + 3] += (n[0], n[1], cross2(rho_a, n))
        H_N[ib : ib + 3] -= (n[0], n[1], cross2(rho_b, n))
        H_T[ia : ia + 3] += (t[0], t[1], cross2(rho_a, t))
        H_T[ib : ib + 3] -= (t[0], t[1], cross2(rho_b, t))
        # g̈ = H_N a + Ḣ_N v: the centres' centripetal accelerations along n, plus the turn of
        # n itself, ṅ·w = |w_⊥|²/dist for the relative velocity w of the centres. (Moreau–Jean
        # uses it for its activation margin and impact-time root; the event-driven integrator
        # takes no disk–disk contacts, so the tangential term is left at zero.)
        om_a, om_b = v[ia + 2], v[ib + 2]
        w = (v[ia] - om_a * da[1] - v[ib] + om_b * db[1], v[ia + 1] + om_a * da[0] - v[ib + 1] - om_b * db[0])
        w_n = w[0] * n[0] + w[1] * n[1]
        drift_N = (-om_a * om_a * (da[0] * n[0] + da[1] * n[1]) + om_b * om_b * (db[0] * n[0] + db[1] * n[1])
                   + (w[0] * w[0] + w[1] * w[1] - w_n * w_n) / dist)
        return ContactKinematics(gap, H_N, H_T, drift_N, 0.0, 0.0)
