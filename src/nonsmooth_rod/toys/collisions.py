"""Collisions of balls in a row: two-ball impacts and the three-ball cradle."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.body import RigidBody
from ..model.contacts import DiskOnDisk
from ..model.laws import ContactLaw
from ..model.scene import Scene
from ..results import SimulationResult
from ..validation import InputError, require_in_range, require_positive


@dataclass(frozen=True)
class BallRow:
    """Balls on the x axis without gravity, ball i of mass m_i and radius r_i, separated by
    `gaps` (surface to surface), moving with `velocities`; every neighbouring pair is a
    disk–disk contact with restitution e (frictionless).

    Two balls: the closed form of a central collision. Three equal touching balls struck by one:
    Moreau's simultaneous impact law gives (−1/3, 2/3, 2/3) v for e = 1, where experiments
    (Newton's cradle) show (0, 0, v); with gaps between them the impacts are sequential and the
    pairwise law gives (0, 0, v).
    """

    masses: tuple = (1.0, 1.0)
    radii: tuple = (0.05, 0.05)
    gaps: tuple = (0.1,)
    velocities: tuple = (1.0, 0.0)
    restitution: float = 1.0

    def __post_init__(self):
        n = len(self.masses)
        if n < 2 or len(self.radii) != n or len(self.velocities) != n or len(self.gaps) != n - 1:
            raise InputError("a ball row needs n ≥ 2 masses, radii, velocities and n − 1 gaps")
        for m in self.masses:
            require_positive("ball mass", m)
        for r in self.radii:
            require_positive("ball radius", r)
        for gap in self.gaps:
            if gap < 0:
                raise InputError(f"gaps between balls must be non-negative, got {gap!r}")
        require_in_range("restitution", self.restitution, 0.0, 1.0)

    @classmethod
    def cradle(cls, n: int = 3, speed: float = 1.0, approach_gap: float = 0.05, gap: float = 0.0,
               restitution: float = 1.0, radius: float = 0.05, mass: float = 1.0) -> "BallRow":
        """Newton's cradle: ball 0 at `speed` towards n − 1 balls at rest, `gap` apart."""
        return cls((mass,) * n, (radius,) * n, (approach_gap,) + (gap,) * (n - 2),
                   (speed,) + (0.0,) * (n - 1), restitution)

    def scene(self) -> Scene:
        bodies = [RigidBody(m, 0.4 * m * r * r, name=f"ball{i}") for i, (m, r) in
                  enumerate(zip(self.masses, self.radii))]
        law = ContactLaw.of(0.0, 0.0, self.restitution)
        contacts = [DiskOnDisk(i + 1, i, self.radii[i + 1], self.radii[i], law=law, name=f"{i}-{i + 1}")
                    for i in range(len(bodies) - 1)]
        return Scene(bodies, contacts, gravity=0.0)

    def initial_state(self):
        n = len(self.masses)
        x = np.zeros(n)
        for i in range(1, n):
            x[i] = x[i - 1] + self.radii[i - 1] + self.gaps[i - 1] + self.radii[i]
        q = np.zeros(3 * n)
        v = np.zeros(3 * n)
        q[0::3] = x
        v[0::3] = self.velocities
        return q, v

    def first_impact_time(self) -> float:
        """When the first pair touches (inf if no pair closes)."""
        times = []
        for i, gap in enumerate(self.gaps):
            closing = self.velocities[i] - self.velocities[i + 1]
            if closing > 0:
                times.append(gap / closing)
            elif gap == 0 and closing == 0:
                continue
        return min(times) if times else math.inf

    def two_ball_outcome(self) -> tuple[float, float]:
        """Velocities after a central collision of two balls (Newton's law, restitution e)."""
        if len(self.masses) != 2:
            raise InputError("two_ball_outcome needs exactly two balls")
        (m1, m2), (v1, v2), e = self.masses, self.velocities, self.restitution
        p = m1 * v1 + m2 * v2
        return ((p - m2 * e * (v1 - v2)) / (m1 + m2), (p + m1 * e * (v1 - v2)) / (m1 + m2))

    def simultaneous_outcome(self) -> np.ndarray:
        """Three equal balls, ball 0 arriving at v on two touching balls at rest, all three
        taking part in one Moreau impact (both pairs in the step's problem at once):
        u⁺ + e u⁻ ≥ 0 ⊥ p ≥ 0 on both pairs gives p₁ = 2 p₂ = 2 (1 + e) m v / 3, so
        v' = ((1 − 2e)/3, (1 + e)/3, (1 + e)/3) v; for e = 1, (−1/3, 2/3, 2/3) v, energy kept."""
        self._require_equal_trio()
        v, e = self.velocities[0], self.restitution
        return np.array([(1 - 2 * e) / 3, (1 + e) / 3, (1 + e) / 3]) * v

    def sequential_outcome(self) -> np.ndarray:
        """The same balls with gaps between them, e = 1: a chain of two-ball collisions, each
        swapping the velocities of equal masses, leaves (0, 0, v) — what a real cradle shows."""
        self._require_equal_trio()
        if self.restitution != 1.0:
            raise InputError("the sequential outcome (0, 0, v) holds for e = 1")
        return np.array([0.0, 0.0, self.velocities[0]])

    def _require_equal_trio(self):
        if len(self.masses) != 3 or len(set(self.masses)) != 1 or any(self.velocities[1:]):
            raise InputError("the cradle outcomes are for three equal balls, the last two at rest")


def ball_velocities(result: SimulationResult) -> np.ndarray:
    """ẋ of every ball at the end of the run."""
    return result.trajectory.v[-1, 0::3].copy()
