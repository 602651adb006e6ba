"""A row of dominoes on a floor, the first pushed: the contacts are found from the rectangles.

The closed form is the first domino's tipping threshold. A push (a horizontal impulse J at
height z on its back face) that leaves its front bottom corner stuck sets it turning about that
corner at

    ω = J z / I_c,        I_c = m (b² + h²) / 3 + m (b² + h²) = 4/3 m (b² + h²)

(angular momentum about the corner; half-width b, half-height h, mass m). Turning about the
corner, its centre of mass rises from h to R = √(b² + h²) when it passes over the corner:

    ½ I_c ω*² = m g (R − h)   ⇒   J* = I_c ω* / z.

Below J* it rocks back, having tilted by at most φ = α − acos((h + (J/J*)² (R − h)) / R), α =
atan(b/h); above it, it topples into the next one, and so on down the row.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.body import RigidBody
from ..model.collision import PairLaws, Polygon, find_contacts
from ..model.contacts import Line
from ..model.laws import ContactLaw
from ..model.scene import Scene
from ..model.shapes import rectangle_inertia
from ..validation import InputError, require_friction_pair, require_positive
from .common import G


@dataclass(frozen=True)
class Dominoes:
    """`n` dominoes (thickness × height, `mass`) standing on a floor `pitch` apart (centre to
    centre), the first one (d0, on the left) pushed to the right by an impulse `push` (N s; its
    fraction of the tipping impulse with `push_ratio`) at height `push_height` on its back face.
    Friction μs/μd on the floor and between dominoes, no bounce (e = 0). Each domino collides
    with the floor and its two neighbours only: a falling domino comes to rest on the next one,
    which stands between it and the rest of the row (`model.collision.deepest_overlap` checks
    over a run that no pair of dominoes overlaps, neighbours or not)."""

    n: int = 20
    thickness: float = 0.01
    height: float = 0.05
    pitch: float = 0.03
    mass: float = 0.01
    push_ratio: float = 1.1
    push_height: float = 0.04
    mu_floor: float = 0.6
    mu_dominoes: float = 0.3
    g: float = G

    def __post_init__(self):
        if isinstance(self.n, bool) or not isinstance(self.n, int) or self.n < 1:
            raise InputError(f"n (dominoes) must be a whole number ≥ 1, got {self.n!r}")
        for name in ("thickness", "height", "pitch", "mass", "push_height", "g"):
            require_positive(name, getattr(self, name))
        if not 0.0 < self.pitch - self.thickness < self.height:
            raise InputError(f"pitch: the gap between dominoes ({self.pitch - self.thickness:g} m) must be between 0 "
                             f"and the height ({self.height:g} m): each falls onto the next")
        if not 0.0 < self.push_height <= self.height:
            raise InputError(f"push_height must be on the domino's back face (0, {self.height:g}], "
                             f"got {self.push_height!r}")
        if not (math.isfinite(self.push_ratio) and self.push_ratio >= 0.0):
            raise InputError(f"push_ratio must be a number ≥ 0, got {self.push_ratio!r}")
        require_friction_pair(self.mu_floor, self.mu_floor)
        require_friction_pair(self.mu_dominoes, self.mu_dominoes)

    @property
    def corner_inertia(self) -> float:
        """I_c: the domino's moment of inertia about a bottom corner."""
        b, h = self.thickness / 2, self.height / 2
        return 4.0 / 3.0 * self.mass * (b * b + h * h)

    @property
    def tipping_rate(self) -> float:
        """ω*: the least rate of turn about the front corner that carries the centre of mass over it."""
        b, h = self.thickness / 2, self.height / 2
        return math.sqrt(2.0 * self.mass * self.g * (math.hypot(b, h) - h) / self.corner_inertia)

    @property
    def tipping_impulse(self) -> float:
        """J* = I_c ω* / z."""
        return self.corner_inertia * self.tipping_rate / self.push_height

    @property
    def push(self) -> float:
        return self.push_ratio * self.tipping_impulse

    def largest_tilt(self) -> float:
        """φ: how far the first domino tilts before rocking back (below the threshold)."""
        if self.push_ratio >= 1.0:
            raise InputError("largest_tilt: the first domino topples at push_ratio ≥ 1")
        b, h = self.thickness / 2, self.height / 2
        radius = math.hypot(b, h)
        return math.atan2(b, h) - math.acos((h + self.push_ratio ** 2 * (radius - h)) / radius)

    def names(self) -> list[str]:
        return [f"d{k}" for k in range(self.n)]

    def shapes(self) -> dict:
        box = Polygon.rectangle(self.thickness, self.height)
        return {name: box for name in self.names()}

    def scene(self) -> Scene:
        names = self.names()
        inertia = rectangle_inertia(self.mass, self.thickness, self.height)
        bodies = [RigidBody(self.mass, inertia, name=name) for name in names]
        laws = PairLaws([("*", "floor", ContactLaw.of(self.mu_floor, self.mu_floor, 0.0))],
                        default=ContactLaw.of(self.mu_dominoes, self.mu_dominoes, 0.0))
        never = [(a, b) for i, a in enumerate(names) for b in names[i + 2:]]
        contacts = find_contacts(bodies, self.shapes(), {"floor": Line()}, laws, never=never)
        return Scene(bodies, contacts, gravity=self.g)

    def initial_state(self):
        """Standing in a row from x = 0; the first turning about its front corner at ω = J z / I_c."""
        q0 = np.zeros(3 * self.n)
        q0[0::3] = self.pitch * np.arange(self.n)
        q0[1::3] = self.height / 2
        omega = self.push * self.push_height / self.corner_inertia
        v0 = np.zeros(3 * self.n)
        # the centre at (−b, h) from the corner, turning clockwise (θ̇ = −ω): velocity ω (h, b)
        v0[0:3] = omega * self.height / 2, omega * self.thickness / 2, -omega
        return q0, v0

    def fallen(self, q) -> np.ndarray:
        """Which dominoes have their centre of mass past their front corner (tilt beyond atan(b/h))
        at the configuration q."""
        return -np.asarray(q)[2::3] > math.atan2(self.thickness, self.height)


__all__ = ["Dominoes"]
