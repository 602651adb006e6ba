"""Bodies on shaken obstacles: Housner's block on a floor shaken horizontally, a ball on a plate
shaken vertically (model/motion.py's driven obstacles)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.body import RigidBody
from ..model.contacts import DiskOnLine, Line
from ..model.laws import ContactLaw
from ..model.motion import Harmonic
from ..model.scene import Scene
from ..validation import require_nonnegative, require_positive
from .common import G, _corners, _rectangle_inertia


def _onset(threshold: float, amplitude: float, omega: float) -> float | None:
    """The first t > 0 at which a floor moving as A sin(ωt) accelerates by `threshold` in
    magnitude (|−Aω² sin ωt| = threshold), or None if its peak Aω² stays below."""
    peak = amplitude * omega * omega
    return None if peak <= threshold else math.asin(threshold / peak) / omega


@dataclass(frozen=True)
class ShakenBlock:
    """A uniform block (half-width b, half-height c) at rest on a floor moving as x = A sin(2π f t)
    (Housner's earthquake problem). In the floor's frame the block feels −m a_floor at its centre:
    it holds while |a_floor| ≤ μs g (friction) and |a_floor| c ≤ g b (the moment about a corner);
    it slides first when μs < b/c and the floor's peak acceleration Aω² exceeds μs g, it rocks
    first when b/c < μs and Aω² exceeds g b/c — at the first time |a_floor| reaches that."""

    half_width: float = 0.1
    half_height: float = 0.3
    mu_s: float = 0.5
    mu_d: float | None = None  # default: μs
    amplitude: float = 0.02
    frequency_hz: float = 2.0
    mass: float = 1.0
    g: float = G

    def __post_init__(self):
        for name in ("half_width", "half_height", "mass", "g", "amplitude", "frequency_hz"):
            require_positive(name, getattr(self, name))
        require_nonnegative("mu_s", self.mu_s)

    @property
    def omega(self) -> float:
        return 2.0 * math.pi * self.frequency_hz

    @property
    def peak_acceleration(self) -> float:
        return self.amplitude * self.omega ** 2

    @property
    def floor(self) -> Line:
        return Line(motion=Harmonic((self.amplitude, 0.0), self.frequency_hz))

    def floor_acceleration(self, t):
        return -self.peak_acceleration * np.sin(self.omega * np.asarray(t))

    @property
    def first_motion(self) -> str:
        """'hold', 'slide' or 'rock': what the block does first."""
        slide, rock = self.mu_s * self.g, self.g * self.half_width / self.half_height
        if self.peak_acceleration <= min(slide, rock):
            return "hold"
        return "slide" if slide < rock else "rock"

    @property
    def onset_time(self) -> float | None:
        """When it starts to slide or rock (closed form), None if it holds."""
        threshold = min(self.mu_s * self.g, self.g * self.half_width / self.half_height)
        return _onset(threshold, self.amplitude, self.omega)

    def scene(self) -> Scene:
        w, hgt = 2 * self.half_width, 2 * self.half_height
        body = RigidBody(self.mass, _rectangle_inertia(self.mass, w, hgt), name="block")
        law = ContactLaw.of(self.mu_s, self.mu_s if self.mu_d is None else self.mu_d, 0.0)
        return Scene([body], _corners(0, w, hgt, self.floor, law), gravity=self.g)

    def initial_state(self):
        """At rest on the floor, moving with it (the floor's velocity at t = 0 is Aω)."""
        return np.array([0.0, self.half_height, 0.0]), np.array([self.amplitude * self.omega, 0.0, 0.0])


@dataclass(frozen=True)
class BallOnShakenPlate:
    """A ball (radius r) resting on a plate moving as y = A sin(2π f t): it stays on while the
    plate's acceleration −Aω² sin ωt exceeds −g, so always when Aω² < g; otherwise it lifts off at
    the first t with sin ωt = g/(Aω²)."""

    radius: float = 0.05
    amplitude: float = 0.01
    frequency_hz: float = 8.0
    mass: float = 1.0
    g: float = G

    def __post_init__(self):
        for name in ("radius", "amplitude", "frequency_hz", "mass", "g"):
            require_positive(name, getattr(self, name))

    @property
    def omega(self) -> float:
        return 2.0 * math.pi * self.frequency_hz

    @property
    def liftoff_time(self) -> float | None:
        return _onset(self.g, self.amplitude, self.omega)

    def scene(self) -> Scene:
        plate = Line(motion=Harmonic((0.0, self.amplitude), self.frequency_hz))
        ball = RigidBody(self.mass, 0.4 * self.mass * self.radius ** 2, name="ball")
        return Scene([ball], [DiskOnLine(0, (0.0, 0.0), plate, self.radius, ContactLaw(), name="plate")],
                     gravity=self.g)

    def initial_state(self):
        return np.array([0.0, self.radius, 0.0]), np.array([0.0, self.amplitude * self.omega, 0.0])
