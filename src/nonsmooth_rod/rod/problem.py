"""The paper's body: a rod with a steel ball at each end (Alaci et al., Axioms 2024).

Coordinates follow ../shared/paper/notes.md: O is the centre of ball A (the ball that starts
on the plane), θ the angle from +x to the axis A→B, the centre of mass Γ = O + ξ(cos θ, sin θ),
ball B's centre at O + L(cos θ, sin θ). N acts along +y and T along +x on ball A; the slip
velocity of A's contact point is v_C = ẋ_O + r θ̇.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..validation import (
    InputError,
    require_friction_pair,
    require_in_range,
    require_positive,
)
from ..model.body import RigidBody
from ..model.contacts import DiskOnLine, Line
from ..model.laws import ContactLaw
from ..model.shapes import rod_with_balls
from ..model.scene import Scene

PAPER_CASES = {1: (0.12, 0.10), 2: (0.28, 0.20), 3: (0.40, 0.30)}


@dataclass(frozen=True)
class RodGeometry:
    """Two equal balls joined by a solid cylindrical rod, all of one density (SI units)."""

    ball_radius: float = 0.020
    rod_diameter: float = 0.006
    length: float = 0.410  # distance between the ball centres
    density: float = 7800.0

    def __post_init__(self):
        require_positive("ball radius", self.ball_radius)
        require_positive("rod diameter", self.rod_diameter)
        require_positive("length (distance between ball centres)", self.length)
        require_positive("density", self.density)
        if self.rod_diameter >= 2 * self.ball_radius:
            raise InputError(
                f"rod diameter {self.rod_diameter:g} m must be smaller than the ball diameter "
                f"{2 * self.ball_radius:g} m"
            )
        if self.length <= 2 * self.ball_radius:
            raise InputError(
                f"length {self.length:g} m between ball centres must exceed the ball diameter "
                f"{2 * self.ball_radius:g} m (the balls would overlap)"
            )

    def inertial_properties(self) -> tuple[float, float, float]:
        """(M, ξ, J_Γ): the rod counts between the ball surfaces, L − 2r, as in the paper.

        The rod is a solid cylinder about a transverse axis, m (3 R² + ℓ²)/12; the balls are
        solid spheres shifted by L/2 (Steiner). With the paper's data this gives
        M = 0.60436 kg, ξ = 0.205 m, J_Γ = 22.9838e-3 kg m² — the paper prints 22.983e-3.
        """
        mass, inertia = rod_with_balls(self.ball_radius, self.rod_diameter, self.length, self.density)
        return mass, self.length / 2, inertia


@dataclass(frozen=True)
class RodProblem:
    """Everything that defines a run of the paper's system (SI units, angles in radians)."""

    mass: float
    xi: float
    inertia: float
    ball_radius: float
    length: float
    mu_s: float = 0.28
    mu_d: float = 0.20
    theta0: float = math.pi / 3
    restitution: float = 0.0
    g: float = 9.81
    geometry: RodGeometry | None = None

    def __post_init__(self):
        require_positive("mass", self.mass)
        require_positive("xi (distance from ball A's centre to the centre of mass)", self.xi)
        require_positive("inertia", self.inertia)
        require_positive("ball radius", self.ball_radius)
        require_positive("length (distance between ball centres)", self.length)
        require_positive("g", self.g)
        if self.xi >= self.length:
            raise InputError(f"xi = {self.xi:g} m must be smaller than the length {self.length:g} m")
        if self.length <= 2 * self.ball_radius:
            raise InputError(
                f"length {self.length:g} m between ball centres must exceed the ball diameter "
                f"{2 * self.ball_radius:g} m"
            )
        require_in_range("theta0", self.theta0, 0.0, math.pi / 2, open_lo=True, open_hi=True)
        require_in_range("restitution", self.restitution, 0.0, 1.0)
        require_friction_pair(self.mu_s, self.mu_d)

    @classmethod
    def from_geometry(cls, geometry: RodGeometry | None = None, **kwargs) -> "RodProblem":
        geometry = geometry or RodGeometry()
        mass, xi, inertia = geometry.inertial_properties()
        return cls(mass=mass, xi=xi, inertia=inertia, ball_radius=geometry.ball_radius,
                   length=geometry.length, geometry=geometry, **kwargs)

    @classmethod
    def paper(cls, case: int | None = 2, **kwargs) -> "RodProblem":
        """The paper's body, with friction case 1, 2 or 3 (default: case 2, (0.28, 0.20))."""
        if case is not None:
            if case not in PAPER_CASES:
                raise InputError(f"paper case must be 1, 2 or 3, got {case!r}")
            kwargs.setdefault("mu_s", PAPER_CASES[case][0])
            kwargs.setdefault("mu_d", PAPER_CASES[case][1])
        return cls.from_geometry(RodGeometry(), **kwargs)

    def with_friction(self, mu_s: float, mu_d: float) -> "RodProblem":
        return replace(self, mu_s=mu_s, mu_d=mu_d)

    @property
    def theta0_deg(self) -> float:
        return math.degrees(self.theta0)

    def as_params(self) -> dict:
        """Every input in SI units, for summary.json."""
        params = {
            "mu_s": self.mu_s, "mu_d": self.mu_d, "theta0_deg": self.theta0_deg,
            "theta0_rad": self.theta0, "restitution": self.restitution,
            "ball_radius": self.ball_radius, "length": self.length, "mass": self.mass,
            "xi": self.xi, "inertia": self.inertia, "g": self.g,
        }
        if self.geometry is not None:
            params.update(rod_diameter=self.geometry.rod_diameter, density=self.geometry.density)
        return params

    # --- as a scene of the general model --------------------------------------------------
    def scene(self) -> Scene:
        """One body, two disk contacts with the floor y = 0: ball A and ball B."""
        law = ContactLaw.of(self.mu_s, self.mu_d, self.restitution)
        body = RigidBody(self.mass, self.inertia, name="rod")
        floor = Line((0.0, 0.0), 0.0)
        ball_a = DiskOnLine(0, (-self.xi, 0.0), floor, self.ball_radius, law, name="A")
        ball_b = DiskOnLine(0, (self.length - self.xi, 0.0), floor, self.ball_radius, law, name="B")
        return Scene([body], [ball_a, ball_b], gravity=self.g)

    def initial_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Released from rest with ball A on the plane, x_O = 0, axis at θ0."""
        th = self.theta0
        q = np.array([self.xi * math.cos(th), self.ball_radius + self.xi * math.sin(th), th])
        return q, np.zeros(3)

    # --- coordinates of the paper ------------------------------------------------------------
    def ball_a_coordinates(self, q, v):
        """(x_O, y_O, θ), (ẋ_O, ẏ_O, θ̇) from centre-of-mass coordinates."""
        q = np.asarray(q)
        v = np.asarray(v)
        th, om = q[..., 2], v[..., 2]
        c, s = np.cos(th), np.sin(th)
        xo = q[..., 0] - self.xi * c
        yo = q[..., 1] - self.xi * s
        xo_dot = v[..., 0] + self.xi * s * om
        yo_dot = v[..., 1] - self.xi * c * om
        return (xo, yo, th), (xo_dot, yo_dot, om)

    def slip_velocity(self, xo_dot, theta_dot):
        return xo_dot + self.ball_radius * theta_dot
