"""A disk (cylinder) rolling or sliding down an incline."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.body import RigidBody
from ..model.contacts import DiskOnLine, Line
from ..model.laws import ContactLaw
from ..model.scene import Scene
from ..validation import require_friction_pair, require_in_range, require_positive
from .common import G


@dataclass(frozen=True)
class DiskOnIncline:
    """A solid disk (J = m R²/2) released from rest on an incline of angle α.

    Rolls without slipping iff tan α ≤ 3 μs, with slope acceleration −(2/3) g sin α;
    otherwise slides with −g (sin α − μd cos α) while its spin grows at 2 μd g cos α / R.
    """

    angle: float = math.radians(30.0)
    mu_s: float = 0.3
    mu_d: float = 0.2
    radius: float = 0.1
    mass: float = 1.0
    g: float = G

    def __post_init__(self):
        require_in_range("incline angle", self.angle, 0.0, math.pi / 2, open_hi=True)
        require_friction_pair(self.mu_s, self.mu_d)
        for name in ("radius", "mass", "g"):
            require_positive(name, getattr(self, name))

    @property
    def line(self) -> Line:
        return Line((0.0, 0.0), self.angle)

    def scene(self) -> Scene:
        disk = RigidBody(self.mass, 0.5 * self.mass * self.radius**2, name="disk")
        law = ContactLaw.of(self.mu_s, self.mu_d, 0.0)
        return Scene([disk], [DiskOnLine(0, (0.0, 0.0), self.line, self.radius, law, name="contact")],
                     gravity=self.g)

    def initial_state(self):
        n = self.line.normal
        return np.array([self.radius * n[0], self.radius * n[1], 0.0]), np.zeros(3)

    @property
    def rolls(self) -> bool:
        return math.tan(self.angle) <= 3 * self.mu_s

    @property
    def slope_acceleration(self) -> float:
        """Acceleration of the centre along the slope's tangent (negative: down the slope)."""
        if self.rolls:
            return -2.0 / 3.0 * self.g * math.sin(self.angle)
        return -self.g * (math.sin(self.angle) - self.mu_d * math.cos(self.angle))

    @property
    def angular_acceleration(self) -> float:
        """θ̈ of the disk (positive = counter-clockwise; rolling down the slope turns it CCW)."""
        if self.rolls:
            return -self.slope_acceleration / self.radius
        return 2 * self.mu_d * self.g * math.cos(self.angle) / self.radius
