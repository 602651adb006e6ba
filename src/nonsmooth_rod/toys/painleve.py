"""Painlevé's rod: a rod sliding on its end where the Coulomb problem has no or several solutions."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.body import RigidBody
from ..model.contacts import Line, PointOnLine
from ..model.laws import ContactLaw
from ..model.scene import Scene
from ..validation import require_friction_pair, require_in_range, require_positive
from .common import G


@dataclass(frozen=True)
class PainleveRod:
    """A thin uniform rod (length 2a) whose lower end (a point) slides on the floor.

    θ is the angle of the rod from +x; its centre of mass lies at end + a (cos θ, sin θ).
    The sliding equations for the end moving away from the centre of mass (slip velocity < 0)
    lose consistency where J/m + a² cos²θ < μd a² cos θ sin θ: Painlevé's paradox, possible
    only for μd > 4/3 (thin uniform rod, J = m a²/3). The toy launches the end sliding at
    `slip_speed` (< 0) at angle `theta0`, below that band: friction lifts the rod into it
    while the end still slides. (Only the lower end is a contact: keep runs short of the rod
    turning through the floor.)
    """

    half_length: float = 0.5
    theta0: float = math.radians(30.0)
    slip_speed: float = -10.0
    theta_rate: float = 0.0
    mu_s: float = 2.0
    mu_d: float = 2.0
    mass: float = 1.0
    g: float = G

    def __post_init__(self):
        for name in ("half_length", "mass", "g"):
            require_positive(name, getattr(self, name))
        require_in_range("theta0", self.theta0, 0.0, math.pi / 2, open_lo=True, open_hi=True)
        require_friction_pair(self.mu_s, self.mu_d)

    @property
    def inertia(self) -> float:
        return self.mass * self.half_length**2 / 3.0

    def scene(self) -> Scene:
        body = RigidBody(self.mass, self.inertia, name="rod")
        law = ContactLaw.of(self.mu_s, self.mu_d, 0.0)
        return Scene([body], [PointOnLine(0, (-self.half_length, 0.0), Line(), law, name="end")],
                     gravity=self.g)

    def initial_state(self):
        a, th = self.half_length, self.theta0
        q = np.array([a * math.cos(th), a * math.sin(th), th])
        om = self.theta_rate
        # the end stays on the floor (ẏ_end = 0) and slides at slip_speed
        v = np.array([self.slip_speed - a * math.sin(th) * om, a * math.cos(th) * om, om])
        return q, v

    def consistency(self, theta) -> np.ndarray:
        """(J/m + a² cos²θ − μd a² cos θ sin θ)/a²: the normal 'effective inverse mass' of the
        sliding end (slip velocity < 0) times m; ≤ 0 is Painlevé's inconsistent region."""
        th = np.asarray(theta, dtype=float)
        a = self.half_length
        return (self.inertia / self.mass + a**2 * np.cos(th) ** 2
                - self.mu_d * a**2 * np.cos(th) * np.sin(th)) / a**2

    def painleve_band(self) -> tuple[float, float] | None:
        """Angles (θ1, θ2) between which sliding with slip velocity < 0 is inconsistent."""
        # J/(m a²) + c² − μ c s = 0 with J/(m a²) = 1/3; in terms of φ = 2θ:
        # 1/3 + (1 + cos φ)/2 − μ sin φ / 2 = 0  →  cos φ − μ sin φ = −5/3
        mu = self.mu_d
        amp = math.hypot(1.0, mu)
        if 5.0 / 3.0 > amp:
            return None
        phase = math.atan2(mu, 1.0)  # cos φ − μ sin φ = amp cos(φ + phase)
        base = math.acos(-5.0 / 3.0 / amp)
        phis = sorted(((base - phase) % (2 * math.pi), (-base - phase) % (2 * math.pi)))
        return phis[0] / 2, phis[1] / 2

    @staticmethod
    def critical_mu(theta: float, inertia_over_mass_a2: float = 1.0 / 3.0) -> float:
        """Smallest μd that makes sliding (slip velocity < 0) inconsistent at angle θ."""
        c, s = math.cos(theta), math.sin(theta)
        return (inertia_over_mass_a2 + c * c) / (c * s)
