"""The "dynamics package" baseline: smooth (regularised) friction and penalty contact, one ODE.

This is how MSC.ADAMS-style engines in their continuous mode — and the paper's own check — pose
the problem: no complementarity, no events; every contact force is a smooth function of the state
and a general-purpose ODE integrator (scipy's RK45, DOP853, Radau, BDF, LSODA) does the rest.

Normal force, per contact, from the penetration δ = −gap and its rate δ̇ = −u_N (clipped ≥ 0):

* ``hunt-crossley`` (default): N = k δⁿ (1 + α δ̇)   (k in N/mⁿ, n = `exponent`, α in s/m);
* ``spring-damper``:           N = k δ + c δ̇        (k in N/m, c = `damping` in N·s/m).

The defaults are a steel ball of radius 20 mm on a steel plate: Hertz's k = (4/3) E* √R ≈ 2e10
N/m^1.5 with n = 1.5, and α = 500 s/m, which damps the resting contact's vibration to a damping
ratio ζ ≈ (α/2) √(N δ / (n m)) ≈ 0.3 for the rod (N ≈ 5 N, δ ≈ 0.4 µm, m ≈ 0.3 kg) and makes a
closing contact stop without rebound (e ≈ 0, the paper's case).

Friction, T = −μ(u_T) N with u_T the slip velocity and ε the regularisation velocity:

* ``linear`` (paper Fig. 3a): μ(v) = μd · clip(v/ε, −1, 1);
* ``tanh``:                   μ(v) = μd · tanh(v/ε);
* ``stribeck`` (paper Fig. 6, MSC.ADAMS's contact friction): μ(v) = sgn(v) μs · step(|v|; 0 → ε)
  for |v| ≤ ε, then sgn(v) (μs + (μd − μs) step(|v|; ε → ρε)) up to ρε (ρ = `stribeck_ratio`,
  ADAMS's friction/stiction transition velocity ratio, 10 by default), μd beyond;
  step(x; a → b) = s² (3 − 2s), s = (x − a)/(b − a) — ADAMS's cubic STEP.

The linear and tanh curves know one coefficient (μd, the sliding one) and cannot hold a contact
that needs more; only the Stribeck curve has a static peak μs. No curve can stick exactly: a held
contact creeps at the velocity where μ(v) N equals the force it must hold (≈ ε for a held
contact).

Contact states for output and phases: "open" while gap > 0, "stick" while |u_T| <
`stick_velocity` (1e-4 m/s by default), else "slip+"/"slip-"; phases shorter than `min_phase`
(1 ms by default: the passage of u_T through the stick band at a slip reversal) are merged.

The run stops with a status word instead of hanging: "time-limit" (wall clock), "step-size-collapse"
(scipy's "required step size is less than spacing between numbers"), "nan", "penetration"
(beyond `max_penetration`), or "ok".
"""
from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import BDF, DOP853, LSODA, RK23, RK45, Radau
from scipy.optimize import brentq

from ..model.contacts import DiskOnLine
from ..model.scene import Scene
from ..results import Event, Impact, SimulationResult, Trajectory, merge_short_phases, Phase
from ..validation import Choice, InputError, Number, Text, check_options, option
from .declaration import NO_DRIVEN, NO_JOINTS, STEP_CAP, Declaration
from .event_driven import ATOL_CEILING, RTOL_FLOOR
from .sampling import OUTPUT_DT_KNOB, Thinning, stop_event, stop_message, output_dt_samples

FRICTION_CURVES = ("stribeck", "tanh", "linear")
ODE_METHODS = {"RK45": RK45, "DOP853": DOP853, "Radau": Radau, "BDF": BDF, "LSODA": LSODA, "RK23": RK23}
EXPLICIT_METHODS = ("RK45", "DOP853", "RK23")
CONTACT_MODELS = ("hunt-crossley", "spring-damper")

HERTZ_STEEL_STIFFNESS = 2.0e10  # N/m^1.5: (4/3) E* √R, E* = 1.15e11 Pa, R = 20 mm
DEFAULT_HC_DAMPING = 500.0  # s/m (α of Hunt–Crossley)
# Penalty parameters within which the contact force k δ^n (1 + α δ̇) stays far from overflow
# for penetrations and speeds the run can reach (beyond, k = 1e300 gave a "math domain error"
# or |q| ≈ 1e239 with status ok).
STIFFNESS_RANGE = (1.0, 1e15)
DAMPING_RANGE = (0.0, 1e9)


def _cubic_step(x: float, x0: float, x1: float) -> float:
    """ADAMS's STEP from 0 at x0 to 1 at x1 (C¹: s² (3 − 2 s))."""
    if x <= x0:
        return 0.0
    if x >= x1:
        return 1.0
    s = (x - x0) / (x1 - x0)
    return s * s * (3.0 - 2.0 * s)


def friction_coefficient(curve: str, v: float, eps: float, mu_s: float, mu_d: float,
                         stribeck_ratio: float = 10.0) -> float:
    """Signed μ(v) of a regularised friction curve (T = −μ(v) N)."""
    if curve == "tanh":
        return mu_d * math.tanh(v / eps)
    if curve == "linear":
        return mu_d * max(-1.0, min(1.0, v / eps))
    if curve == "stribeck":
        a = abs(v)
        if a <= eps:
            m = mu_s * _cubic_step(a, 0.0, eps)
        else:
            m = mu_s + (mu_d - mu_s) * _cubic_step(a, eps, stribeck_ratio * eps)
        return math.copysign(m, v) if a > 0.0 else 0.0
    raise InputError(f"unknown friction curve '{curve}'; choose from: {', '.join(FRICTION_CURVES)}")


@dataclass
class RegularizedOptions:
    """Regularised friction, penalty contact, and the ODE integrator that runs them."""

    # regularisation (stiction transition) velocity, m/s
    epsilon: float = option(1e-4, Number(1e-12, 10.0), label="epsilon (regularisation velocity)")
    friction_curve: str = option("stribeck", Choice(FRICTION_CURVES))
    # friction transition velocity / ε (Stribeck curve only)
    stribeck_ratio: float = option(10.0, Number(1.0, 1e6, open_lo=True))
    ode_method: str = option("RK45", Choice(tuple(ODE_METHODS)))
    rtol: float = option(1e-6, Number(RTOL_FLOOR, 0.1))
    atol: float = option(1e-9, Number(0.0, ATOL_CEILING, open_lo=True))
    contact_model: str = option("hunt-crossley", Choice(CONTACT_MODELS))
    stiffness: float = option(HERTZ_STEEL_STIFFNESS, Number(*STIFFNESS_RANGE))
    exponent: float = option(1.5, Number(1.0, 3.0))  # Hunt–Crossley only
    # α [s/m] (Hunt–Crossley) or c [N·s/m] (spring–damper)
    damping: float | None = option(None, Number(*DAMPING_RANGE, optional=True))
    # |u_T| below this counts as stick in the output, m/s
    stick_velocity: float = option(1e-4, Number(0.0, 1.0, open_lo=True), label="stick velocity")
    min_phase: float = option(1e-3, Number(0.0))  # s
    output_dt: float = option(1e-3, Number(0.0, open_lo=True))  # spacing of saved samples, s
    # name of a contact whose first touchdown ends the run
    stop_at_impact: str | None = option(None, Text())
    # wall-clock seconds; then status "time-limit"
    time_limit: float | None = option(None, Number(0.0, open_lo=True, optional=True))
    max_penetration: float = option(1e-3, Number(0.0, 1.0, open_lo=True))  # m; deeper: status "penetration"
    first_step: float | None = option(None, Number(0.0, open_lo=True, optional=True))
    max_step: float = option(math.inf, Number(0.0, open_lo=True, infinite=True))

    def __post_init__(self):
        check_options(self)
        if self.damping is None:
            # Spring–damper: critical-ish damping of a 0.3 kg body on the default spring.
            self.damping = DEFAULT_HC_DAMPING if self.contact_model == "hunt-crossley" else 2.0 * math.sqrt(
                self.stiffness * 0.3)


class _TimeLimit(Exception):
    pass


class _Contact:
    """Plain-float kinematics of a disk on a line (the RHS runs it millions of times)."""

    def __init__(self, c: DiskOnLine):
        self.i = 3 * c.body
        self.ox, self.oy = float(c.offset[0]), float(c.offset[1])
        self.nx, self.ny = c.line.normal
        self.tx, self.ty = c.line.tangent
        self.px, self.py = float(c.line.point[0]), float(c.line.point[1])
        self.r = float(c.radius)
        self.belt = float(c.line.velocity)

    def local(self, y, n_dof):
        """gap, u_N, u_T and the lever arms ρ×n, ρ×t."""
        i = self.i
        x, yy, th = y[i], y[i + 1], y[i + 2]
        vx, vy, om = y[n_dof + i], y[n_dof + i + 1], y[n_dof + i + 2]
        c, s = math.cos(th), math.sin(th)
        dx, dy = c * self.ox - s * self.oy, s * self.ox + c * self.oy
        nx, ny, tx, ty = self.nx, self.ny, self.tx, self.ty
        gap = nx * (x + dx - self.px) + ny * (yy + dy - self.py) - self.r
        rx, ry = dx - self.r * nx, dy - self.r * ny
        arm_n = rx * ny - ry * nx
        arm_t = rx * ty - ry * tx
        u_N = nx * vx + ny * vy + arm_n * om
        u_T = tx * vx + ty * vy + arm_t * om - self.belt
        return gap, u_N, u_T, arm_n, arm_t


@dataclass
class _Record:
    """What a regularised run collects as it goes."""

    names: list
    wall0: float
    cpu0: float
    stop_index: int | None
    message: str
    status: str = "ok"
    t_stop: float | None = None
    steps: int = 0
    max_penetration: float = 0.0
    thinning: Thinning = None
    t0: float = 0.0
    next_sample: int = 1  # the next sample of the output grid t0 + k·output_dt
    samples_t: list = field(default_factory=list)
    samples_y: list = field(default_factory=list)
    step_sizes: list = field(default_factory=list)
    events: list = field(default_factory=list)
    impacts: list = field(default_factory=list)
    local: list = field(default_factory=list)
    states: list = field(default_factory=list)
    changes: list = field(default_factory=list)


class _LazyDense:
    """The step's dense output, built on first use (most steps need none)."""

    def __init__(self, solver):
        self._solver, self._dense = solver, None

    def __call__(self):
        if self._dense is None:
            self._dense = self._solver.dense_output()
        return self._dense


class Regularized:
    """Regularised friction + penalty contact, integrated by a scipy ODE solver step by step."""

    name = "regularized"

    SAMPLES_KNOB = OUTPUT_DT_KNOB
    samples_estimate = staticmethod(output_dt_samples)

    def __init__(self, options: RegularizedOptions | None = None):
        self.options = options or RegularizedOptions()

    # ------------------------------------------------------------------ forces
    def _normal(self, delta: float, delta_dot: float) -> float:
        o = self.options
        if delta <= 0.0:
            return 0.0
        if o.contact_model == "hunt-crossley":
            n = o.stiffness * delta**o.exponent * (1.0 + o.damping * delta_dot)
        else:
            n = o.stiffness * delta + o.damping * delta_dot
        return n if n > 0.0 else 0.0

    def _forces(self, y):
        """Per contact: (N, T, gap, u_T, arm_n, arm_t)."""
        o = self.options
        out = []
        for c, law in zip(self._contacts, self._laws):
            gap, u_N, u_T, arm_n, arm_t = c.local(y, self._n_dof)
            N = self._normal(-gap, -u_N)
            T = 0.0
            if N > 0.0 and law.mu_s > 0.0:
                T = -friction_coefficient(o.friction_curve, u_T, o.epsilon, law.mu_s, law.mu_d,
                                          o.stribeck_ratio) * N
            out.append((N, T, gap, u_T, arm_n, arm_t))
        return out

    def _rhs(self, t, y):
        self._nfev += 1
        if self._nfev % 64 == 0 and self._deadline is not None and time.perf_counter() > self._deadline:
            raise _TimeLimit
        n = self._n_dof
        gen = np.array(self._scene.force(t, y[:n], y[n:]), dtype=float)
        for c, (N, T, _, _, arm_n, arm_t) in zip(self._contacts, self._forces(y)):
            if N == 0.0:
                continue
            i = c.i
            gen[i] += N * c.nx + T * c.tx
            gen[i + 1] += N * c.ny + T * c.ty
            gen[i + 2] += N * arm_n + T * arm_t
        out = np.empty(2 * n)
        out[:n] = y[n:]
        out[n:] = gen * self._minv
        return out

    def _state_of(self, gap, u_T):
        if gap > 0.0:
            return "open"
        if abs(u_T) < self.options.stick_velocity:
            return "stick"
        return "slip+" if u_T > 0 else "slip-"

    # ------------------------------------------------------------------ main loop
    def run(self, scene: Scene, q0, v0, t_end: float, *, t0: float = 0.0, resume=None, save_every: float | None = None,
            stop=()) -> SimulationResult:
        """Integrate from (q0, v0) at t0 to t_end on the scene's clock (or the stop contact's
        touchdown), keeping one sample per `save_every` (default: every output_dt) and ending at
        the first kept sample where a `stop` callable (t, q, v) holds. `resume` is not used."""
        # Implicit methods try states far off the solution (rejected steps, Jacobian columns):
        # their overflows are not results. A non-finite accepted state ends the run as "nan".
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            return self._run(scene, q0, v0, t_end, Thinning(t0, save_every, stop))

    def _run(self, scene: Scene, q0, v0, t_end: float, thinning: Thinning) -> SimulationResult:
        solver, rec = self._start(scene, q0, v0, t_end, thinning)
        try:
            while solver.status == "running" and rec.status == "ok" and rec.t_stop is None:
                self._step(solver, rec)
        except _TimeLimit:
            rec.status = "time-limit"
            rec.message = f"wall-clock limit of {self.options.time_limit:g} s reached at t = {solver.t:.9g} s"
        return self._finish(solver, rec)

    def _start(self, scene: Scene, q0, v0, t_end: float, thinning: Thinning):
        """The ODE solver at t0 and the record of the run (samples, states, events)."""
        o = self.options
        self._scene = scene
        self._n_dof = n = scene.n_dof
        self._minv = scene.inverse_mass_diagonal
        self._contacts = [_Contact(c) for c in scene.contacts]
        self._laws = [c.law.friction for c in scene.contacts]
        self._nfev = 0
        names = [c.name for c in scene.contacts]
        rec = _Record(names=names, wall0=time.perf_counter(), cpu0=time.process_time(),
                      stop_index=names.index(o.stop_at_impact) if o.stop_at_impact in names else None,
                      message=f"reached t_end = {t_end:g} s", thinning=thinning, t0=thinning.t0)
        self._deadline = None if o.time_limit is None else rec.wall0 + o.time_limit
        y = np.concatenate([np.asarray(q0, float), np.asarray(v0, float)])
        kwargs = dict(rtol=o.rtol, atol=o.atol, max_step=o.max_step)
        if o.first_step is not None:
            kwargs["first_step"] = o.first_step
        solver = ODE_METHODS[o.ode_method](self._rhs, rec.t0, y, t_end, **kwargs)
        rec.samples_t, rec.samples_y = [rec.t0], [y.copy()]
        thinning.keeps(rec.t0)
        if thinning.first_stop([rec.t0], [y[:n].copy()], [y[n:].copy()]) is not None:
            rec.t_stop, rec.status, rec.message = rec.t0, "stopped", stop_message(rec.t0)
        rec.local = [c.local(y, n) for c in self._contacts]
        states = [self._state_of(g, u) for g, _, u, _, _ in rec.local]
        # A contact starting exactly at gap 0 with no approach velocity is resting, not open.
        rec.states = [("stick" if s == "open" and abs(loc[0]) < 1e-12 else s) for s, loc in zip(states, rec.local)]
        rec.changes = [[(rec.t0, s)] for s in rec.states]
        return solver, rec

    def _step(self, solver, rec) -> None:
        """One accepted step: touchdown of the stop contact, state changes, output samples."""
        o, n = self.options, self._n_dof
        t_old = solver.t
        msg = solver.step()
        if solver.status == "failed":
            rec.status, rec.message = "step-size-collapse", f"{o.ode_method} failed at t = {solver.t:.9g} s: {msg}"
            return
        rec.steps += 1
        rec.step_sizes.append(solver.t - t_old)
        if not np.all(np.isfinite(solver.y)):
            rec.status, rec.message = "nan", f"non-finite state at t = {solver.t:.9g} s"
            return
        dense = _LazyDense(solver)
        new_local = [c.local(solver.y, n) for c in self._contacts]
        if rec.stop_index is not None and rec.local[rec.stop_index][0] > 0.0 >= new_local[rec.stop_index][0]:
            self._touchdown(rec, dense, t_old, solver.t)
        t_limit = rec.t_stop if rec.t_stop is not None else solver.t
        t_held = self._take_samples(rec, dense, t_limit)
        if t_held is not None:  # a stop condition holds there: the run ends at that sample
            if rec.t_stop is not None and t_held < rec.t_stop:  # before the stop contact's touchdown
                rec.impacts.pop()
                rec.events.pop()
            rec.t_stop, t_limit = t_held, t_held
            rec.status, rec.message = "stopped", stop_message(t_held)
            new_local = [c.local(dense()(t_held), n) for c in self._contacts]
        for ci, c in enumerate(self._contacts):
            new_state = self._state_of(new_local[ci][0], new_local[ci][2])
            if new_state != rec.states[ci]:
                rec.changes[ci].append((self._locate(c, dense(), t_old, t_limit, rec.states[ci], new_state),
                                        new_state))
                rec.states[ci] = new_state
            rec.max_penetration = max(rec.max_penetration, -new_local[ci][0])
        rec.local = new_local
        if rec.status == "stopped":
            return
        if rec.t_stop is not None:
            rec.samples_t.append(rec.t_stop)
            rec.samples_y.append(dense()(rec.t_stop))
            rec.message = f"stopped at the touchdown of {o.stop_at_impact}"
        elif rec.max_penetration > o.max_penetration:
            rec.status = "penetration"
            rec.message = (f"penetration {rec.max_penetration:.3g} m exceeds {o.max_penetration:g} m at "
                           f"t = {solver.t:.9g} s")

    def _take_samples(self, rec, dense, t_limit: float) -> float | None:
        """The output grid's samples up to t_limit, the kept ones stored; the time of the first
        kept one where a stop condition holds (the samples end there), or None."""
        n, dt = self._n_dof, self.options.output_dt
        while (t := rec.t0 + rec.next_sample * dt) <= t_limit:
            rec.next_sample += 1
            if not rec.thinning.keeps(t)[0]:
                continue
            y = dense()(t)
            rec.samples_t.append(float(t))
            rec.samples_y.append(y)
            if rec.thinning.first_stop([t], [y[:n].copy()], [y[n:].copy()]) is not None:
                return float(t)
        return None

    def _touchdown(self, rec, dense, t_old: float, t_new: float) -> None:
        """The stop contact's gap closed within the step: its root on the dense output."""
        n, i = self._n_dof, rec.stop_index
        c = self._contacts[i]
        t_hit = brentq(lambda tt: c.local(dense()(tt), n)[0], t_old, t_new, xtol=1e-14, rtol=1e-15)
        y_hit = dense()(t_hit)
        nc = len(rec.names)
        rec.impacts.append(Impact(t_hit, rec.names[i], y_hit[:n].copy(), y_hit[n:].copy(), y_hit[n:].copy(),
                                  np.zeros(nc), np.zeros(nc)))
        rec.events.append(Event(t_hit, "impact", rec.names[i], {"model": "penalty"}))
        rec.t_stop = t_hit

    def _finish(self, solver, rec) -> SimulationResult:
        o = self.options
        t_final = rec.t_stop if rec.t_stop is not None else float(solver.t)
        if rec.samples_t[-1] < t_final and rec.t_stop is None:
            rec.samples_t.append(float(solver.t))
            rec.samples_y.append(solver.y.copy())
        traj = self._trajectory(rec.samples_t, rec.samples_y)
        phases = {name: self._phases(rec.changes[ci], t_final) for ci, name in enumerate(rec.names)}
        if rec.status == "stopped":
            rec.events.append(stop_event(t_final))
        elif rec.status != "ok":
            rec.events.append(Event(t_final, rec.status, "", {"message": rec.message}))
        h_arr = np.array(rec.step_sizes) if rec.step_sizes else np.array([np.nan])
        stats = {"nfev": self._nfev, "njev": int(getattr(solver, "njev", 0)), "nlu": int(getattr(solver, "nlu", 0)),
                 "steps": rec.steps, "min_step": float(np.min(h_arr)), "median_step": float(np.median(h_arr)),
                 "max_penetration": rec.max_penetration, "t_final": t_final,
                 "wall_time_s": time.perf_counter() - rec.wall0, "epsilon": o.epsilon,
                 "friction_curve": o.friction_curve, "ode_method": o.ode_method, "rtol": o.rtol, "atol": o.atol}
        self.step_sizes = np.array(rec.step_sizes)  # kept for step-size histories
        return SimulationResult(self.name, rec.status, rec.message, traj, rec.names, rec.events, rec.impacts,
                                phases, steps=rec.steps, cpu_time_s=time.process_time() - rec.cpu0, stats=stats)

    def _phases(self, changes, t_final: float) -> list[Phase]:
        """One contact's phases from its state changes (time, new state)."""
        ph = []
        for j, (ts, st) in enumerate(changes):
            te = changes[j + 1][0] if j + 1 < len(changes) else t_final
            if te > ts or not ph:
                ph.append(Phase(st, ts, max(te, ts)))
        return merge_short_phases(ph, self.options.min_phase)

    def _locate(self, c: _Contact, dense, t0, t1, old, new) -> float:
        """Time within [t0, t1] at which the contact left state `old` (root of the boundary)."""
        n, thr = self._n_dof, self.options.stick_velocity
        if old == "open" or new == "open":
            f = lambda tt: c.local(dense(tt), n)[0]  # noqa: E731
        elif old == "stick" or new == "stick":
            side = new if new != "stick" else old
            sgn = 1.0 if side == "slip+" else -1.0
            f = lambda tt: sgn * c.local(dense(tt), n)[2] - thr  # noqa: E731
        else:  # slip+ ↔ slip- within one step: the zero of u_T
            f = lambda tt: c.local(dense(tt), n)[2]  # noqa: E731
        try:
            if f(t0) * f(t1) < 0.0:
                return float(brentq(f, t0, t1, xtol=1e-13))
        except ValueError:
            pass
        return float(t1)

    def _trajectory(self, ts, ys) -> Trajectory:
        n, nc = self._n_dof, len(self._contacts)
        ys = np.array(ys).reshape(len(ts), 2 * n)
        a = np.empty((len(ts), n))
        N = np.zeros((len(ts), nc))
        T = np.zeros((len(ts), nc))
        modes = np.empty((len(ts), nc), dtype=object)
        deadline, self._deadline = self._deadline, None
        for k, y in enumerate(ys):
            a[k] = self._rhs(ts[k], y)[n:] if np.all(np.isfinite(y)) else np.nan
            for ci, (Nk, Tk, gap, u_T, _, _) in enumerate(self._forces(y)):
                N[k, ci], T[k, ci] = Nk, Tk
                modes[k, ci] = self._state_of(gap, u_T)
        self._deadline = deadline
        return Trajectory(np.array(ts, dtype=float), ys[:, :n].copy(), ys[:, n:].copy(), a, N, T, modes)


Regularized.declares = Declaration(
    options=RegularizedOptions, contacts=("DiskOnLine",), samples_estimate=Regularized.samples_estimate,
    samples_knob=Regularized.SAMPLES_KNOB, refusals=(NO_JOINTS, NO_DRIVEN, STEP_CAP))
