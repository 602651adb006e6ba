"""Glocker's woodpecker toy: a sleeve jamming on a pole, a bird on a torsion spring, a beak.

The toy (Pfeiffer & Glocker, *Multibody Dynamics with Unilateral Contacts*, 1996; Glocker's
thesis, TU München 1995, pp. 162 ff.; Leine, Glocker & van Campen 2003) is the benchmark that
Siconos ships as examples/mechanics/Woodpecker (its parameters, WoodPeckerConsts.h, are the
defaults below). A sleeve M (inner radius r_M, half-height h_M) rides on a pole of radius r_O with
a little clearance; a bird S is hinged to it at l_M from the pole's axis by a torsion spring c_φ;
its beak, at (−l_S, h_S) from the bird's centre of mass, pecks the pole. The sleeve tilts until
two of its inner edges jam against the pole (friction μ holds it or lets it slide); the bird
swings, unjams it, it falls a little, the beak hits, the sleeve jams again: a limit cycle going
down the pole.

The published model has three coordinates — the sleeve's height y, its angle φ_M and the bird's
angle φ_S — and is linearised in the angles (constant mass matrix, gaps and contact rows linear
in φ). This toy is its planar rigid-body version with the exact geometry:

* bodies: the sleeve, a carriage and the bird. The published model leaves out the sleeve's
  horizontal motion; here the carriage (a slider along the pole's axis at a fixed angle) carries
  the sleeve's centre by a pin, so the sleeve only moves up and down and turns. The sleeve's mass
  is split between the two (the pin sits at its centre of mass, so the vertical mass is m_M);
* a pin (the hinge) between the sleeve at (l_M, 0) and the bird at (−l_G, 0), with the torsion
  spring c_φ (rest angle 0) between their angles;
* three point contacts on the pole's face x = r_O (a line, normal +x), all with μ: the beak
  (Newton e = 0.5), the sleeve's lower (r_M, −h_M) and upper (r_M, +h_M) inner edges (e = 0) —
  the published model's contacts 1, 2, 3 (one edge per tilt, on the bird's side of the pole,
  as in its contact rows).

What differs from the published (linearised) model is second order in the angles, but the bird
swings to |φ_S| ≈ 0.5 rad: gravity's moment m_S g l_G cos φ_S and the bird's vertical lever
l_G cos φ_S are 12 % below the linearised ones there, and the sleeve jams at 0.1009 rad instead
of (r_M − r_O)/h_M = 0.1034 rad. The limit cycle's period is 11 % shorter and the sleeve never
reaches its upper jam after the beak's impact (docs/joints.md, "Glocker's woodpecker toy";
`toys.woodpecker_reduced` integrates both three-coordinate models independently).

`geometry="linearised"` builds the published model itself from the engine's parts: the same
sleeve, carriage, slider and axle, but the hinge is a `LinearJoint` holding the bird's height at
its linearised value y + l_M φ_M + l_G φ_S (the bird's horizontal position stays put: nothing
pushes it sideways — the published mass matrix leaves its horizontal motion out), and the three
contacts are `LinearRelation`s with the published constant rows (Siconos' WoodPecker.cpp: gaps
l_M + l_G − l_S − r_O − h_S φ_S, r_M − r_O ± h_M φ_M; tangent rows (1, l_M, l_G − l_S), (1, r_M, 0)
over (y, φ_M, φ_S)). It starts from the published `start`, its sleeve on the linearised jam.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.body import RigidBody
from ..model.contacts import LinearRelation, Line, PointOnLine
from ..model.forces import TorsionSpring
from ..model.joints import LinearJoint, Pin, Slider
from ..model.laws import ContactLaw
from ..model.scene import Scene
from ..results import SimulationResult
from ..validation import InputError, require_nonnegative, require_positive
from .common import G

SLEEVE, CARRIAGE, BIRD = 0, 1, 2
CONTACTS = ("beak", "lower", "upper")  # the published model's contacts 1, 2, 3
GEOMETRIES = ("exact", "linearised")


@dataclass(frozen=True)
class Woodpecker:
    """Glocker's woodpecker toy with the published parameters (SI units, angles in radians).

    `start` is the published initial state (y, φ_M, φ_S, ẏ, φ̇_M, φ̇_S): the sleeve jammed on its
    lower edge, sliding down, the bird swinging back (Siconos' WoodPeckerConsts.h). `geometry`:
    "exact" (the planar toy) or "linearised" (the published model: the module's notes)."""

    pole_radius: float = 0.0025  # r_O
    sleeve_radius: float = 0.0031  # r_M: the sleeve's inner radius
    sleeve_half_height: float = 0.0058  # h_M
    hinge_offset: float = 0.010  # l_M: pole axis to the hinge
    bird_offset: float = 0.015  # l_G: hinge to the bird's centre of mass
    beak_height: float = 0.02  # h_S: the beak above the bird's centre of mass
    beak_back: float = 0.0201  # l_S: the beak towards the pole from the bird's centre of mass
    sleeve_mass: float = 0.0003  # m_M
    bird_mass: float = 0.0045  # m_S
    sleeve_inertia: float = 5.0e-9  # J_M
    bird_inertia: float = 7.0e-7  # J_S
    spring_stiffness: float = 0.0056  # c_φ, N m/rad
    mu: float = 0.3
    beak_restitution: float = 0.5
    sleeve_restitution: float = 0.0
    g: float = G
    start: tuple = (0.0, -0.1036, -0.2788, -0.3411, 0.0, -7.4583)
    geometry: str = "exact"

    def __post_init__(self):
        if self.geometry not in GEOMETRIES:
            raise InputError(f"geometry must be one of {', '.join(GEOMETRIES)}, got {self.geometry!r}")
        for name in ("pole_radius", "sleeve_half_height", "hinge_offset", "bird_offset", "beak_height",
                     "sleeve_mass", "bird_mass", "sleeve_inertia", "bird_inertia", "spring_stiffness", "g"):
            require_positive(name, getattr(self, name))
        for name in ("mu", "beak_restitution", "sleeve_restitution"):
            require_nonnegative(name, getattr(self, name))
        if not self.sleeve_radius > self.pole_radius:
            raise InputError(f"sleeve_radius must exceed pole_radius ({self.pole_radius:g} m), "
                             f"got {self.sleeve_radius:g}")
        if len(self.start) != 6 or not all(math.isfinite(x) for x in self.start):
            raise InputError(f"start must be six finite numbers (y, φ_M, φ_S, ẏ, φ̇_M, φ̇_S), got {self.start!r}")

    @property
    def jam_angle(self) -> float:
        """|φ_M| at which an inner edge of the sleeve touches the pole (exact geometry):
        r_M cos φ − h_M sin|φ| = r_O, i.e. R cos(|φ| + α) = r_O with R = |(r_M, h_M)| (the
        linearised model's: (r_M − r_O)/h_M)."""
        r, h = self.sleeve_radius, self.sleeve_half_height
        return math.acos(self.pole_radius / math.hypot(r, h)) - math.atan2(h, r)

    def scene(self) -> Scene:
        half = self.sleeve_mass / 2  # the sleeve's mass, half on its carriage (see the module's notes)
        bodies = [RigidBody(half, self.sleeve_inertia, name="sleeve"),
                  RigidBody(half, self.sleeve_inertia, name="carriage"),
                  RigidBody(self.bird_mass, self.bird_inertia, name="bird")]
        laws = (ContactLaw.of(self.mu, self.mu, self.beak_restitution),
                ContactLaw.of(self.mu, self.mu, self.sleeve_restitution))
        linear = self.geometry == "linearised"
        contacts, hinge = self._linearised_parts(*laws) if linear else self._exact_parts(*laws)
        joints = [Slider(CARRIAGE, (0.0, 0.0), None, (0.0, 0.0), (0.0, 1.0), 0.0, name="guide"),
                  Pin(SLEEVE, (0.0, 0.0), CARRIAGE, (0.0, 0.0), name="axle"), hinge]
        spring = TorsionSpring(BIRD, SLEEVE, self.spring_stiffness, 0.0, name="spring")
        return Scene(bodies, contacts, gravity=self.g, joints=joints, forces=[spring])

    def _exact_parts(self, beak_law, sleeve_law):
        """The contacts on the pole's face and the hinge's pin, exact geometry."""
        pole = Line((self.pole_radius, 0.0), -math.pi / 2)  # the face x = r_O, normal +x
        r, h = self.sleeve_radius, self.sleeve_half_height
        contacts = [PointOnLine(BIRD, (-self.beak_back, self.beak_height), pole, beak_law, name="beak"),
                    PointOnLine(SLEEVE, (r, -h), pole, sleeve_law, name="lower"),
                    PointOnLine(SLEEVE, (r, h), pole, sleeve_law, name="upper")]
        return contacts, Pin(SLEEVE, (self.hinge_offset, 0.0), BIRD, (-self.bird_offset, 0.0), name="hinge")

    def _linearised_parts(self, beak_law, sleeve_law):
        """The published constant contact rows over (y, φ_M, φ_S) = the sleeve's y and θ, the bird's θ
        (Siconos' WoodPecker.cpp), and the hinge linearised: y_bird = y + l_M φ_M + l_G φ_S."""
        lm, lg, ls, hs = self.hinge_offset, self.bird_offset, self.beak_back, self.beak_height
        clearance, hm, r = self.sleeve_radius - self.pole_radius, self.sleeve_half_height, self.sleeve_radius
        contacts = [LinearRelation({BIRD: (0.0, 0.0, -hs)}, lm + lg - ls - self.pole_radius,
                                   {SLEEVE: (0.0, 1.0, lm), BIRD: (0.0, 0.0, lg - ls)}, beak_law, name="beak"),
                    LinearRelation({SLEEVE: (0.0, 0.0, hm)}, clearance, {SLEEVE: (0.0, 1.0, r)}, sleeve_law,
                                   name="lower"),
                    LinearRelation({SLEEVE: (0.0, 0.0, -hm)}, clearance, {SLEEVE: (0.0, 1.0, r)}, sleeve_law,
                                   name="upper")]
        hinge = LinearJoint({BIRD: (0.0, 1.0, -lg), SLEEVE: (0.0, -1.0, -lm)}, 0.0, name="hinge")
        return contacts, hinge

    def state_of(self, y, phi_m, phi_s, dy, omega_m, omega_s):
        """(q, v) of the three bodies for the model's coordinates (y, φ_M, φ_S) and their rates."""
        lm, lg = self.hinge_offset, self.bird_offset
        if self.geometry == "linearised":  # the bird's centre only moves up and down, linearly
            q = np.array([0.0, y, phi_m, 0.0, y, 0.0, lm + lg, y + lm * phi_m + lg * phi_s, phi_s])
            v = np.array([0.0, dy, omega_m, 0.0, dy, 0.0, 0.0, dy + lm * omega_m + lg * omega_s, omega_s])
            return q, v
        bird = (lm * math.cos(phi_m) + lg * math.cos(phi_s), y + lm * math.sin(phi_m) + lg * math.sin(phi_s))
        bird_v = (-lm * math.sin(phi_m) * omega_m - lg * math.sin(phi_s) * omega_s,
                  dy + lm * math.cos(phi_m) * omega_m + lg * math.cos(phi_s) * omega_s)
        q = np.array([0.0, y, phi_m, 0.0, y, 0.0, bird[0], bird[1], phi_s])
        v = np.array([0.0, dy, omega_m, 0.0, dy, 0.0, bird_v[0], bird_v[1], omega_s])
        return q, v

    @property
    def exact_start(self) -> tuple:
        """`start` with the sleeve's angle moved out of the pole onto its exact jam: the published
        φ_M = −0.1036 rad jams the linearised sleeve (at −0.1034) but would sink its lower edge
        16 µm into the pole with the exact geometry (jam at −0.1009)."""
        y, phi_m, *rest = self.start
        return (y, max(phi_m, -self.jam_angle), *rest)

    @property
    def linearised_start(self) -> tuple:
        """`start` with the sleeve's angle on the linearised jam −(r_M − r_O)/h_M = −0.103448 rad: the
        published −0.1036 sinks the lower edge 0.9 µm into the pole, more than a scene file's
        initial overlap tolerance."""
        y, phi_m, *rest = self.start
        return (y, max(phi_m, -(self.sleeve_radius - self.pole_radius) / self.sleeve_half_height), *rest)

    def initial_state(self):
        """`linearised_start` or `exact_start`, by the geometry."""
        return self.state_of(*(self.linearised_start if self.geometry == "linearised" else self.exact_start))

    @staticmethod
    def coordinates(result: SimulationResult) -> np.ndarray:
        """The model's coordinates (y, φ_M, φ_S) at every sample of a run: (n, 3)."""
        return result.trajectory.q[:, [3 * SLEEVE + 1, 3 * SLEEVE + 2, 3 * BIRD + 2]]


@dataclass(frozen=True)
class LimitCycle:
    """What a run of the toy does cycle by cycle, a cycle running from one beak impact to the next.

    `beak_times`: the beak's impacts; `periods`: their differences; `sequences`: per cycle, the
    contacts that close (impacts) in their order, the beak's first; `descents`: the sleeve's
    drop over each cycle (m)."""

    beak_times: np.ndarray
    periods: np.ndarray
    sequences: list
    descents: np.ndarray

    @property
    def mean_speed(self) -> float:
        """The sleeve's mean descent speed over the whole cycles (m/s, positive going down)."""
        return float(np.sum(self.descents) / np.sum(self.periods))


def limit_cycle(result: SimulationResult, times=None, names=None, heights=None) -> LimitCycle:
    """The cycles of a run of the toy (or, with `times`, `names`, `heights`, of any record of
    closings: their times, contact names, and the sleeve's height y at each time)."""
    if times is None:
        times = np.array([i.t for i in result.impacts])
        names = [i.contact for i in result.impacts]
        y = result.trajectory.q[:, 3 * SLEEVE + 1]
        heights = np.interp(times, result.t, y)
    times, heights = np.asarray(times, dtype=float), np.asarray(heights, dtype=float)
    beaks = [k for k, name in enumerate(names) if name == "beak"]
    sequences = [list(names[a:b]) for a, b in zip(beaks, beaks[1:])]
    return LimitCycle(times[beaks], np.diff(times[beaks]), sequences, -np.diff(heights[beaks]))
