"""Planar contact toys built from the general parts, each with its closed-form answer.

Every toy is a small frozen dataclass holding its physical parameters (SI units, angles in
radians) with

* ``scene()``          — the `Scene` (bodies, contacts, laws, applied forces),
* ``initial_state()``  — (q0, v0), centre-of-mass coordinates (x, y, θ) of every body,
* closed-form answers  — methods named after what they return (``impact_times``,
  ``slope_acceleration``, ``stick_time`` ...),
* measurement helpers — `ball_height`, `rest_time`, `slope_motion`, `first_slip_time`,
  `stick_slip_phases`, `impact_rate_pairs`, `ball_velocities` read the same quantities off a
  `SimulationResult`, so that tests and examples compare like with like.

`run(toy, method, t_end, ...)` runs any toy with Moreau–Jean or the event-driven reference.
The closed forms are those of shared/design/nonsmooth-notes.md ("Closed forms for tests");
docs/toys.md states the measured agreement of each toy.

Conventions: an incline is `Line(angle=α)`, rising to the right; "along the slope" means
along its tangent (cos α, sin α), so a block sliding down has a negative slope velocity.
A block is a rectangle touching its support by its two bottom corners (`PointOnLine`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .integrators.event_driven import EventDriven, EventDrivenOptions
from .integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from .io import atomic_path
from .model.body import RigidBody, cross2, rotate
from .model.contacts import DiskOnDisk, DiskOnLine, Line, PointOnLine
from .model.laws import ContactLaw
from .model.scene import Scene
from .results import SimulationResult
from .validation import (
    InputError,
    require_friction_pair,
    require_in_range,
    require_nonnegative,
    require_positive,
)

G = 9.81


# ------------------------------------------------------------------------------------ running
def run(toy, method: str = "moreau-jean", t_end: float = 1.0, *, h: float = 1e-3, theta: float = 0.5,
        solver: str = "lemke", rtol: float = 1e-12, output_dt: float = 1e-3,
        zeno_interval: float = 1e-9, fast: bool = True) -> SimulationResult:
    """Run a toy from its initial state with Moreau–Jean ("moreau-jean", step h, θ, one-step
    solver; `fast` allows its compiled loop where the scene permits) or the event-driven
    reference ("event-driven", tolerance rtol, samples every output_dt)."""
    scene = toy.scene()
    q0, v0 = toy.initial_state()
    if method == "moreau-jean":
        integrator = MoreauJean(MoreauJeanOptions(h=h, theta=theta, solver=solver, fast=fast))
    elif method == "event-driven":
        integrator = EventDriven(EventDrivenOptions(rtol=rtol, atol=rtol, output_dt=output_dt,
                                                    zeno_interval=zeno_interval))
    else:
        raise InputError(f"unknown method '{method}'; choose moreau-jean or event-driven")
    return integrator.run(scene, q0, v0, t_end)


def _rectangle_inertia(mass: float, width: float, height: float) -> float:
    return mass * (width**2 + height**2) / 12.0


def _corners(body: int, width: float, height: float, line: Line, law: ContactLaw):
    """The two bottom corners of a width × height rectangle, as point contacts on `line`."""
    a, b = width / 2, height / 2
    return [PointOnLine(body, (-a, -b), line, law, name="left"),
            PointOnLine(body, (a, -b), line, law, name="right")]


def _block_scene(toy, applied_force=None) -> Scene:
    """A toy's width × height block on its `line`, both bottom corners with its μs/μd, e = 0."""
    body = RigidBody(toy.mass, _rectangle_inertia(toy.mass, toy.width, toy.height), name="block")
    law = ContactLaw.of(toy.mu_s, toy.mu_d, 0.0)
    return Scene([body], _corners(0, toy.width, toy.height, toy.line, law), gravity=toy.g,
                 applied_force=applied_force)


def _force_along_floor(height: float, magnitude):
    """Applied force `magnitude(t, q)` along +x acting at the block's bottom face (the floor
    line), so it neither pitches the block nor unloads one corner."""
    b = height / 2

    def applied(t, q, v):
        force = (magnitude(t, q), 0.0)
        lever = rotate(q[2], (0.0, -b))  # from the centre of mass to the floor line
        return np.array([force[0], force[1], cross2(lever, force)])

    return applied


def _slope_coordinate(result: SimulationResult, angle: float, body: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Position and velocity of a body's centre of mass along a line of inclination `angle`."""
    t = (math.cos(angle), math.sin(angle))
    q, v = result.trajectory.q, result.trajectory.v
    i = 3 * body
    s = q[:, i] * t[0] + q[:, i + 1] * t[1]
    ds = v[:, i] * t[0] + v[:, i + 1] * t[1]
    return s - s[0], ds


def first_slip_time(result: SimulationResult, contacts=None) -> float | None:
    """Start of the first phase in which any of `contacts` (default all) slips; None if never."""
    names = contacts or result.contact_names
    starts = [ph.t_start for name in names for ph in result.phases.get(name, [])
              if ph.mode in ("slip+", "slip-")]
    return min(starts) if starts else None


# ------------------------------------------------------------------------------ bouncing ball
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


# ---------------------------------------------------------------------------- block on incline
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


# ------------------------------------------------------------------------ block pushed by a ramp
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
        return self.rate * t

    def scene(self) -> Scene:
        return _block_scene(self, _force_along_floor(self.height, lambda t, q: self.push(t)))

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


# --------------------------------------------------------------------------- disk on an incline
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


# --------------------------------------------------------------------- stick–slip on a belt
@dataclass(frozen=True)
class BeltOscillator:
    """A block on a belt moving at `belt_speed`, held by a spring (stiffness k) to a fixed
    anchor: the classic stick–slip oscillator.

    The block starts riding the belt with the spring relaxed. It sticks until the spring force
    reaches μs N (x = μs N/k), then slips with friction μd N, oscillating about x_d = μd N/k
    until its velocity matches the belt again at x = x_d − y0, y0 = (μs − μd) N/k, and sticks:
    stick time 2 y0 / v_b, slip time (2π − 2 atan(ω y0 / v_b)) / ω, ω = √(k/m).
    The spring acts along the belt's surface (see PushedBlock: no pitching, equal corner loads).
    """

    belt_speed: float = 0.1
    stiffness: float = 100.0
    mu_s: float = 0.6
    mu_d: float = 0.4
    width: float = 0.2
    height: float = 0.05
    mass: float = 1.0
    g: float = G

    def __post_init__(self):
        require_friction_pair(self.mu_s, self.mu_d)
        for name in ("belt_speed", "stiffness", "width", "height", "mass", "g"):
            require_positive(name, getattr(self, name))
        if self.mu_s == self.mu_d:
            raise InputError("the belt oscillator needs mu_s > mu_d to stick and slip")

    @property
    def line(self) -> Line:
        return Line((0.0, 0.0), 0.0, self.belt_speed)

    def scene(self) -> Scene:
        return _block_scene(self, _force_along_floor(self.height, lambda t, q: -self.stiffness * q[0]))

    def initial_state(self):
        return np.array([0.0, self.height / 2, 0.0]), np.array([self.belt_speed, 0.0, 0.0])

    @property
    def normal_force(self) -> float:
        return self.mass * self.g

    @property
    def omega(self) -> float:
        return math.sqrt(self.stiffness / self.mass)

    @property
    def slip_amplitude(self) -> float:
        """y0 = (μs − μd) N / k: the offset of both stick ends from the slip centre μd N / k."""
        return (self.mu_s - self.mu_d) * self.normal_force / self.stiffness

    @property
    def first_slip_time(self) -> float:
        return self.mu_s * self.normal_force / self.stiffness / self.belt_speed

    @property
    def stick_time(self) -> float:
        return 2 * self.slip_amplitude / self.belt_speed

    @property
    def slip_time(self) -> float:
        w = self.omega
        return (2 * math.pi - 2 * math.atan(w * self.slip_amplitude / self.belt_speed)) / w

    @property
    def period(self) -> float:
        return self.stick_time + self.slip_time

    @property
    def slip_onset_position(self) -> float:
        return self.mu_s * self.normal_force / self.stiffness

    @property
    def restick_position(self) -> float:
        return (2 * self.mu_d - self.mu_s) * self.normal_force / self.stiffness

    def limit_cycle(self, n: int = 400) -> tuple[np.ndarray, np.ndarray]:
        """(x, ẋ) around the closed limit cycle: the slip arc, then the stick segment."""
        w, y0, vb = self.omega, self.slip_amplitude, self.belt_speed
        tau = np.linspace(0.0, self.slip_time, n)
        xd = self.mu_d * self.normal_force / self.stiffness
        x = xd + y0 * np.cos(w * tau) + vb / w * np.sin(w * tau)
        xdot = -y0 * w * np.sin(w * tau) + vb * np.cos(w * tau)
        x = np.concatenate([x, [self.slip_onset_position]])
        xdot = np.concatenate([xdot, [vb]])
        return x, xdot


def stick_slip_phases(result: SimulationResult, min_duration: float = 0.0) -> list[tuple[str, float, float]]:
    """(mode, start, end) of the block's stick and slip phases, read from both corners: the
    block sticks while both corners stick and slips while both slip."""
    tr = result.trajectory
    modes = tr.modes
    words = []
    for row in modes:
        states = set(row)
        if states == {"stick"}:
            words.append("stick")
        elif states <= {"slip+", "slip-"}:
            words.append("slip")
        else:
            words.append("mixed")
    phases: list[list] = []
    for k in range(1, len(tr.t)):
        w = words[k]
        if phases and phases[-1][0] == w:
            phases[-1][2] = tr.t[k]
        else:
            phases.append([w, tr.t[k - 1], tr.t[k]])
    return [tuple(p) for p in phases if p[2] - p[1] >= min_duration]


# ------------------------------------------------------------------------- Housner's rocking block
@dataclass(frozen=True)
class RockingBlock:
    """Housner's rocking block: a uniform rectangle (half-width b, half-height c) tilted by
    `tilt` onto its left corner and released on a rigid floor (e = 0, friction high enough
    to prevent sliding).

    Slenderness α = atan(b/c), R = √(b² + c²). Rocking about a corner conserves energy; each
    impact (the other corner lands, the old one lifts off) conserves the angular momentum about
    the landing corner, so ω⁺/ω⁻ = 1 − (3/2) sin² α (Housner 1963). The first impact comes at
    |ω| = √(3 g/(2R) (cos(α − tilt) − cos α)), and every impact multiplies |ω| by the ratio.
    """

    half_width: float = 0.1
    half_height: float = 0.3
    tilt: float = math.radians(10.0)
    mu: float = 1.0
    mass: float = 1.0
    g: float = G

    def __post_init__(self):
        for name in ("half_width", "half_height", "mass", "g"):
            require_positive(name, getattr(self, name))
        require_in_range("tilt", self.tilt, 0.0, self.slenderness, open_lo=True, open_hi=True)
        require_friction_pair(self.mu, self.mu)

    @property
    def slenderness(self) -> float:
        return math.atan2(self.half_width, self.half_height)

    @property
    def size(self) -> float:
        """R: distance from the centre of mass to a corner."""
        return math.hypot(self.half_width, self.half_height)

    @property
    def ratio(self) -> float:
        return 1.0 - 1.5 * math.sin(self.slenderness) ** 2

    @property
    def first_impact_rate(self) -> float:
        """|θ̇| just before the first impact."""
        a, R = self.slenderness, self.size
        return math.sqrt(1.5 * self.g / R * (math.cos(a - self.tilt) - math.cos(a)))

    def impact_rates(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """|θ̇| before and after each of the first n impacts."""
        before = self.first_impact_rate * self.ratio ** np.arange(n)
        return before, before * self.ratio

    def scene(self) -> Scene:
        w, hgt = 2 * self.half_width, 2 * self.half_height
        body = RigidBody(self.mass, _rectangle_inertia(self.mass, w, hgt), name="block")
        law = ContactLaw.of(self.mu, self.mu, 0.0)
        return Scene([body], _corners(0, w, hgt, Line(), law), gravity=self.g)

    def initial_state(self):
        # Pivot (left corner) at the origin; the centre of mass sits at rotate(tilt, (b, c)).
        cx, cy = rotate(self.tilt, (self.half_width, self.half_height))
        return np.array([cx, cy, self.tilt]), np.zeros(3)


def impact_rate_pairs(result: SimulationResult, *, extrapolate: bool = False) -> list[tuple[float, float, float]]:
    """(t, θ̇ before, θ̇ after) of body 0 at each impact of a run.

    Moreau–Jean's post-impact velocity is the end-of-step velocity, one step of gravity after
    the impact. With `extrapolate`, the next step's change of θ̇ (pure rocking by then) carries
    it back to the impact time, which removes that O(h) part of the error (the Jacobians are
    still taken at the step's start, |θ̇| h away from the impact configuration).
    """
    out = []
    tr = result.trajectory
    for imp in result.impacts:
        before, after = float(imp.v_before[2]), float(imp.v_after[2])
        if extrapolate and result.method == "moreau-jean":
            k = np.flatnonzero(np.all(tr.v == imp.v_after, axis=1))
            if k.size and k[0] + 1 < len(tr.t):
                k = int(k[0])
                rate = (tr.v[k + 1, 2] - tr.v[k, 2]) / (tr.t[k + 1] - tr.t[k])
                after -= rate * (tr.t[k] - imp.t)
        out.append((float(imp.t), before, after))
    return out


# --------------------------------------------------------------------------- Painlevé's rod
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


# ------------------------------------------------------------------------ collisions of balls
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


def save_figure(fig, out_dir, name: str) -> "Path":
    """Write a matplotlib figure to out_dir/name.png atomically and close it; returns the path."""
    import matplotlib.pyplot as plt

    path = Path(out_dir) / f"{name}.png"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    plt.close(fig)
    return path


def example_parser(description: str):
    """The command line every toy example shares: `--out DIR` for its figure."""
    import argparse

    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--out", default=".", help="folder for the figure (default: current folder)")
    return parser


def ball_velocities(result: SimulationResult) -> np.ndarray:
    """ẋ of every ball at the end of the run."""
    return result.trajectory.v[-1, 0::3].copy()


__all__ = [
    "run", "BouncingBall", "BlockOnIncline", "PushedBlock", "DiskOnIncline", "BeltOscillator",
    "RockingBlock", "PainleveRod", "BallRow", "ball_height", "rest_time", "slope_motion",
    "first_slip_time", "stick_slip_phases", "impact_rate_pairs", "ball_velocities", "save_figure",
    "example_parser",
]
