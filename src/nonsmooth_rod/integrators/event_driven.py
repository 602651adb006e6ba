"""Event-driven (hybrid) integration: smooth modes joined by located, refined events.

Within a mode (each contact open, sticking or sliding) the scene is a smooth ODE integrated
with a high-order method (DOP853, tight tolerances), one step at a time. Mode changes are the
zero crossings of switching indicators, evaluated on each step's dense output:

* sticking contact: T − μs N rises through 0, or T + μs N falls through 0 → slip against it;
* sliding contact: slip velocity crosses 0 → re-stick if the sticking solution has |T| ≤ μs N,
  else slip the other way (the re-stick test the paper's treatment misses);
  and det A (A = H_N M⁻¹ (H_N − s μd H_T)) falls to 0: Painlevé, stop with status "painleve";
* closed contact: N falls through 0 → contact opens (flight);
* closed vertex–edge contact: its pair of features stops being the touching one (a box's corner
  passing the end of a table: the margin of `VertexOnEdge.region` falls through 0) → it opens
  ("leave-feature"), and the pair that takes over (the table's end under the box's edge) is
  decided at that instant;
* open contact: gap falls through 0 → impact, solved at impulse level with Newton restitution
  and two-coefficient Coulomb friction on the impulses (see solvers/two_coefficient.py); for a
  vertex–edge contact the indicator is max(gap, −margin), which reaches 0 only inside the pair's
  region (a corner passing beside a segment's end, below its level, touches nothing); a pair
  entering its region already touching at no approach speed closes without an impact
  ("enter-feature").

Contacts: a body's disks, points and polygons against fixed lines and segments, declared or
found (model/collision.py); body–body contacts are refused in one line.

A reference must never miss an event, so sign changes between steps are not enough: an
indicator may cross and come back within one step (T/N above μs for microseconds near its
maximum, a gap closing and reopening, N dipping below 0). Each accepted step is therefore
watched whole (`_Watch`): every indicator is interpolated on Chebyshev points of the step's
dense output, its interior extrema (roots of the interpolant's derivative) are evaluated
exactly, an extremum that nearly reaches zero is refined by a bounded minimisation, and the
first crossing is located with brentq on the dense output to a few ulps. A step whose
indicators the interpolant cannot resolve is bisected. The step cap (`max_step`) is not
needed for events and is off by default.

The choice of modes at a switch enumerates the candidate modes of the contacts that are
"at a decision" and keeps the first consistent one, preferring stick (a contact that μs can
hold is held: this is what makes the paper's bistable start roll). A sliding contact is
labelled by the sign of its slip velocity, frictionless or not.

A state at rest (v = 0 and a = 0 with constant forces: no applied force) stays at rest, so
the run jumps to t_end at once (stats["rest_from"]); with an applied force it is integrated,
and the step grows freely.
"""
from __future__ import annotations

import itertools
import math
import time
import warnings
from dataclasses import dataclass, field

import numpy as np
import scipy.integrate
from numpy.polynomial import chebyshev
from scipy.optimize import brentq, minimize_scalar

from ..model.contacts import DiskOnSegment, SegmentEndOnEdge, VertexOnEdge
from ..model.dynamics import SLIP_SIGN, mode_dynamics
from ..model.scene import Scene
from ..solvers.two_coefficient import solve_two_coefficient
from ..results import Event, Impact, SimulationResult, Trajectory, phases_from_intervals
from ..validation import Choice, Integer, Number, Text, check_options, option
from ..solvers.registry import SolverName
from . import accumulation
from .declaration import NO_DRIVEN, NO_JOINTS, STEP_CAP, Declaration, Refusal, first_item
from .sampling import OUTPUT_DT_KNOB, Thinning, grid_blocks, stop_event, stop_message, output_dt_samples
from .watch_tests import TINY, start_band

ODE_METHODS = ("DOP853", "RK45", "RK23", "Radau", "BDF", "LSODA")
# scipy's ODE solvers raise a smaller rtol to 100 ε with a warning: refuse it instead.
RTOL_FLOOR = 100 * float(np.finfo(float).eps)
# An absolute tolerance on positions (m) and velocities (m/s) beyond this is no tolerance: the
# solver's steps then skip over the events (atol = 1e20 wrote −inf into the trajectory).
ATOL_CEILING = 1e-2


@dataclass
class EventDrivenOptions:
    """Accuracy and stopping controls of the event-driven integrator."""

    rtol: float = option(1e-12, Number(RTOL_FLOOR, 0.1))
    atol: float = option(1e-12, Number(0.0, ATOL_CEILING, open_lo=True))
    ode_method: str = option("DOP853", Choice(ODE_METHODS))
    # spacing of the saved samples (events are always saved)
    output_dt: float = option(1e-3, Number(0.0, open_lo=True))
    # Events are found within each step, whatever its length (see `_Watch`): the cap only
    # bounds the step for whoever wants it; infinity (the default) leaves it to the tolerance.
    max_step: float = option(math.inf, Number(0.0, open_lo=True, infinite=True))
    stop_at_impact: str | None = option(None, Text())  # name of a contact whose first impact ends the run
    max_events: int = option(10_000, Integer(1, 10**9))
    # impacts closer than this in time: an accumulation point (s)
    zeno_interval: float = option(1e-9, Number(0.0, 1e-3))
    impact_solver: str = option("enum", SolverName())  # the exact reference for the few contacts of an impact
    gap_tol: float = option(1e-9, Number(0.0, 1e-3, open_lo=True))  # m
    velocity_tol: float = option(1e-9, Number(0.0, 1e-3, open_lo=True))  # m/s
    # impacts of an accumulation are resolved while their flights rise above this (m): below, the
    # rest of the series is summed to its accumulation time (integrators/accumulation.py); 0: all
    resolution: float = option(0.0, Number(0.0, 1.0))

    def __post_init__(self):
        check_options(self)


def _finite_part(result: SimulationResult) -> SimulationResult:
    """The result up to its first non-finite sample (q, v, N or T), then status "failed"."""
    tr = result.trajectory
    bad = ~(np.all(np.isfinite(tr.q), axis=1) & np.all(np.isfinite(tr.v), axis=1)
            & np.all(np.isfinite(tr.normal_force), axis=1) & np.all(np.isfinite(tr.tangential_force), axis=1))
    if not bad.any():
        return result
    k = int(np.argmax(bad))
    t_bad = float(tr.t[k])
    result.trajectory = Trajectory(tr.t[:k], tr.q[:k], tr.v[:k], tr.a[:k], tr.normal_force[:k],
                                   tr.tangential_force[:k], tr.modes[:k])
    result.set_status("failed", f"non-finite state at t = {t_bad:.9g} s (the integration diverged)")
    return result


class _Stop(Exception):
    """The run ends here with `status`; `event`: its event (default: one of kind `status`)."""

    def __init__(self, status, message, detail=None, event=None):
        self.status = status
        self.message = message
        self.detail = detail or {}
        self.event = event


# ---------------------------------------------------------------------- switching indicators
@dataclass(frozen=True)
class _Indicator:
    """A switching function of the current mode: the event `kind` of `contact` happens where its
    value crosses zero in `direction` (+1 rising, −1 falling)."""

    kind: str  # touchdown, liftoff, break-upper, break-lower, slip-zero, painleve, leave-feature
    contact: int
    direction: int
    offset: float = 0.0  # subtracted from the value


def _indicators(scene, modes, force_tol: float) -> list[_Indicator]:
    """The indicators that can end a segment in `modes`."""
    out = []
    for i, mode in enumerate(modes):
        law = scene.contacts[i].law.friction
        if mode == "open":
            out.append(_Indicator("touchdown", i, -1))
            continue
        out.append(_Indicator("liftoff", i, -1))
        if _has_region(scene.contacts[i]):
            out.append(_Indicator("leave-feature", i, -1))
        if mode == "stick":
            # A frictionless contact holds only with T = 0, known to round-off: it breaks away
            # when it would need a tangential force beyond the force tolerance.
            margin = force_tol if law.mu_s == 0.0 else 0.0
            out.append(_Indicator("break-upper", i, +1, margin))
            out.append(_Indicator("break-lower", i, -1, -margin))
        else:
            # Only the crossing back through zero counts, not the start of the slip at zero.
            out.append(_Indicator("slip-zero", i, -1 if mode == "slip+" else +1))
            if law.mu_d > 0.0:
                out.append(_Indicator("painleve", i, -1))
    return out


def _has_region(contact) -> bool:
    """Whether the contact counts only while its pair of features is the touching one (a vertex
    on an edge: its gap is infinite elsewhere), so that entering and leaving that region are
    events (`_PackedRelation.region`)."""
    return isinstance(contact, VertexOnEdge)


def _touchdown_value(contact, q, v) -> float | None:
    """Falls to 0 where the contact touches: its gap, and for a pair of features that counts
    only in a region (a corner on a segment, a table's end under a box's edge), max(gap, −margin)
    — continuous, positive while the pair is outside its region whatever its gap (a corner
    passing beside a segment's end, below its level), 0 when it enters the region touching."""
    if not _has_region(contact):
        return None
    gap, margin = contact.region(q, v)
    return max(gap, -margin)


def _indicator_values(scene, modes, indicators, t, y, kin=None, dyn=None) -> np.ndarray:
    """Values of the indicators at state y (the mode's dynamics are solved once, if needed;
    kin and dyn: the kinematics and the mode's dynamics at y when the caller has them)."""
    n = scene.n_dof
    q, v = y[:n], y[n:]
    kin = kin if kin is not None else scene.kinematics(q, v)
    out = np.empty(len(indicators))
    for j, ind in enumerate(indicators):
        k = kin[ind.contact]
        if ind.kind == "touchdown":
            value = _touchdown_value(scene.contacts[ind.contact], q, v)
            value = k.gap if value is None else value
        elif ind.kind == "leave-feature":
            value = scene.contacts[ind.contact].region(q, v)[1]
        elif ind.kind == "slip-zero":
            value = k.H_T @ v - k.surface_velocity
        else:
            if dyn is None:
                dyn = mode_dynamics(scene, t, q, v, modes, kin)
            N, T = dyn.normal_force[ind.contact], dyn.tangential_force[ind.contact]
            mu_s = scene.contacts[ind.contact].law.friction.mu_s
            value = {"liftoff": N, "break-upper": T - mu_s * N, "break-lower": T + mu_s * N,
                     "painleve": np.linalg.det(dyn.matrix) if dyn.matrix.size else 1.0}[ind.kind]
        out[j] = value - ind.offset
    return out


_NODES = 13
_CHEB_X = -np.cos(np.pi * np.arange(_NODES) / (_NODES - 1))  # Chebyshev–Lobatto points, ascending
_CHEB_FIT = np.linalg.inv(chebyshev.chebvander(_CHEB_X, _NODES - 1))  # values → coefficients
_MAX_BISECTIONS = 4
_EPS = float(np.finfo(float).eps)
_TINY = TINY  # a start value counted as just on the safe side (watch_tests)


def _interior_extrema(coef) -> np.ndarray:
    """Points of (−1, 1) where the Chebyshev series `coef` has a local extremum, ascending."""
    d = chebyshev.chebtrim(chebyshev.chebder(coef), tol=1e-14 * float(np.max(np.abs(coef))))
    if len(d) < 2:
        return np.empty(0)
    r = chebyshev.chebroots(d)
    r = r[np.abs(r.imag) <= 1e-5].real  # a near-double root (two close extrema) may come out complex
    return np.unique(r[(r > -1.0) & (r < 1.0)])


def _noise_levels(scene, modes, indicators, t, y, start=None) -> np.ndarray:
    """Round-off level of each indicator near state y: a thousand ulps of the size of its terms
    (start: the indicators' values at y, when the caller has them)."""
    n = scene.n_dof
    length = float(np.max(np.abs(y[:n]), initial=0.0))
    speed = float(np.max(np.abs(y[n:]), initial=0.0))
    force = _force_scale(scene, t, y[:n], y[n:])
    if start is None and any(ind.kind == "painleve" for ind in indicators):
        start = _indicator_values(scene, modes, indicators, t, y)
    sizes = []
    for j, ind in enumerate(indicators):
        contact = scene.contacts[ind.contact]
        if ind.kind in ("touchdown", "leave-feature"):
            sizes.append(length + contact.geometry_scale())
        elif ind.kind == "slip-zero":
            sizes.append(speed * (1.0 + length) + abs(getattr(getattr(contact, "line", None), "velocity", 0.0)))
        elif ind.kind == "painleve":
            sizes.append(abs(start[j]))
        else:
            sizes.append(force)
    return 1e3 * _EPS * np.array(sizes)


# The forced mode of a contact whose pair of features has left its region (identity marks it).
_LEFT_REGION = ["open"]

# Events at one instant (to round-off): a contact that leaves or meets the line goes first, so
# that a cone closing with N → 0 is not taken for a break-away.
_PRIORITY = {"liftoff": 0, "touchdown": 0, "leave-feature": 0}


def _first_of(found, indicators):
    """The event (t, j) to act on among the crossings `found` in one step."""
    if not found:
        return None
    t_first = min(t for t, _ in found)
    tie = 8 * _EPS * max(1.0, abs(t_first))
    return min((_PRIORITY.get(indicators[j].kind, 1), t, j) for t, j in found if t - t_first <= tie)[1:]


class _Watch:
    """The indicators of one mode, watched over whole steps of the dense output.

    Each indicator is multiplied by −direction, so that it is positive on the side it starts
    on ("safe") and its event is the first fall to ≤ 0. A segment often starts with an
    indicator at zero (a slip at zero slip velocity, a flight at zero gap, a contact at the
    edge of its cone): until it first leaves its round-off band (`noise`), it counts as safe;
    leaving the band on the wrong side is an event there.
    """

    def __init__(self, scene, modes, indicators, t0, y0, gap_tol=0.0, start=None):
        self.scene, self.modes, self.indicators, self.t0 = scene, list(modes), indicators, t0
        self.sign = -np.array([ind.direction for ind in indicators], dtype=float)
        self.noise = _noise_levels(scene, modes, indicators, t0, y0, start)
        touchdowns = [j for j, ind in enumerate(indicators) if ind.kind == "touchdown"]
        if touchdowns and gap_tol > 0.0:
            # A contact that has just opened starts at the gap its closed phase drifted to (the
            # integration error of g̈ = 0 on a turning normal, a pivot: ~1e-12 m), which the
            # switch accepted as closed (≤ gap_tol): its band is that drift.
            start = np.abs(_indicator_values(scene, modes, indicators, t0, y0))
            for j in touchdowns:
                if start[j] <= gap_tol:
                    self.noise[j] = max(self.noise[j], 2.0 * start[j])
        self.band_exit = np.full(len(indicators), math.inf)  # when each first left its start band
        self._cached = {}
        self.evaluations = 0

    def safe_values(self, t, dense) -> np.ndarray:
        self.evaluations += 1
        return self.sign * _indicator_values(self.scene, self.modes, self.indicators, t, dense(t))

    def _start_band(self, j, ts, s):
        """Count values safe (in place) from the segment start until the indicator leaves its band
        (watch_tests.start_band: the compiled screen's too)."""
        start_band(ts, s, self.t0, self.noise[j], self.band_exit, j)

    def first_event(self, dense, a, b, depth=0):
        """(t, j): the first crossing in [a, b] and which indicator makes it; None if none."""
        if not self.indicators or b <= a:
            return None
        ts = a + 0.5 * (b - a) * (_CHEB_X + 1.0)
        ts[0], ts[-1] = a, b
        s = np.array([self._cached.get(t) if t in self._cached else self.safe_values(t, dense) for t in ts])
        self._cached = {b: s[-1].copy()}  # the next step starts where this one ends
        for j in range(len(self.indicators)):
            self._start_band(j, ts, s[:, j])
        coef = _CHEB_FIT @ s
        err = np.abs(coef[-1]) + np.abs(coef[-2]) + 64 * _EPS * np.max(np.abs(s), axis=0)
        can_bisect = depth < _MAX_BISECTIONS and (b - a) > 1e3 * _EPS * max(1.0, abs(b))
        found = []
        for j in range(len(self.indicators)):
            t_cross = self._scan(j, ts, s[:, j], coef[:, j], err[j], dense, can_bisect)
            if t_cross == "unresolved":
                mid = 0.5 * (a + b)
                return self.first_event(dense, a, mid, depth + 1) or self.first_event(dense, mid, b, depth + 1)
            if t_cross is not None:
                found.append((t_cross, j))
        return _first_of(found, self.indicators)

    def _scan(self, j, ts, s, coef, err, dense, can_bisect):
        """Where indicator j first falls to ≤ 0 within the step ts[0]..ts[-1]: a time, None, or
        "unresolved" when the interpolant cannot tell and the step should be halved."""
        x_ext = _interior_extrema(coef)
        p_ext = chebyshev.chebval(x_ext, coef)
        if min(s[0], s[-1], *p_ext) > err:
            return None  # on the safe side throughout, by more than the interpolation error
        if err > 1e-3 * np.ptp(s):
            if can_bisect:
                return "unresolved"
            nodes_t, nodes_s = list(ts), list(s)  # the samples themselves, at the finest halving
        else:
            t_ext = ts[0] + 0.5 * (ts[-1] - ts[0]) * (x_ext + 1.0)
            nodes_t = [ts[0], *t_ext, ts[-1]]
            nodes_s = [s[0], *(self.safe_values(t, dense)[j] for t in t_ext), s[-1]]
            self._start_band(j, nodes_t, nodes_s)
            self._refine_near_misses(j, nodes_t, nodes_s, dense, 1e-3 * np.ptp(s) + 10.0 * err)
        return self._first_fall(j, nodes_t, nodes_s, dense)

    def _refine_near_misses(self, j, nodes_t, nodes_s, dense, near):
        """A local minimum just above zero may hide a crossing if the interpolant placed it a
        little off: minimise the indicator itself between the neighbouring nodes."""
        for k in range(1, len(nodes_t) - 1):
            if 0.0 < nodes_s[k] <= near and nodes_s[k] < min(nodes_s[k - 1], nodes_s[k + 1]):
                res = minimize_scalar(lambda t: self.safe_values(t, dense)[j], method="bounded",
                                      bounds=(nodes_t[k - 1], nodes_t[k + 1]),
                                      options={"xatol": 4 * _EPS * max(1.0, abs(nodes_t[k]))})
                if res.fun < nodes_s[k]:
                    nodes_t[k], nodes_s[k] = float(res.x), float(res.fun)

    def _first_fall(self, j, nodes_t, nodes_s, dense):
        """The first root where the indicator, monotone between nodes, falls to ≤ 0."""
        for k in range(len(nodes_t) - 1):
            if nodes_s[k] > 0.0 >= nodes_s[k + 1]:
                lo, hi = nodes_t[k], nodes_t[k + 1]

                def f(t):
                    return self.safe_values(t, dense)[j]
                if nodes_s[k] == _TINY and f(lo) <= 0.0:
                    return lo  # counted safe in its start band, it leaves it on the wrong side
                if nodes_s[k + 1] == 0.0:
                    return hi
                return brentq(f, lo, hi, xtol=4 * _EPS, rtol=4 * _EPS)
        return None


# ---------------------------------------------------------------------- the run's record
@dataclass
class _Run:
    """The current state of a run and everything it reports. Its samples are kept and its stop
    conditions tried as they come (`thinning`, integrators/sampling.py)."""

    t: float
    q: np.ndarray
    v: np.ndarray
    thinning: Thinning
    events: list = field(default_factory=list)
    impacts: list = field(default_factory=list)
    samples: list = field(default_factory=list)  # blocks (t, y, modes, ModeDynamics or None)
    unkept: tuple | None = None  # the last sample not kept, if later than every kept one
    boundaries: list = field(default_factory=list)
    interval_modes: list = field(default_factory=list)
    steps: int = 0
    nfev: int = 0
    indicator_evaluations: int = 0
    last_impact_t: float = -math.inf
    rest_from: float | None = None
    t_end: float = math.inf
    speed_floor: float = 0.0  # at the last impact: closing speeds at or below it are not resolved
    closing_speed: float = math.inf  # of the last impact
    unresolved_impacts: int = 0
    instant: tuple = (math.nan, {})  # (t, forced modes) of the events at the current instant

    def __post_init__(self):
        self.boundaries = [self.t]

    def sample(self, t, y, modes, dynamics=None):
        """Offer samples (times t, states y) in time order: the kept ones are stored; where a stop
        condition holds, the run ends there (raises _Stop "stopped")."""
        ts, ys = np.atleast_1d(np.asarray(t, dtype=float)), np.atleast_2d(y)
        keep = self.thinning.keeps(ts)
        self.unkept = None if keep[-1] else (ts[-1:], ys[-1:].copy(), list(modes), dynamics)
        ts, ys = ts[keep], ys[keep]  # copies (a mask)
        n = ys.shape[1] // 2
        stop = self.thinning.first_stop(ts, ys[:, :n].copy(), ys[:, n:].copy())
        if stop is not None:
            ts, ys, self.unkept = ts[: stop + 1], ys[: stop + 1], None
        if ts.size:
            self.samples.append((ts, ys, list(modes), dynamics))
        if stop is not None:
            self._end_segment(float(ts[-1]), ys[-1], modes)
            raise _Stop("stopped", stop_message(self.t), event=stop_event(self.t))

    def close(self, t, y, modes, dynamics=None):
        """End the current segment at t in state y (sampled there)."""
        self.sample(t, y, modes, dynamics)
        self._end_segment(t, y, modes)

    def _end_segment(self, t, y, modes):
        if t > self.boundaries[-1]:
            self.boundaries.append(t)
            self.interval_modes.append(list(modes))
        n = len(y) // 2
        self.t, self.q, self.v = t, np.array(y[:n], dtype=float), np.array(y[n:], dtype=float)

    def kept_samples(self) -> list:
        """The kept samples, and the run's last sample if it was not kept."""
        return self.samples + ([self.unkept] if self.unkept is not None else [])


def _smallest_eigenvalue_real(A) -> float:
    """The smallest real part of A's eigenvalues; for a 1 × 1 A (one sliding contact) its entry,
    without LAPACK's call (whose value can differ in the last bit at tiny magnitudes, never in
    the sign the caller tests)."""
    return float(A[0, 0]) if A.shape == (1, 1) else float(np.min(np.linalg.eigvals(A).real))


def _force_scale(scene, t, q, v) -> float:
    return max(1e-12, float(np.max(np.abs(scene.force(t, q, v)))))


class EventDriven:
    """Event-driven integrator for scenes of bodies against fixed lines and segments."""

    name = "event-driven"

    SAMPLES_KNOB = OUTPUT_DT_KNOB
    samples_estimate = staticmethod(output_dt_samples)

    def __init__(self, options: EventDrivenOptions | None = None):
        self.options = options or EventDrivenOptions()

    # The modes' dynamics at a state, for the mode decisions, a rest and the samples (the hybrid
    # method solves them with the compiled model/dynamics.ModeSystem where it can).
    _dynamics = staticmethod(mode_dynamics)

    # ------------------------------------------------------------------ mode decisions
    def _local(self, scene, q, v):
        kin = scene.kinematics(q, v)
        u_N = np.array([k.H_N @ v for k in kin])
        u_T = np.array([k.H_T @ v - k.surface_velocity for k in kin])
        gaps = np.array([k.gap for k in kin])
        return kin, gaps, u_N, u_T

    def _consistent(self, scene, t, q, v, modes, kin, u_T, decided):
        """Is this mode assignment consistent at (q, v)? Returns the ModeDynamics or None."""
        dyn = self._dynamics(scene, t, q, v, modes, kin)
        if not np.all(np.isfinite(dyn.a)):
            return None
        fscale = _force_scale(scene, t, q, v)
        ascale = max(1e-12, float(np.max(np.abs(dyn.a * scene.mass_diagonal))) / fscale)
        tolF = 1e-9 * fscale
        for i, mode in enumerate(modes):
            k = kin[i]
            law = scene.contacts[i].law.friction
            if mode == "open":
                if decided[i]:
                    gdd = k.H_N @ dyn.a + k.drift_N
                    if gdd < -1e-9 * ascale:
                        return None
                continue
            N, T = dyn.normal_force[i], dyn.tangential_force[i]
            if N < -tolF:
                return None
            if mode == "stick":
                if abs(T) > law.mu_s * N + tolF:
                    return None
            elif decided[i] and abs(u_T[i]) <= self.options.velocity_tol:
                # Sliding from rest must accelerate the way it slides, with a well-posed A.
                acc_T = k.H_T @ dyn.a + k.drift_T
                if SLIP_SIGN[mode] * acc_T < -1e-9 * ascale:
                    return None
            if mode != "stick" and dyn.matrix.size and _smallest_eigenvalue_real(dyn.matrix) <= 0:
                return None
        return dyn

    def _decide(self, scene, t, q, v, forced=None):
        """Modes after a switch: contacts in `forced` take one of the listed modes, the other
        contacts at a decision (closed, at rest normally) are enumerated; stick first. A contact
        without friction is enumerated alike: it sticks only where it needs no tangential force,
        and slides the way its slip velocity goes."""
        forced = forced or {}
        kin, gaps, u_N, u_T = self._local(scene, q, v)
        vt = self.options.velocity_tol
        candidates, decided = [], []
        for i in range(len(kin)):
            if i in forced:
                candidates.append(list(forced[i]))
                # A pair that has left its region opens whatever its (meaningless) g̈ there.
                decided.append(forced[i] is not _LEFT_REGION)
            elif gaps[i] > self.options.gap_tol or u_N[i] > vt:
                candidates.append(["open"])
                decided.append(False)
            elif abs(u_T[i]) > vt:
                candidates.append(["slip+" if u_T[i] > 0 else "slip-", "open"])
                decided.append(True)
            else:
                candidates.append(["stick", "slip+", "slip-", "open"])
                decided.append(True)
        for modes in itertools.product(*candidates):
            if self._consistent(scene, t, q, v, list(modes), kin, u_T, decided) is not None:
                return list(modes)
        raise _Stop("painleve",
                    f"no consistent contact mode at t = {t:.12g} s (modes tried from {candidates}): "
                    "the sliding problem has no solution here (Painlevé-type inconsistency)")
    # ------------------------------------------------------------------ main loop
    def run(self, scene: Scene, q0, v0, t_end: float, *, t0: float = 0.0, resume=None, save_every: float | None = None,
            stop=()) -> SimulationResult:
        """From (q0, v0) at t0 to t_end on the scene's clock (inputs as the driver checked them:
        `declares`), keeping one sample per `save_every` (default: every output sample and event)
        and ending at the first kept sample where a `stop` callable (t, q, v) holds. `resume` is
        not used: the modes are decided afresh from (q0, v0)."""
        q, v = np.array(q0, dtype=float), np.array(v0, dtype=float)
        wall = time.process_time()
        names = [c.name for c in scene.contacts]
        run = _Run(float(t0), q, v, Thinning(t0, save_every, stop))
        run.t_end = float(t_end)
        # A diverging run (huge tolerances, a Painlevé blow-up) overflows inside scipy and the
        # model: no warnings on stderr, the non-finite samples end the result instead (below).
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            try:
                modes = self._decide(scene, run.t, q, v)
                run.events.append(Event(run.t, "start", "", {"modes": list(modes)}))
                status, message = self._loop(scene, run, modes, t_end, names)
            except _Stop as stop:
                status, message = stop.status, stop.message
                run.events.append(stop.event or Event(run.t, status, "", {"message": message, **stop.detail}))
            result = self._result(scene, run, names, status, message, time.process_time() - wall)
        return _finite_part(result)

    def _loop(self, scene, run, modes, t_end, names):
        """Segments and switches until t_end (or a stop); returns (status, message)."""
        n_events = 0
        while run.t < t_end:
            n_events += 1
            if n_events > self.options.max_events:
                raise _Stop("too-many-events", f"more than {self.options.max_events} events before "
                                               f"t = {run.t:.6g} s")
            if self._hold_rest(scene, run, modes, t_end):
                break
            hit = self._segment(scene, run, modes, t_end)
            if hit is None:
                break
            modes = self._switch(scene, run, modes, *hit, names)
            if modes is None:
                return "ok", f"stopped at the impact of {names[hit[1]]}"
        return "ok", "reached t_end"

    def _solver(self, scene, modes, t0, y0, t_end):
        n = scene.n_dof
        frozen = list(modes)

        def rhs(t, y):
            return np.concatenate([y[n:], mode_dynamics(scene, t, y[:n], y[n:], frozen).a])
        o = self.options
        return getattr(scipy.integrate, o.ode_method)(rhs, t0, y0, t_end, rtol=o.rtol, atol=o.atol,
                                                  max_step=o.max_step)

    def _segment(self, scene, run, modes, t_end):
        """Integrate `modes` from the run's state, step by step, to the first event or t_end.
        Returns the event's (kind, contact), or None at t_end; leaves the run at the stop."""
        indicators = _indicators(scene, modes, 1e-9 * _force_scale(scene, run.t, run.q, run.v))
        y0 = np.concatenate([run.q, run.v])
        watch = _Watch(scene, modes, indicators, run.t, y0, self.options.gap_tol)
        solver = self._solver(scene, modes, run.t, y0, t_end)
        hit = None
        try:
            while solver.status == "running" and hit is None:
                t_a = solver.t
                message = solver.step()
                if solver.status == "failed":
                    self._stalled(scene, run, modes, solver, y0, message)
                run.steps += 1
                dense = solver.dense_output()
                hit = watch.first_event(dense, t_a, solver.t)
                t_stop = hit[0] if hit is not None else solver.t
                self._sample(run, dense, t_a, t_stop, modes)
        finally:
            run.nfev += int(solver.nfev)
            run.indicator_evaluations += watch.evaluations
        run.close(float(t_stop), dense(t_stop) if hit is not None else solver.y.copy(), modes)
        return None if hit is None else (indicators[hit[1]].kind, indicators[hit[1]].contact)

    def _sample(self, run, dense, a, b, modes):
        """Output samples on the grid t0 + k·output_dt within [a, b)."""
        for ts in grid_blocks(run.boundaries[0], self.options.output_dt, a, b):
            run.sample(ts, dense(ts).T, modes)

    def _stalled(self, scene, run, modes, solver, y0, message):
        """The ODE solver failed: a Painlevé stop if the sliding system became singular (it
        stalls as A → 0 with the normal force unbounded, before det A = 0 is bracketed),
        else a failure. Keeps the samples up to there."""
        if not self._sliding_singular(scene, solver.t, solver.y, modes, run.t, y0):
            raise _Stop("failed", f"integration failed at t = {solver.t:.6g} s in modes {modes}: "
                                  f"{message}")
        run.close(float(solver.t), solver.y.copy(), modes)
        raise _Stop("painleve", f"Painlevé configuration at t = {run.t:.12g} s: the sliding problem loses "
                                "consistency (A → 0) with the normal force growing without bound; the run "
                                "stops here")

    # ------------------------------------------------------------------ switches
    def _switch(self, scene, run, modes, kind, i, names):
        """The modes after event `kind` of contact i (None: the run stops at this impact)."""
        t = run.t
        forced = {}
        if kind == "painleve":
            raise _Stop("painleve", f"Painlevé configuration at t = {t:.12g} s: sliding of contact {names[i]} "
                                    "loses consistency (J/M + ξ cos θ·D → 0); the run stops here")
        if kind in ("break-upper", "break-lower"):
            forced[i] = ["slip-" if kind == "break-upper" else "slip+"]
            run.events.append(Event(t, "stick-slip", names[i], {"to": forced[i][0]}))
        elif kind == "liftoff":
            forced[i] = ["open"]
            run.events.append(Event(t, "liftoff", names[i]))
        elif kind == "leave-feature":
            # The pair of features stops being the touching one (a corner passing the end of a
            # segment): the contact opens, and another pair (the segment's end on the body's
            # edge), if any, touches from here.
            forced[i] = _LEFT_REGION
            run.events.append(Event(t, "leave-feature", names[i]))
        elif kind == "slip-zero":
            run.events.append(Event(t, "slip-zero", names[i], {"from": modes[i]}))
            # The slip velocity has just crossed zero: re-stick if μs holds, else reverse.
            forced[i] = ["stick", "slip+" if modes[i] == "slip-" else "slip-"]
        elif kind == "touchdown" and self._enters_touching(scene, run, i):
            run.events.append(Event(t, "enter-feature", names[i]))
        elif kind == "touchdown":
            run.instant = (math.nan, {})  # the impact changed the velocities: decide afresh
            if self._touchdown(scene, run, modes, i, names):
                return None
            return self._accumulation(scene, run, modes, self._decide_at_instant(scene, run, forced), i, names)
        new_modes = self._decide_at_instant(scene, run, forced)
        if kind == "slip-zero":
            run.events[-1].detail["to"] = new_modes[i]
        return new_modes

    def _decide_at_instant(self, scene, run, forced):
        """Events at one instant compose: the modes forced by earlier events at this t still hold
        (two corners lifting off together must not take turns re-closing each other), unless
        together they admit no consistent mode."""
        t_prev, forced_prev = run.instant
        merged = {**forced_prev, **forced} if abs(run.t - t_prev) <= 8 * _EPS * max(1.0, abs(run.t)) else forced
        try:
            new_modes = self._decide(scene, run.t, run.q, run.v, merged)
        except _Stop:
            if merged == forced:
                raise
            merged = forced
            new_modes = self._decide(scene, run.t, run.q, run.v, forced)
        run.instant = (run.t, merged)
        return new_modes

    def _enters_touching(self, scene, run, i) -> bool:
        """Whether a touchdown of contact i is a pair of features entering its region already
        touching, at no approach speed (a table's end coming under a sliding box's bottom edge as
        its corner passes it): the contact closes without an impact."""
        if not _has_region(scene.contacts[i]):
            return False
        k = scene.contacts[i].kinematics(run.q, run.v, scene.n_dof)
        return abs(float(k.H_N @ run.v) - k.normal_velocity) <= self.options.velocity_tol

    def _touchdown(self, scene, run, modes, i, names) -> bool:
        """Impact of contact i; True if the run stops at it."""
        t, q, v_before = run.t, run.q, run.v.copy()
        run.v, pN, pT = self._impact(scene, t, q, v_before, i)
        if t - run.last_impact_t < self.options.zeno_interval:
            raise _Stop("zeno", f"impacts accumulate at t = {t:.12g} s (Zeno): the event-driven "
                                "scheme cannot pass an accumulation point")
        run.last_impact_t = t
        run.closing_speed = accumulation.closing_speed(scene, i, q, v_before)
        run.speed_floor = accumulation.speed_floor(scene, t, q, self.options.resolution)
        if accumulation.resolved(run.closing_speed, run.speed_floor):
            run.impacts.append(Impact(t, names[i], q.copy(), v_before, run.v.copy(), pN, pT))
            run.events.append(Event(t, "impact", names[i]))
        else:  # applied, not reported: the accumulation's end follows (`_accumulation`)
            run.unresolved_impacts += 1
        run.sample(t, np.concatenate([q, run.v]), modes)
        if self.options.stop_at_impact == names[i]:
            return True
        self._check_accumulation(scene, t, q, run.v, i)
        return False

    def _accumulation(self, scene, run, before, modes, hit, names):
        """After an impact of contact `hit` (modes `before` it, `modes` after): when every contact
        leaving the obstacle at it (the one hit, or one closed before) leaves slower than the run's
        speed floor, the next impacts are not resolved (integrators/accumulation.py): sum them to
        the accumulation time and go on from there with the contacts at rest on the obstacle (the
        series' limit). Returns the modes from where the run goes on."""
        if run.speed_floor <= 0.0:
            return modes
        kin, gaps, u_N, u_T = self._local(scene, run.q, run.v)
        u_N = u_N - np.array([k.normal_velocity for k in kin])
        leaving = [j for j, m in enumerate(modes) if m == "open" and (j == hit or before[j] != "open")
                   and u_N[j] > self.options.velocity_tol]
        if not leaving or max(u_N[j] for j in leaving) > run.speed_floor:
            return modes
        j = max(leaving, key=lambda c: u_N[c])
        dyn = self._dynamics(scene, run.t, run.q, run.v, modes, kin)
        ratio = u_N[j] / run.closing_speed if run.closing_speed > 0.0 else math.inf
        t_acc = accumulation.accumulation_time(run.t, u_N[j], float(kin[j].H_N @ dyn.a) + kin[j].drift_N, ratio)
        if t_acc is None:
            return modes
        t_acc = min(t_acc, run.t_end)  # the series unfinished at t_end: its limit there, to the resolution
        taking_part = [c for c in range(len(kin)) if c == hit or before[c] != "open" or modes[c] != "open"]
        y = np.concatenate(accumulation.limit_state(
            scene.inverse_mass_diagonal, [kin[c].H_N for c in taking_part], gaps[taking_part],
            [kin[c].H_T for c in taking_part if abs(u_T[c]) <= run.speed_floor], run.q, run.v))
        run.events.append(Event(t_acc, "accumulation", names[j], {
            "from": run.t, "leaving_speed": float(u_N[j]), "speed_floor": run.speed_floor, "ratio": float(ratio)}))
        for ts in grid_blocks(run.boundaries[0], self.options.output_dt, run.t, t_acc):
            run.sample(ts, np.broadcast_to(y, (ts.size, y.size)), modes)
        run.close(float(t_acc), y, modes)
        run.instant = (math.nan, {})
        return self._decide(scene, run.t, run.q, run.v)

    def _hold_rest(self, scene, run, modes, t_end) -> bool:
        """A body at rest (v = 0 within velocity_tol, a = 0 to round-off) in stick or flight under
        constant forces stays at rest, and no indicator can move: hold the state to t_end in one
        go instead of integrating nothing. An applied force may change in time: then integrate."""
        if scene.forces_vary_in_time() or any(m not in ("stick", "open") for m in modes):
            return False
        if np.max(np.abs(run.v), initial=0.0) > self.options.velocity_tol:
            return False
        v = np.zeros_like(run.v)
        dyn = self._dynamics(scene, run.t, run.q, v, modes)
        a_scale = float(np.max(np.abs(scene.inverse_mass_diagonal * scene.force(run.t, run.q, v))))
        if not np.all(np.abs(dyn.a) <= 1e-12 * a_scale):
            return False
        y = np.concatenate([run.q, v])
        run.rest_from = run.t
        for ts in grid_blocks(run.boundaries[0], self.options.output_dt, run.t, t_end):
            run.sample(ts, np.broadcast_to(y, (ts.size, y.size)), modes, dyn)
        run.close(float(t_end), y, modes, dyn)
        return True

    # ------------------------------------------------------------------ impacts
    def _impact(self, scene, t, q, v, hit):
        """Impulse-level impact of contact `hit` with every other closed contact taking part."""
        kin, gaps, u_N, u_T = self._local(scene, q, v)
        closed = [i for i in range(len(kin)) if gaps[i] <= self.options.gap_tol * 10 or i == hit]
        H = np.array([row for i in closed for row in (kin[i].H_N, kin[i].H_T)])
        minv = scene.inverse_mass_diagonal
        W = H @ (minv[:, None] * H.T)
        e = np.array([scene.contacts[i].law.impact.restitution for i in closed])
        qv = np.empty(2 * len(closed))
        for j, i in enumerate(closed):
            qv[2 * j] = (1.0 + e[j]) * min(u_N[i], 0.0) + max(u_N[i], 0.0)
            qv[2 * j + 1] = u_T[i]
        mu_s = np.array([scene.contacts[i].law.friction.mu_s for i in closed])
        mu_d = np.array([scene.contacts[i].law.friction.mu_d for i in closed])
        guess = np.sign([u_T[i] for i in closed]) * (np.abs([u_T[i] for i in closed]) > self.options.velocity_tol)
        res = solve_two_coefficient(W, qv, mu_s, mu_d, guess, solver=self.options.impact_solver)
        v_after = v + minv * (H.T @ res.p)
        pN = np.zeros(len(kin))
        pT = np.zeros(len(kin))
        for j, i in enumerate(closed):
            pN[i], pT[i] = res.p[2 * j], res.p[2 * j + 1]
        return v_after, pN, pT

    @staticmethod
    def _sliding_singular(scene, t, y, modes, t0, y0) -> bool:
        """Has the constrained system of a mode with sliding contacts become (nearly) singular
        since the segment started: |det A| fallen by three orders of magnitude?"""
        if not any(m in SLIP_SIGN for m in modes):
            return False
        n = scene.n_dof
        A0 = mode_dynamics(scene, t0, y0[:n], y0[n:], modes).matrix
        A1 = mode_dynamics(scene, t, y[:n], y[n:], modes).matrix
        if not A0.size:
            return False
        return abs(np.linalg.det(A1)) <= 1e-3 * abs(np.linalg.det(A0))

    def _check_accumulation(self, scene, t, q, v, i):
        """Stop with "zeno" when a rebound cannot leave the contact tolerance band: the next
        impacts would follow within it, ever closer (an accumulation point). The accumulation
        time of the remaining geometric series of hops is reported (exact for one contact
        under a constant force)."""
        contact = scene.contacts[i]
        k = contact.kinematics(q, v, scene.n_dof)
        u = float(k.H_N @ v)
        a = float(k.H_N @ (scene.inverse_mass_diagonal * scene.force(t, q, v))) + k.drift_N
        if u <= self.options.velocity_tol or a >= 0.0 or u * u / (-2.0 * a) > self.options.gap_tol:
            return
        e = contact.law.impact.restitution
        t_acc = t + (2.0 * u / -a) / (1.0 - e) if e < 1.0 else math.inf
        raise _Stop("zeno", f"impacts of {contact.name} accumulate at t = {t_acc:.12g} s (Zeno): the rebound "
                            f"at t = {t:.12g} s ({u:.3g} m/s) stays within the contact tolerance; the "
                            "event-driven scheme cannot pass an accumulation point",
                    {"t_accumulation": t_acc})

    # ------------------------------------------------------------------ results
    def _result(self, scene, run, names, status, message, cpu_time_s) -> SimulationResult:
        traj = self._trajectory(scene, run.kept_samples())
        phases = {}
        if len(run.boundaries) > 1:
            for ci, name in enumerate(names):
                phases[name] = phases_from_intervals(run.boundaries, [m[ci] for m in run.interval_modes])
        stats = {"nfev": run.nfev, "t_final": run.t, "indicator_evaluations": run.indicator_evaluations,
                 "rest_from": run.rest_from, "unresolved_impacts": run.unresolved_impacts}
        return SimulationResult(self.name, status, message, traj, names, run.events, run.impacts, phases,
                                steps=run.steps, cpu_time_s=cpu_time_s, stats=stats)

    def _trajectory(self, scene, blocks) -> Trajectory:
        """The samples with their accelerations and forces (from the mode each was taken in;
        a resting block carries its one solution)."""
        n_dof, nc = scene.n_dof, len(scene.contacts)
        n = sum(len(b[0]) for b in blocks)
        ts = np.concatenate([b[0] for b in blocks]) if blocks else np.empty(0)
        y = np.concatenate([b[1] for b in blocks]) if blocks else np.empty((0, 2 * n_dof))
        a = np.full((n, n_dof), np.nan)
        N = np.zeros((n, nc))
        T = np.zeros((n, nc))
        modes = np.empty((n, nc), dtype=object)
        row = 0
        for bt, by, bmodes, dyn in blocks:
            rows = slice(row, row + len(bt))
            modes[rows] = np.array(bmodes, dtype=object)
            if dyn is not None:
                a[rows], N[rows], T[rows] = dyn.a, dyn.normal_force, dyn.tangential_force
            else:
                for k in range(len(bt)):
                    d = self._dynamics(scene, bt[k], by[k, :n_dof], by[k, n_dof:], bmodes)
                    a[row + k], N[row + k], T[row + k] = d.a, d.normal_force, d.tangential_force
            row += len(bt)
        return Trajectory(ts, y[:, :n_dof], y[:, n_dof:], a, N, T, modes)


def _first_contact(kind):
    """A refusal's finder: the name of the scene's first contact `kind(contact)` holds for."""
    return first_item(lambda scene: (c.name for c in scene.contacts if kind(c)), "name")


# What the reference cannot run among the relations it takes, each said in one line.
POINT_ON_SEGMENT = Refusal(
    _first_contact(lambda c: isinstance(c, DiskOnSegment) and c.radius == 0.0),
    "the event-driven integrator does not handle a point (radius 0) on a segment: contact {name!r} would take the "
    "segment's side from the sign of a zero gap, which round-off flips while it touches; declare it as a "
    "VertexOnEdge on the segment's side (as found contacts are), or give it a radius")
SEGMENT_END = Refusal(
    _first_contact(lambda c: isinstance(c, SegmentEndOnEdge)),
    "the event-driven integrator does not handle a SegmentEndOnEdge (contact {name!r}): beyond the edge it is the "
    "edge's corner against the segment's end, a normal from point to point, undefined where they meet; declare it "
    "as a VertexOnEdge with vertex_body = -1 (as found contacts are)")
BODY_ON_BODY = Refusal(
    _first_contact(lambda c: len(c.bodies) != 1),
    "the event-driven integrator handles bodies against fixed obstacles only (lines, segments): contact {name!r} "
    "joins two bodies, and it lacks a mode choice for them (tried, it slides two stacked boxes that μs holds); use "
    "moreau-jean")

EventDriven.declares = Declaration(
    options=EventDrivenOptions, contacts=("DiskOnLine", "DiskOnSegment", "SegmentEndOnEdge", "VertexOnEdge"),
    samples_estimate=EventDriven.samples_estimate, samples_knob=EventDriven.SAMPLES_KNOB,
    refusals=(NO_JOINTS, NO_DRIVEN, STEP_CAP, POINT_ON_SEGMENT, SEGMENT_END, BODY_ON_BODY))
