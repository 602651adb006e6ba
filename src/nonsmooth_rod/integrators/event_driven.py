"""Event-driven (hybrid) integration: smooth modes joined by located, refined events.

Within a mode (each contact open, sticking or sliding) the scene is a smooth ODE integrated
with a high-order method (DOP853, tight tolerances). Mode changes are located as roots of
event functions on the dense output (scipy refines them to a few ulps of t):

* sticking contact: T − μs N = 0 (rising) or T + μs N = 0 (falling) → slip against it;
* sliding contact: slip velocity = 0 → re-stick if the sticking solution has |T| ≤ μs N,
  else slip the other way (the re-stick test the paper's treatment misses);
  and A = H_N M⁻¹ (H_N − s μd H_T) → 0: Painlevé, stop with status "painleve";
* closed contact: N = 0 (falling) → contact opens (flight);
* open contact: gap = 0 (falling) → impact, solved at impulse level with Newton restitution
  and two-coefficient Coulomb friction on the impulses (see onestep.py).

The choice of modes at a switch enumerates the candidate modes of the contacts that are
"at a decision" and keeps the first consistent one, preferring stick (a contact that μs can
hold is held: this is what makes the paper's bistable start roll).
"""
from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from ..model.dynamics import SLIP_SIGN, mode_dynamics
from ..model.scene import Scene
from ..solvers.two_coefficient import solve_two_coefficient
from ..results import Event, Impact, SimulationResult, Trajectory, phases_from_intervals
from ..validation import InputError, require_positive


@dataclass
class EventDrivenOptions:
    """Accuracy and stopping controls of the event-driven integrator."""

    rtol: float = 1e-12
    atol: float = 1e-12
    method: str = "DOP853"
    output_dt: float = 1e-3  # spacing of the saved samples (events are always saved)
    # Events are seen as sign changes between steps: a loose tolerance lets DOP853 step clean
    # over a short excursion (case 2's T/N > μs lasts 0.1 s) and miss it. Cap the step.
    max_step: float = 1e-2
    stop_at_impact: str | None = None  # name of a contact whose first impact ends the run
    max_events: int = 10_000
    zeno_interval: float = 1e-9  # impacts closer than this in time: an accumulation point
    impact_solver: str = "enum"
    gap_tol: float = 1e-9
    velocity_tol: float = 1e-9

    def __post_init__(self):
        require_positive("rtol", self.rtol)
        require_positive("atol", self.atol)
        require_positive("output_dt", self.output_dt)
        if not (isinstance(self.max_step, (int, float)) and self.max_step > 0):  # inf: no cap
            raise InputError(f"max_step must be positive, got {self.max_step!r}")


class _Stop(Exception):
    def __init__(self, status, message, detail=None):
        self.status = status
        self.message = message
        self.detail = detail or {}


@dataclass
class _Segment:
    t: list = field(default_factory=list)
    y: list = field(default_factory=list)
    modes: list = field(default_factory=list)


class EventDriven:
    """Event-driven integrator for scenes whose contacts are disks or points on lines."""

    name = "event-driven"

    def __init__(self, options: EventDrivenOptions | None = None):
        self.options = options or EventDrivenOptions()

    # ------------------------------------------------------------------ helpers
    def _local(self, scene, q, v):
        kin = scene.kinematics(q, v)
        u_N = np.array([k.H_N @ v for k in kin])
        u_T = np.array([k.H_T @ v - k.surface_velocity for k in kin])
        gaps = np.array([k.gap for k in kin])
        return kin, gaps, u_N, u_T

    def _consistent(self, scene, t, q, v, modes, kin, u_T, decided):
        """Is this mode assignment consistent at (q, v)? Returns the ModeDynamics or None."""
        dyn = mode_dynamics(scene, t, q, v, modes, kin)
        if not np.all(np.isfinite(dyn.a)):
            return None
        fscale = max(1e-12, float(np.max(np.abs(scene.force(t, q, v)))))
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
            if mode != "stick" and dyn.matrix.size and np.min(np.linalg.eigvals(dyn.matrix).real) <= 0:
                return None
        return dyn

    def _decide(self, scene, t, q, v, forced=None):
        """Modes after a switch: contacts in `forced` take one of the listed modes, the other
        contacts at a decision (closed, at rest normally) are enumerated; stick first."""
        forced = forced or {}
        kin, gaps, u_N, u_T = self._local(scene, q, v)
        vt = self.options.velocity_tol
        candidates, decided = [], []
        for i in range(len(kin)):
            if i in forced:
                candidates.append(list(forced[i]))
                decided.append(True)
            elif gaps[i] > self.options.gap_tol or u_N[i] > vt:
                candidates.append(["open"])
                decided.append(False)
            elif abs(u_T[i]) > vt:
                candidates.append(["slip+" if u_T[i] > 0 else "slip-", "open"])
                decided.append(True)
            else:
                order = ["stick", "slip+", "slip-", "open"]
                if scene.contacts[i].law.friction.mu_s == 0.0:
                    order = ["slip+", "open"]  # frictionless: no tangential force either way
                candidates.append(order)
                decided.append(True)
        for modes in itertools.product(*candidates):
            modes = list(modes)
            # A frictionless contact at rest tangentially "slides" with zero force.
            if self._consistent(scene, t, q, v, modes, kin, u_T,
                                [d and not (m == "slip+" and scene.contacts[i].law.friction.mu_s == 0.0)
                                 for i, (d, m) in enumerate(zip(decided, modes))]) is not None:
                return modes
        raise _Stop("painleve",
                    f"no consistent contact mode at t = {t:.12g} s (modes tried from {candidates}): "
                    "the sliding problem has no solution here (Painlevé-type inconsistency)")

    def _event_functions(self, scene, modes, q0=None, v0=None):
        """Event functions of the current mode, with what each one means."""
        funcs, meanings = [], []
        opts = self.options
        n_dof = scene.n_dof
        start_gaps = ([k.gap for k in scene.kinematics(q0, v0)] if q0 is not None
                      else [math.inf] * len(modes))

        def split(y):
            return y[:n_dof], y[n_dof:]

        for i, mode in enumerate(modes):
            law = scene.contacts[i].law.friction
            contact = scene.contacts[i]

            if mode == "open":
                if start_gaps[i] <= opts.gap_tol:
                    # A flight that starts at the line (a rebound) starts a few ulps above,
                    # on or below it: a short hop then crosses zero twice within one integrator
                    # step, or "crosses" at the start, and the touchdown is missed (the body
                    # falls through) or found at once. Watch for the apex first; from there
                    # the touchdown is a single, detectable crossing.
                    def apex_event(t, y, contact=contact):
                        q, v = split(y)
                        return float(contact.kinematics(q, v, n_dof).H_N @ v)
                    apex_event.terminal, apex_event.direction = True, -1
                    funcs.append(apex_event)
                    meanings.append(("apex", i))
                    continue
                def gap_event(t, y, contact=contact):
                    q, v = split(y)
                    return contact.kinematics(q, v, n_dof).gap
                gap_event.terminal, gap_event.direction = True, -1
                funcs.append(gap_event)
                meanings.append(("touchdown", i))
                continue

            def normal_event(t, y, i=i):
                q, v = split(y)
                return mode_dynamics(scene, t, q, v, modes).normal_force[i]
            normal_event.terminal, normal_event.direction = True, -1
            funcs.append(normal_event)
            meanings.append(("liftoff", i))

            if mode == "stick":
                if law.mu_s == 0.0:
                    continue

                def upper(t, y, i=i, mu=law.mu_s):
                    q, v = split(y)
                    d = mode_dynamics(scene, t, q, v, modes)
                    return d.tangential_force[i] - mu * d.normal_force[i]
                upper.terminal, upper.direction = True, 1

                def lower(t, y, i=i, mu=law.mu_s):
                    q, v = split(y)
                    d = mode_dynamics(scene, t, q, v, modes)
                    return d.tangential_force[i] + mu * d.normal_force[i]
                lower.terminal, lower.direction = True, -1
                funcs += [upper, lower]
                meanings += [("break-upper", i), ("break-lower", i)]
            else:
                if law.mu_s > 0.0:
                    def slip_event(t, y, contact=contact):
                        q, v = split(y)
                        k = contact.kinematics(q, v, n_dof)
                        return k.H_T @ v - k.surface_velocity
                    # Only the crossing back through zero counts, not the start of the slip at zero.
                    slip_event.terminal, slip_event.direction = True, (-1 if mode == "slip+" else 1)
                    funcs.append(slip_event)
                    meanings.append(("slip-zero", i))
                if law.mu_d > 0.0:
                    def painleve(t, y):
                        q, v = split(y)
                        A = mode_dynamics(scene, t, q, v, modes).matrix
                        return float(np.linalg.det(A))
                    painleve.terminal, painleve.direction = True, -1
                    funcs.append(painleve)
                    meanings.append(("painleve", i))
        return funcs, meanings

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

    # ------------------------------------------------------------------ main loop
    def run(self, scene: Scene, q0, v0, t_end: float) -> SimulationResult:
        require_positive("t_end", t_end)
        opts = self.options
        for c in scene.contacts:
            if not hasattr(c, "line"):
                raise InputError("the event-driven integrator handles disk/point-on-line contacts only")
        wall = time.process_time()
        n_dof = scene.n_dof
        names = [c.name for c in scene.contacts]
        t = 0.0
        q = np.array(q0, dtype=float)
        v = np.array(v0, dtype=float)
        events: list[Event] = []
        impacts: list[Impact] = []
        samples_t, samples_y, samples_modes = [], [], []
        boundaries, interval_modes = [0.0], []
        status, message = "ok", "reached t_end"
        steps = 0
        nfev = 0
        last_impact_t = -math.inf
        try:
            modes = self._decide(scene, t, q, v)
            events.append(Event(0.0, "start", "", {"modes": list(modes)}))
            grid = np.arange(0.0, t_end + 0.5 * opts.output_dt, opts.output_dt)
            grid = grid[grid <= t_end]
            n_events = 0
            while t < t_end:
                n_events += 1
                if n_events > opts.max_events:
                    raise _Stop("too-many-events", f"more than {opts.max_events} events before t = {t:.6g} s")
                y0 = np.concatenate([q, v])
                funcs, meanings = self._event_functions(scene, modes, q, v)
                frozen = list(modes)

                def rhs(tt, y):
                    qq, vv = y[:n_dof], y[n_dof:]
                    a = mode_dynamics(scene, tt, qq, vv, frozen).a
                    return np.concatenate([vv, a])

                sol = solve_ivp(rhs, (t, t_end), y0, method=opts.method, rtol=opts.rtol, atol=opts.atol,
                                max_step=opts.max_step,
                                events=funcs or None, dense_output=True)
                steps += int(sol.t.size - 1)
                nfev += int(sol.nfev)
                singular_stop = False
                if sol.status == -1:
                    if not self._sliding_singular(scene, sol.t[-1], sol.y[:, -1], modes, t, y0):
                        raise _Stop("failed", f"integration failed at t = {sol.t[-1]:.6g} s: {sol.message}")
                    # The integrator stalled as A → 0 with the normal force unbounded, before the
                    # painleve event (det A = 0) could be bracketed: the same stop, reached from
                    # inside the consistent region. Keep the samples up to there.
                    singular_stop = True
                # Which event ended the segment (earliest; ties resolved by order)?
                t_stop, which = sol.t[-1], None
                if sol.status == 1:
                    best = math.inf
                    for j, te in enumerate(sol.t_events):
                        if te.size and te[0] < best:
                            best, which = te[0], j
                    t_stop = best
                y_stop = sol.sol(t_stop) if which is not None else sol.y[:, -1]
                inside = grid[(grid >= t) & (grid < t_stop)]
                for tt in inside:
                    samples_t.append(tt)
                    samples_y.append(sol.sol(tt))
                    samples_modes.append(list(modes))
                samples_t.append(t_stop)
                samples_y.append(y_stop)
                samples_modes.append(list(modes))
                boundaries.append(t_stop)
                interval_modes.append(list(modes))
                t = t_stop
                q, v = y_stop[:n_dof].copy(), y_stop[n_dof:].copy()
                if singular_stop:
                    raise _Stop("painleve",
                                f"Painlevé configuration at t = {t:.12g} s: the sliding problem loses "
                                "consistency (A → 0) with the normal force growing without bound; the run "
                                "stops here")
                if which is None:
                    break
                kind, i = meanings[which]
                forced = {}
                if kind == "apex":
                    modes = self._decide(scene, t, q, v)
                    continue
                if kind == "painleve":
                    raise _Stop("painleve",
                                f"Painlevé configuration at t = {t:.12g} s: sliding of contact {names[i]} "
                                "loses consistency (J/M + ξ cos θ·D → 0); the run stops here")
                if kind in ("break-upper", "break-lower"):
                    forced[i] = ["slip-" if kind == "break-upper" else "slip+"]
                    events.append(Event(t, "stick-slip", names[i], {"to": forced[i][0]}))
                elif kind == "liftoff":
                    forced[i] = ["open"]
                    events.append(Event(t, "liftoff", names[i]))
                elif kind == "slip-zero":
                    events.append(Event(t, "slip-zero", names[i], {"from": modes[i]}))
                    # The slip velocity has just crossed zero: re-stick if μs holds, else reverse.
                    forced[i] = ["stick", "slip+" if modes[i] == "slip-" else "slip-"]
                elif kind == "touchdown":
                    v_before = v.copy()
                    v, pN, pT = self._impact(scene, t, q, v, i)
                    if t - last_impact_t < opts.zeno_interval:
                        raise _Stop("zeno", f"impacts accumulate at t = {t:.12g} s (Zeno): the event-driven "
                                            "scheme cannot pass an accumulation point")
                    last_impact_t = t
                    impacts.append(Impact(t, names[i], q.copy(), v_before, v.copy(), pN, pT))
                    events.append(Event(t, "impact", names[i]))
                    samples_t.append(t)
                    samples_y.append(np.concatenate([q, v]))
                    samples_modes.append(list(modes))
                    if opts.stop_at_impact == names[i]:
                        status, message = "ok", f"stopped at the impact of {names[i]}"
                        break
                    self._check_accumulation(scene, t, q, v, i)
                new_modes = self._decide(scene, t, q, v, forced)
                if kind == "slip-zero":
                    events[-1].detail["to"] = new_modes[i]
                modes = new_modes
        except _Stop as stop:
            status, message = stop.status, stop.message
            events.append(Event(t, status, "", {"message": message, **stop.detail}))
        traj = self._trajectory(scene, samples_t, samples_y, samples_modes)
        phases = {}
        if len(boundaries) > 1:
            for ci, name in enumerate(names):
                phases[name] = phases_from_intervals(boundaries, [m[ci] for m in interval_modes])
        result = SimulationResult(self.name, status, message, traj, names, events, impacts, phases,
                                  steps=steps, cpu_time_s=time.process_time() - wall,
                                  stats={"nfev": nfev, "t_final": t})
        return result

    def _trajectory(self, scene, ts, ys, modes_list) -> Trajectory:
        n_dof, nc = scene.n_dof, len(scene.contacts)
        n = len(ts)
        q = np.array([y[:n_dof] for y in ys]).reshape(n, n_dof)
        v = np.array([y[n_dof:] for y in ys]).reshape(n, n_dof)
        a = np.full((n, n_dof), np.nan)
        N = np.zeros((n, nc))
        T = np.zeros((n, nc))
        for k in range(n):
            d = mode_dynamics(scene, ts[k], q[k], v[k], modes_list[k])
            a[k], N[k], T[k] = d.a, d.normal_force, d.tangential_force
        return Trajectory(np.array(ts), q, v, a, N, T, np.array(modes_list, dtype=object).reshape(n, nc))
