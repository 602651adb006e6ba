"""A slider-crank whose slider rubs its guide, with or without clearance (after Flores, Leine &
Glocker, "Modeling and analysis of planar rigid multibody systems with translational clearance
joints based on the non-smooth dynamics approach", Multibody Syst. Dyn. 23, 2010).

A crank (a uniform bar of length r with a flywheel's inertia) pinned to the world at the origin
by one end; a connecting rod (uniform, length l) pinned to the crank's free end and to the centre
of a slider; the slider a box (width w, height b) in a horizontal guide — two walls, the lower
at y = −(b + δ)/2 and the upper at y = +(b + δ)/2, δ the clearance — touching them by its four
corners (point contacts with friction μ and restitution e: two on each wall). A constant torque
may drive the crank.

Closed form (δ = 0, μ = 0: a rigid slider-crank): the slider's centre stays on the guide's axis
at x(φ) = r cos φ + √(l² − r² sin² φ), φ the crank's angle. With clearance the slider is
free between the walls: the rod's thrust (its vertical part changes sign with the crank's
angle) throws it from one wall to the other — the contact switches Flores et al. study. The
parameters are of their example's kind (a small, fast mechanism), not their published values.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.body import RigidBody
from ..model.contacts import Line, PointOnLine
from ..model.forces import Torque
from ..model.joints import Pin
from ..model.laws import ContactLaw
from ..model.scene import Scene
from ..model.shapes import rectangle_inertia
from ..results import SimulationResult
from ..validation import InputError, require_nonnegative, require_positive
from .common import G

CRANK, ROD, SLIDER = 0, 1, 2
LOWER_CORNERS, UPPER_CORNERS = ("lower-left", "lower-right"), ("upper-left", "upper-right")


@dataclass(frozen=True)
class SliderCrank:
    """The mechanism, the crank starting at angle `crank_angle` turning at `crank_speed` (rad/s),
    the slider centred in its guide, level."""

    crank_length: float = 0.05
    rod_length: float = 0.12
    crank_mass: float = 0.3
    crank_inertia: float = 1e-3  # about its centre of mass: the crank with its flywheel, kg m²
    rod_mass: float = 0.2
    slider_mass: float = 0.15
    slider_width: float = 0.05
    slider_height: float = 0.05
    clearance: float = 0.0  # δ: guide height − slider height
    mu: float = 0.0
    restitution: float = 0.0
    crank_speed: float = 2 * math.pi * 20  # rad/s at the start (1200 rpm)
    crank_angle: float = 0.0
    torque: float = 0.0  # constant torque on the crank, N m
    g: float = G

    def __post_init__(self):
        for name in ("crank_length", "rod_length", "crank_mass", "crank_inertia", "rod_mass", "slider_mass",
                     "slider_width", "slider_height"):
            require_positive(name, getattr(self, name))
        for name in ("clearance", "mu", "restitution", "g"):
            require_nonnegative(name, getattr(self, name))
        if not self.rod_length > self.crank_length:
            raise InputError(f"rod_length must exceed crank_length ({self.crank_length:g} m) for the crank to "
                             f"turn fully, got {self.rod_length:g}")

    def slider_position(self, phi):
        """x(φ) of the rigid mechanism (δ = 0): the slider's centre for crank angle φ."""
        r, l = self.crank_length, self.rod_length
        s = r * np.sin(phi)
        return r * np.cos(phi) + np.sqrt(l * l - s * s)

    def _placement(self, phi, omega):
        """(q, v) of the rigid mechanism at crank angle φ and rate ω (the slider level, on the axis)."""
        r, l = self.crank_length, self.rod_length
        crank = (0.5 * r * math.cos(phi), 0.5 * r * math.sin(phi))
        pin = (r * math.cos(phi), r * math.sin(phi))
        beta = -math.asin(pin[1] / l)  # the rod's angle: its far end on y = 0
        x = float(self.slider_position(phi))
        # rates: ẏ_pin + l cos β β̇ = 0 and ẋ = ẋ_pin − l sin β β̇
        dpin = (-r * math.sin(phi) * omega, r * math.cos(phi) * omega)
        dbeta = -dpin[1] / (l * math.cos(beta))
        dx = dpin[0] - l * math.sin(beta) * dbeta
        rod = (pin[0] + 0.5 * l * math.cos(beta), pin[1] + 0.5 * l * math.sin(beta))
        drod = (dpin[0] - 0.5 * l * math.sin(beta) * dbeta, dpin[1] + 0.5 * l * math.cos(beta) * dbeta)
        q = np.array([*crank, phi, *rod, beta, x, 0.0, 0.0])
        v = np.array([-0.5 * r * math.sin(phi) * omega, 0.5 * r * math.cos(phi) * omega, omega,
                      *drod, dbeta, dx, 0.0, 0.0])
        return q, v

    def initial_state(self):
        return self._placement(self.crank_angle, self.crank_speed)

    def scene(self) -> Scene:
        r, l, w, b = self.crank_length, self.rod_length, self.slider_width, self.slider_height
        bodies = [RigidBody(self.crank_mass, self.crank_inertia, name="crank"),
                  RigidBody(self.rod_mass, self.rod_mass * l * l / 12, name="rod"),
                  RigidBody(self.slider_mass, rectangle_inertia(self.slider_mass, w, b), name="slider")]
        half_gap = 0.5 * (b + self.clearance)
        lower, upper = Line((0.0, -half_gap), 0.0), Line((0.0, half_gap), math.pi)  # normals +y, −y
        law = ContactLaw.of(self.mu, self.mu, self.restitution)
        contacts = [PointOnLine(SLIDER, (sx * w / 2, -b / 2), lower, law, name=name)
                    for sx, name in zip((-1, 1), LOWER_CORNERS)]
        contacts += [PointOnLine(SLIDER, (sx * w / 2, b / 2), upper, law, name=name)
                     for sx, name in zip((-1, 1), UPPER_CORNERS)]
        joints = [Pin(CRANK, (-r / 2, 0.0), None, (0.0, 0.0), name="main-bearing"),
                  Pin(ROD, (-l / 2, 0.0), CRANK, (r / 2, 0.0), name="crank-pin"),
                  Pin(ROD, (l / 2, 0.0), SLIDER, (0.0, 0.0), name="wrist-pin")]
        forces = [Torque(CRANK, self.torque, name="drive")] if self.torque else []
        return Scene(bodies, contacts, gravity=self.g, joints=joints, forces=forces)

    @property
    def energy_at_start(self) -> float:
        """Kinetic plus gravitational energy of the initial state (J)."""
        q, v = self.initial_state()
        return float(self._energy(q[None, :], v[None, :])[0])

    def energy(self, result: SimulationResult) -> np.ndarray:
        """Kinetic plus gravitational energy of the three bodies at every sample (J)."""
        return self._energy(result.trajectory.q, result.trajectory.v)

    def _energy(self, q, v) -> np.ndarray:
        masses = np.array([self.crank_mass, self.rod_mass, self.slider_mass])
        inertias = np.array([b.inertia for b in self.scene().bodies])
        kinetic = 0.5 * (masses * (v[:, 0::3] ** 2 + v[:, 1::3] ** 2) + inertias * v[:, 2::3] ** 2).sum(axis=1)
        return kinetic + self.g * (masses * q[:, 1::3]).sum(axis=1)


def wall_switches(result: SimulationResult, threshold: float = 0.0) -> list[tuple[float, str]]:
    """(t, "lower" | "upper"): each time the slider's load passes from one wall to the other — the
    first sample at which one wall's corners carry a normal force above `threshold` (N) after the
    other wall's did."""
    names = result.contact_names
    force = result.trajectory.normal_force
    lower = force[:, [names.index(n) for n in LOWER_CORNERS]].sum(axis=1) > threshold
    upper = force[:, [names.index(n) for n in UPPER_CORNERS]].sum(axis=1) > threshold
    switches, wall = [], None
    for t, on_lower, on_upper in zip(result.t, lower, upper):
        now = "lower" if on_lower and not on_upper else "upper" if on_upper and not on_lower else wall
        if now != wall and wall is not None:
            switches.append((float(t), now))
        wall = now
    return switches
