"""Bodies at rest on more contacts than statics needs: a ladder against a wall, a rod wedged
between two walls, a pyramid of three disks.

Their contact forces at rest are not unique (the ladder, the wedge) or the step's Delassus matrix
is singular, so a time-stepping scheme must choose; each toy states when the static
coefficients can hold it (docs/friction.md, "Statically indeterminate contacts").
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.body import RigidBody
from ..model.contacts import DiskOnDisk, DiskOnLine, Line, PointOnLine
from ..model.laws import ContactLaw
from ..model.scene import Scene
from ..validation import require_friction_pair, require_in_range, require_positive
from .common import G


@dataclass(frozen=True)
class Ladder:
    """A uniform ladder of length L at angle β to the floor, its top against the wall x = 0,
    released from rest; friction (μs, μd) at the foot (floor) and at the top (wall).

    Holds iff tan β ≥ (1 − μ1 μ2) / (2 μ1) with the static coefficients (μ1 floor, μ2 wall).
    """

    angle: float = math.radians(60.0)
    mu_floor: float = 0.3
    mu_floor_d: float = 0.24
    mu_wall: float = 0.1
    mu_wall_d: float = 0.08
    length: float = 3.0
    mass: float = 1.0
    g: float = G

    def __post_init__(self):
        require_in_range("ladder angle", self.angle, 0.0, math.pi / 2, open_lo=True, open_hi=True)
        require_friction_pair(self.mu_floor, self.mu_floor_d)
        require_friction_pair(self.mu_wall, self.mu_wall_d)
        for name in ("length", "mass", "g"):
            require_positive(name, getattr(self, name))

    def critical_angle(self) -> float:
        """The least angle at which the ladder holds."""
        return math.atan2(1.0 - self.mu_floor * self.mu_wall, 2.0 * self.mu_floor)

    def holds(self) -> bool:
        return math.tan(self.angle) >= (1.0 - self.mu_floor * self.mu_wall) / (2.0 * self.mu_floor)

    def scene(self) -> Scene:
        half = self.length / 2
        floor = Line((0.0, 0.0), 0.0)
        wall = Line((0.0, 0.0), math.pi / 2)  # normal −x: the ladder stands at x < 0
        contacts = [PointOnLine(0, (-half, 0.0), floor, ContactLaw.of(self.mu_floor, self.mu_floor_d), "foot"),
                    PointOnLine(0, (half, 0.0), wall, ContactLaw.of(self.mu_wall, self.mu_wall_d), "top")]
        body = RigidBody(self.mass, self.mass * self.length**2 / 12, "ladder")
        return Scene([body], contacts, gravity=self.g)

    def initial_state(self):
        half, b = self.length / 2, self.angle
        return np.array([-half * math.cos(b), half * math.sin(b), b]), np.zeros(3)

    def release_acceleration(self) -> float:
        """β̈ at release when it cannot hold: foot sliding away, top sliding down, both with μd
        (m ẍ = −N2 + μ1d N1, m ÿ = N1 + μ2d N2 − m g, J β̈ = torques, ẍ, ÿ = (L/2) β̈ (sin β, cos β))."""
        m, half, b = self.mass, self.length / 2, self.angle
        J = m * self.length**2 / 12
        s, c = math.sin(b), math.cos(b)
        m1, m2 = self.mu_floor_d, self.mu_wall_d
        # unknowns (β̈, N1, N2)
        A = np.array([[m * half * s, -m1, 1.0],
                      [m * half * c, -1.0, -m2],
                      [J, half * (c - m1 * s), -half * (m2 * c + s)]])
        rhs = np.array([0.0, -m * self.g, 0.0])
        return float(np.linalg.solve(A, rhs)[0])


@dataclass(frozen=True)
class WedgedRod:
    """A rod of length L wedged at angle φ between the walls x = ±(L/2) cos φ, released from rest,
    the same (μs, μd) on both walls. Holds iff μs > tan φ (any compression then holds it: the
    normal forces are indeterminate); otherwise it falls freely, the walls pressing on nothing."""

    angle: float = math.radians(30.0)
    mu_s: float = 0.7
    mu_d: float = 0.5
    length: float = 1.0
    mass: float = 1.0
    g: float = G

    def __post_init__(self):
        require_in_range("rod angle", self.angle, 0.0, math.pi / 2, open_lo=True, open_hi=True)
        require_friction_pair(self.mu_s, self.mu_d)
        for name in ("length", "mass", "g"):
            require_positive(name, getattr(self, name))

    def holds(self) -> bool:
        return self.mu_s > math.tan(self.angle)

    def scene(self) -> Scene:
        half, d = self.length / 2, self.length * math.cos(self.angle) / 2
        law = ContactLaw.of(self.mu_s, self.mu_d)
        contacts = [PointOnLine(0, (-half, 0.0), Line((-d, 0.0), -math.pi / 2), law, "left"),
                    PointOnLine(0, (half, 0.0), Line((d, 0.0), math.pi / 2), law, "right")]
        body = RigidBody(self.mass, self.mass * self.length**2 / 12, "rod")
        return Scene([body], contacts, gravity=self.g)

    def initial_state(self):
        return np.array([0.0, 0.0, self.angle]), np.zeros(3)


@dataclass(frozen=True)
class DiskPyramid:
    """Two disks on the floor, centres 2 s r apart, a third resting on both; one (μs, μd) between
    the disks, another on the floor. With θ the angle of the upper contacts' normals to the
    vertical (sin θ = s / 2), statics gives at the upper contacts |T|/N = tan(θ/2) and on the floor
    |T|/N = tan(θ/2)/3: the pyramid holds iff μs_disks ≥ tan(θ/2) and μs_floor ≥ tan(θ/2)/3."""

    spread: float = 1.2
    mu_disks: float = 0.4
    mu_disks_d: float = 0.3
    mu_floor: float = 0.4
    mu_floor_d: float = 0.3
    radius: float = 0.1
    mass: float = 1.0
    g: float = G

    def __post_init__(self):
        require_in_range("spread", self.spread, 1.0, 2.0, open_hi=True)
        require_friction_pair(self.mu_disks, self.mu_disks_d)
        require_friction_pair(self.mu_floor, self.mu_floor_d)
        for name in ("radius", "mass", "g"):
            require_positive(name, getattr(self, name))

    def half_angle_tangent(self) -> float:
        """tan(θ/2): the friction ratio statics needs at the upper contacts."""
        sin = self.spread / 2
        return sin / (1.0 + math.sqrt(1.0 - sin * sin))

    def holds(self) -> bool:
        need = self.half_angle_tangent()
        return self.mu_disks >= need and self.mu_floor >= need / 3

    def scene(self) -> Scene:
        r = self.radius
        floor_law = ContactLaw.of(self.mu_floor, self.mu_floor_d)
        disk_law = ContactLaw.of(self.mu_disks, self.mu_disks_d)
        contacts = [DiskOnLine(0, (0.0, 0.0), Line(), r, floor_law, "floor-left"),
                    DiskOnLine(1, (0.0, 0.0), Line(), r, floor_law, "floor-right"),
                    DiskOnDisk(2, 0, r, r, law=disk_law, name="top-left"),
                    DiskOnDisk(2, 1, r, r, law=disk_law, name="top-right")]
        bodies = [RigidBody(self.mass, self.mass * r * r / 2, f"disk-{k}") for k in range(3)]
        return Scene(bodies, contacts, gravity=self.g)

    def initial_state(self):
        r, s = self.radius, self.spread
        top = r + math.sqrt(4 * r * r - (s * r) ** 2)
        return np.array([-s * r, r, 0.0, s * r, r, 0.0, 0.0, top, 0.0]), np.zeros(9)


__all__ = ["Ladder", "WedgedRod", "DiskPyramid"]
