"""A ball dropped on a floor: impacts, apex heights, the Zeno point."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.body import RigidBody
from ..model.contacts import DiskOnLine, Line
from ..model.laws import ContactLaw
from ..model.scene import Scene
from ..results import SimulationResult
from ..validation import require_in_range, require_positive
from .common import G


@dataclass(frozen=True)
class BouncingBall:
    """A ball dropped from rest, its lowest point `drop_height` above a floor, restitution e.

    Frictionless (nothing tangential happens). Impacts at t_1 = √(2 h0/g) and then every
    2 e^k v_1 / g; they accumulate (Zeno) at t_∞ = t_1 (1 + e)/(1 − e), after which the ball
    rests on the floor.
    """

    drop_height: float = 1.0
    restitution: float = 0.5
    radius: float = 0.05
    mass: float = 1.0
    g: float = G

    def __post_init__(self):
        require_positive("drop height", self.drop_height)
        require_in_range("restitution", self.restitution, 0.0, 1.0, open_hi=True)
        require_positive("radius", self.radius)
        require_positive("mass", self.mass)
        require_positive("g", self.g)

    def scene(self) -> Scene:
        ball = RigidBody(self.mass, 0.4 * self.mass * self.radius**2, name="ball")
        law = ContactLaw.of(0.0, 0.0, self.restitution)
        return Scene([ball], [DiskOnLine(0, (0.0, 0.0), Line(), self.radius, law, name="floor")], gravity=self.g)

    def initial_state(self):
        return np.array([0.0, self.radius + self.drop_height, 0.0]), np.zeros(3)

    @property
    def first_impact_time(self) -> float:
        return math.sqrt(2 * self.drop_height / self.g)

    @property
    def impact_speed(self) -> float:
        return self.g * self.first_impact_time

    def impact_times(self, n: int) -> np.ndarray:
        """Times of the first n impacts."""
        flights = 2 * self.impact_speed / self.g * self.restitution ** np.arange(1, n)
        return self.first_impact_time + np.concatenate([[0.0], np.cumsum(flights)])

    @property
    def zeno_time(self) -> float:
        e = self.restitution
        return self.first_impact_time * (1 + e) / (1 - e)

    def apex_height(self, k: int) -> float:
        """Height of the lowest point at the apex after impact k (k = 0: the release)."""
        return self.restitution ** (2 * k) * self.drop_height


def ball_height(result: SimulationResult, toy: BouncingBall) -> np.ndarray:
    """Gap between ball and floor along the run (negative = penetration)."""
    return result.trajectory.q[:, 1] - toy.radius


def rest_time(result: SimulationResult, toy: BouncingBall, speed_tol: float | None = None) -> float:
    """First time after which the ball stays on the floor at rest (|ẏ| ≤ tol for good)."""
    tol = speed_tol if speed_tol is not None else 1e-9 * toy.impact_speed
    moving = np.nonzero(np.abs(result.trajectory.v[:, 1]) > tol)[0]
    if moving.size == 0:
        return float(result.t[0])
    if moving[-1] + 1 >= len(result.t):
        return math.inf
    return float(result.t[moving[-1] + 1])
