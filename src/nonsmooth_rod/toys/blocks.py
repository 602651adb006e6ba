"""Blocks on their two corners: on an incline, and pushed along a floor by a ramped force."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.contacts import Line
from ..model.forces import RampedForce
from ..model.scene import Scene
from ..results import SimulationResult
from ..validation import (
    require_friction_pair,
    require_in_range,
    require_nonnegative,
    require_positive,
)
from .common import G, _block_scene, _slope_coordinate

PUSH_HORIZON = 1e4  # s: the pushed block's ramp grows this long, far beyond any run of it


@dataclass(frozen=True)
class BlockOnIncline:
    """A flat rectangular block on an incline of angle α, at rest or launched up the slope
    at `v0` ≥ 0, two-coefficient friction μs ≥ μd on both bottom corners.

    Sticks iff tan α ≤ μs (from rest); slides down with g (sin α − μd cos α) otherwise.
    Launched up, it decelerates at g (sin α + μd cos α), stops, and stays iff tan α ≤ μs.
    The block is wide and low (width ≫ μ × height) so that it slides without tipping.
    """

    angle: float = math.radians(20.0)
    mu_s: float = 0.5
    mu_d: float = 0.3
    v0: float = 0.0
    width: float = 0.2
    height: float = 0.05
    mass: float = 1.0
    g: float = G

    def __post_init__(self):
        require_in_range("incline angle", self.angle, 0.0, math.pi / 2, open_hi=True)
        require_friction_pair(self.mu_s, self.mu_d)
        require_nonnegative("v0 (launch speed up the slope)", self.v0)
        for name in ("width", "height", "mass", "g"):
            require_positive(name, getattr(self, name))

    @property
    def line(self) -> Line:
        return Line((0.0, 0.0), self.angle)

    def scene(self) -> Scene:
        return _block_scene(self)

    def initial_state(self):
        n, t = self.line.normal, self.line.tangent
        b = self.height / 2
        q = np.array([b * n[0], b * n[1], self.angle])
        v = np.array([self.v0 * t[0], self.v0 * t[1], 0.0])
        return q, v

    @property
    def holds(self) -> bool:
        """Does static friction hold the block at rest on the slope?"""
        return math.tan(self.angle) <= self.mu_s

    @property
    def sliding_down_acceleration(self) -> float:
        """Slope acceleration (signed, along +tangent) while sliding down: −g (sin α − μd cos α)."""
        return -self.g * (math.sin(self.angle) - self.mu_d * math.cos(self.angle))

    @property
    def sliding_up_acceleration(self) -> float:
        """Slope acceleration while sliding up: −g (sin α + μd cos α)."""
        return -self.g * (math.sin(self.angle) + self.mu_d * math.cos(self.angle))

    @property
    def stop_time(self) -> float:
        """When a block launched up the slope comes to rest (0 if not launched)."""
        return self.v0 / -self.sliding_up_acceleration

    def slope_velocity(self, t) -> np.ndarray:
        """Closed-form velocity along the slope: up at v0, stopping, then held or sliding back."""
        t = np.asarray(t, dtype=float)
        ts = self.stop_time
        after = np.zeros_like(t) if self.holds else self.sliding_down_acceleration * (t - ts)
        return np.where(t < ts, self.v0 + self.sliding_up_acceleration * t, after)

    def slope_position(self, t) -> np.ndarray:
        """Closed-form displacement along the slope from the start."""
        t = np.asarray(t, dtype=float)
        ts = self.stop_time
        tc = np.minimum(t, ts)
        up = self.v0 * tc + 0.5 * self.sliding_up_acceleration * tc**2
        if self.holds:
            return up
        return up + 0.5 * self.sliding_down_acceleration * np.maximum(t - ts, 0.0) ** 2


def slope_motion(result: SimulationResult, toy) -> tuple[np.ndarray, np.ndarray]:
    """Displacement and velocity of the centre of mass along the toy's line."""
    return _slope_coordinate(result, toy.line.angle)


@dataclass(frozen=True)
class PushedBlock:
    """A block at rest on a flat floor pushed by a horizontal force F(t) = rate·t.

    It sticks until F = μs m g, at t* = μs m g / rate, then slides with friction μd m g:
    ẍ = (rate·t − μd m g)/m, so its acceleration jumps by (μs − μd) g at the onset.
    The push acts along the floor line (a force through the contact line, applied as the
    force on the centre of mass plus its moment), so the block does not pitch and the two
    corners share the load equally — which makes the onset of each corner simultaneous.
    """

    rate: float = 10.0  # N/s
    mu_s: float = 0.5
    mu_d: float = 0.3
    width: float = 0.2
    height: float = 0.05
    mass: float = 1.0
    g: float = G

    def __post_init__(self):
        require_friction_pair(self.mu_s, self.mu_d)
        for name in ("rate", "width", "height", "mass", "g"):
            require_positive(name, getattr(self, name))

    @property
    def line(self) -> Line:
        return Line()

    def push(self, t: float) -> float:
        """The push rate·t (for t ≤ PUSH_HORIZON)."""
        return self.rate * t

    def scene(self) -> Scene:
        # the push as data (a RampedForce: rate·t up to PUSH_HORIZON seconds) applied at the middle
        # of the bottom face, so the compiled loop evaluates it and the run is one compiled call
        push = RampedForce(0, (self.rate * PUSH_HORIZON, 0.0), point=(0.0, -self.height / 2), t_start=0.0,
                           t_full=PUSH_HORIZON, name="push")
        return _block_scene(self, [push])

    def initial_state(self):
        return np.array([0.0, self.height / 2, 0.0]), np.zeros(3)

    @property
    def onset_time(self) -> float:
        return self.mu_s * self.mass * self.g / self.rate

    def position(self, t) -> np.ndarray:
        dt = np.maximum(np.asarray(t, dtype=float) - self.onset_time, 0.0)
        return self.rate * dt**3 / (6 * self.mass) + 0.5 * (self.mu_s - self.mu_d) * self.g * dt**2

    def velocity(self, t) -> np.ndarray:
        dt = np.maximum(np.asarray(t, dtype=float) - self.onset_time, 0.0)
        return self.rate * dt**2 / (2 * self.mass) + (self.mu_s - self.mu_d) * self.g * dt
