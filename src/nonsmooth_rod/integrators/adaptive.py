"""Error-controlled Moreau–Jean (`tol=`): step doubling over windows of steps, Richardson
extrapolation between events, local refinement (with a look-back) where the contact state set
changes. docs/error_control.md has the why and the measurements.

A window of length H runs the unchanged Moreau–Jean loop (moreau_jean_loop.run_steps) from an
accepted state and its contact memory twice: WINDOW_STEPS steps of H/WINDOW_STEPS, then twice as
many of half that. err = ‖q_fine − q_coarse‖∞ estimates the finer run's (first-order) error.

* smooth window (no impact, every contact's state the same throughout both runs and in the window
  before): accepted when err ≤ tol, going on from the Richardson value 2 x_fine − x_coarse, the
  loaded contacts' gaps and relative velocities kept the fine run's (`extrapolated`);
  H ← H · clip(0.9 √(tol/err)).
* event window: no extrapolation; accepted once H ≤ WINDOW_STEPS · tol (fine steps of tol/2) and
  err ≤ tol, and only if the window before was that short too, else that one is taken back and
  redone in halves (a switch inside a long window shows only in the next one). Consecutive
  windows differ by at most GRADING.
* break-aways and slip reversals are decided by the smooth phase's prediction, not by the
  step's overshoot (adaptive_breakaway): a window's sticking contacts are held unless the exact
  law breaks them away in it, and a window ends at a predicted switch.

stats["error_estimate"] bounds the position error at the end (position_error_estimate); each
impact and phase event carries its time error estimate in detail["error"].
"""
from __future__ import annotations

import contextlib
import math
import time
from dataclasses import dataclass, field

import numpy as np

from . import accumulation
from . import moreau_jean_loop as loop
from .adaptive_breakaway import BreakAways
from .sampling import save_slots, stop_event, stop_holds, stop_message
from .moreau_jean_records import HISTORY, WORK_CLOSED, WORK_GRAZING, WORK_SLIP_SIGN, ResumeState
from ..results import Event, Impact, SimulationResult, Trajectory, merge_short_phases, phases_from_intervals
from ..solvers.two_coefficient import STATE_NAMES

# Step-size controller (Hairer, Nørsett & Wanner I, II.4): safety factor and growth limits.
SAFETY, GROW_MAX, SHRINK_MIN = 0.9, 4.0, 0.2
# Smallest step, relative to tol (s): a step this short is accepted whatever its estimate (counted).
MIN_STEP_FRACTION = 1e-3
# Accepted steps of one run (each kept in memory until the run ends): beyond, the run fails.
MAX_ACCEPTED_STEPS = 200_000
# Consecutive steps differ by at most this factor: a loaded contact ends a step with a relative
# velocity O(h) (its Jacobian taken at the step's start) that the next step removes as part of
# its force; a much shorter next step would see it as a spike of O(H/h).
GRADING = 2.0
# Steps of a window, run as WINDOW_STEPS steps and as twice as many: extrapolating once per window,
# not once per step, keeps the bias of removing the velocity's lag small (docs/error_control.md:
# measured on the rod, 8 steps leave an x_O error of 2.7e-6 m whatever tol, 32 meet tol = 1e-6).
WINDOW_STEPS = 32
MEMORY = (WORK_CLOSED, WORK_GRAZING, WORK_SLIP_SIGN)
# The window of an impact of a contact open before it (not a loaded one striking again after the
# step let its gap creep open: adaptive_breakaway) is this many times shorter than another
# event's: the impact step applies the
# law to its start velocity plus a whole step of force, an error s h (a⁺ − P a⁻) first order in the
# step (docs/error_control.md, "Rocking block"); at fine steps of tol/2 Housner's ratio was within
# 1e-4 only with 6e-6 to spare at α = 41°, and 1.1e-4 off once the positions along a sticking
# contact were extrapolated (adaptive.extrapolated).
IMPACT_REFINEMENT = 4


@dataclass
class Point:
    """An accepted state: time, q, v, the contacts' memory, the records of the step reaching it
    (impulses, slip, state codes), that step's size and whether it crossed an event."""

    t: float
    q: np.ndarray
    v: np.ndarray
    memory: tuple
    records: tuple  # (p_normal, p_tangent, slip, states) of the step that reached it
    h: float = 0.0
    event: bool = False
    forced: bool = False  # accepted at the smallest step above tol
    err: float = 0.0  # the window's position error estimate, ‖q_fine − q_coarse‖∞
    err_v: float = 0.0  # its velocity error estimate, ‖v_fine − v_coarse‖∞ (carried into positions later)
    # (contact, t_hit, t_row, q_row, v_row, v_after, p_n, p_t, v before and after at t_hit or None: _at_impact)
    impacts: list = field(default_factory=list)
    impulses: tuple = ()  # (p_normal, p_tangent) of the step's two halves together
    states: np.ndarray | None = None  # the state codes of its last half step
    switches: dict = field(default_factory=dict)  # contact → start of its first fine step in a new state
    at_switch: bool = False  # the window ends at a switch the smooth phase predicts (adaptive_breakaway)


@dataclass
class Attempt:
    """One step of H and two of H/2 from the same Point."""

    status: int
    q_coarse: np.ndarray
    v_coarse: np.ndarray
    q_fine: np.ndarray
    v_fine: np.ndarray
    states: np.ndarray  # (3, n_contacts): coarse, fine 1, fine 2
    records: tuple  # the second half step's records
    impulses: tuple  # (p_normal, p_tangent) over both half steps
    memory: tuple
    impacts: list
    n_impacts_coarse: int
    switches: dict = field(default_factory=dict)


def _out_arrays(n_dof: int, nc: int, steps: int):
    """A loop `out` tuple: row 0 the step before (warm start), row 1 the start, `steps` steps."""
    return loop.new_records(n_dof, nc, steps + 1, 4 * nc * steps + 4, 0)  # no joints (refused with tol)


class Stepper:
    """Runs the loop's unchanged steps from a Point with a chosen step size."""

    def __init__(self, integrator, engine, scene, model, work, params, iparams, probe_steps: int):
        self.integrator, self.engine, self.scene, self.probe_steps = integrator, engine, scene, probe_steps
        self.model, self.work, self.params, self.iparams = model, work, params, iparams
        self.outs = {}
        self.steps_run = 0
        self.seconds = 0.0

    def run(self, point: Point, h: float, n: int):
        """n steps of h from point; returns (status, out)."""
        out, work, params = self.out(n), self.work, self.params
        out.q[1], out.v[1] = point.q, point.v
        for j, rec in enumerate(point.records):
            out[2 + j][0] = rec
        for slot, saved in zip(MEMORY, point.memory):
            work[slot][:] = saved
        params[loop.P_H] = params[loop.P_H_GRID] = h
        params[loop.P_T0], params[loop.P_K0] = point.t, -1.0
        counters = out.counters
        counters[loop.K_N_IMPACTS], counters[loop.K_DONE] = 0, 1
        started = time.perf_counter()
        kernels = self.engine.kernels
        if self.scene.applied_force is None and self.iparams[loop.I_SOLVER] >= 0:
            status = kernels.run_steps(1, 1 + n, params, self.iparams, self.model, work, out, np.zeros(0))
        else:
            status = self.integrator._run_stepwise(kernels, self.scene, 1, 1 + n, params, self.iparams,
                                                   self.model, work, out)
        self.seconds += time.perf_counter() - started
        self.steps_run += n
        return int(status), out

    def out(self, n: int):
        if n not in self.outs:
            self.outs[n] = _out_arrays(self.scene.n_dof, len(self.scene.contacts), n)
        return self.outs[n]

    def attempt(self, point: Point, H: float, n: int, holding=contextlib.nullcontext()) -> Attempt:
        """The window of H as n steps and as 2n steps from the same point, both in `holding` (a
        context: the contacts a window holds, adaptive_breakaway)."""
        with holding:
            return self._attempt(point, H, n)

    def _attempt(self, point: Point, H: float, n: int) -> Attempt:
        status, out = self.run(point, H / n, n)
        q_c, v_c, states_c = out.q[n + 1].copy(), out.v[n + 1].copy(), out.states[1: n + 1].copy()
        n_imp_c = int(out.counters[loop.K_N_IMPACTS])
        if status != loop.RUN_OK:
            return Attempt(status, q_c, v_c, q_c, v_c, None, None, None, None, [], n_imp_c)
        m = 2 * n
        status, out = self.run(point, H / m, m)
        impacts = []
        rows = [int(out.impact_step[j]) for j in range(int(out.counters[loop.K_N_IMPACTS]))]
        for j, row in enumerate(rows):
            t_row, t_hit = point.t + (row - 1) * H / m, float(out.impact_t[j])
            impacts.append((int(out.impact_contact[j]), t_hit, t_row, out.q[row].copy(), out.v[row].copy(),
                            out.v[row + 1].copy(), out.p_normal[row].copy(), out.p_tangent[row].copy(),
                            *_at_impact(out.v, row, m, set(rows), (t_hit - t_row) / (H / m))))
        states = np.vstack([states_c, out.states[1: m + 1]])
        records = tuple(out[2 + j][m].copy() for j in range(4))
        impulses = (out.p_normal[1: m + 1].sum(axis=0), out.p_tangent[1: m + 1].sum(axis=0))
        memory = tuple(self.work[slot].copy() for slot in MEMORY)
        fine = np.vstack([point.records[3][None, :], out.states[1: m + 1]])
        switches = {}
        for j, i in zip(*np.nonzero(fine[1:] != fine[:-1])):
            switches.setdefault(int(i), point.t + j * H / m)
        return Attempt(status, q_c, v_c, out.q[m + 1].copy(), out.v[m + 1].copy(), states, records, impulses,
                       memory, impacts, n_imp_c, switches)


class Controller:
    """The accepted Points of a run and the step size: accept, reject, or take a step back."""

    def __init__(self, tol: float, max_step: float, first: Point, t_end: float, extrapolate):
        self.tol, self.max_step, self.t_end, self.extrapolate = tol, max_step, t_end, extrapolate
        self.window_steps = WINDOW_STEPS
        self.h_event = tol * WINDOW_STEPS  # an event's window: its steps, and the switch located in them, within tol
        self.h_min = tol * MIN_STEP_FRACTION
        self.points = [first]
        self.H = min(max_step, t_end - first.t)
        self.cap_until, self.cap = -math.inf, math.inf  # after a step taken back: steps ≤ cap until then
        self.forced = self.rejected = self.taken_back = 0

    def next_step(self) -> float:
        point = self.points[-1]
        H = min(self.H, self.max_step, self.t_end - point.t)
        if point.t < self.cap_until:
            H = min(H, self.cap)
        if point.h:
            H = min(H, GRADING * point.h)
        remaining = self.t_end - point.t
        if H < remaining < 1.05 * H:  # no sliver of a last step
            H = remaining
        return max(H, min(self.h_min, remaining))

    def judge(self, H: float, att: Attempt) -> bool:
        """Accept or reject the attempt of H; True when a Point was added."""
        point = self.points[-1]
        err = float(np.max(np.abs(att.q_fine - att.q_coarse)))
        event = bool(att.impacts) or att.n_impacts_coarse > 0 or not np.all(att.states == point.records[3])
        arrival = any(STATE_NAMES[int(point.records[3][imp[0]])] == "open" for imp in att.impacts)
        at_floor = H <= self.h_min * (1 + 1e-9)  # accepted whatever its estimate (counted as forced)
        if event and H > (self.h_event / IMPACT_REFINEMENT if arrival else self.h_event) and not at_floor:
            return self._retry(H, 0.5)
        if err > self.tol and not at_floor:
            return self._retry(H, max(SHRINK_MIN, SAFETY * math.sqrt(self.tol / err)))
        if event and point.h > self.h_event and len(self.points) > 1 and not (point.event or point.at_switch):
            return self._take_back(point, H)
        smooth = not event
        q, v = self.extrapolate(att, point.records) if smooth else (att.q_fine, att.v_fine)  # Richardson
        t = self.t_end if H >= self.t_end - point.t else point.t + H
        err_v = float(np.max(np.abs(att.v_fine - att.v_coarse)))
        self.points.append(Point(t, q, v, att.memory, att.records, H, event, err > self.tol, err, err_v, att.impacts,
                                 att.impulses, att.states[-1], att.switches))
        self.forced += err > self.tol
        grow = GROW_MAX if err == 0.0 else min(GROW_MAX, max(SHRINK_MIN, SAFETY * math.sqrt(self.tol / err)))
        self.H = max(self.h_min, H * grow if not event else max(H, 2 * self.h_event))
        return True

    def refuse(self, H: float) -> None:
        """An attempt refused whatever its estimate (a held contact ended it open): redone in halves."""
        self._retry(H, 0.5)

    def _retry(self, H: float, factor: float) -> bool:
        self.rejected += 1
        self.H = max(self.h_min, H * factor)
        point = self.points[-1]
        if self.H < point.h / GRADING and len(self.points) > 1 and not (point.event or point.at_switch):
            return self._take_back(point, H)  # steps change by at most GRADING from one to the next
        return False

    def _take_back(self, point: Point, H: float) -> bool:
        """The state set changed right after a long step: redo that step in halves."""
        self.points.pop()
        self.taken_back += 1
        self.cap = max(self.h_min, point.h / 2)
        self.cap_until = max(self.cap_until, point.t + H)
        self.H = self.cap
        return False


def _at_impact(v, row: int, m: int, impact_rows: set, s: float) -> tuple:
    """The velocities just before and after an impact inside step `row` (at the fraction s of it),
    each carried to the impact instant at the rate of the smooth step beside it (rows of v:
    1 … m + 1), or None where that step is not in the window or has an impact of its own.

    A step's end velocity is that of the step's end, h (1 − s) after the impact: on the rocking
    block (α = 41°) its angular acceleration moves θ̇ by up to 24 rad/s² · h there, 1.2e-5 rad/s at
    tol = 1e-6 (h = 5e-7 s); read at the impact, Housner's ratio is within 1e-4 down to |θ̇| =
    1.1e-2 rad/s, where it was 3.4e-4 off (docs/error_control.md, "Rocking block")."""
    before = after = None
    if row - 1 >= 1 and row - 1 not in impact_rows:
        before = v[row] + s * (v[row] - v[row - 1])
    if row + 2 <= m + 1 and row + 1 not in impact_rows:
        after = v[row + 1] - (1.0 - s) * (v[row + 2] - v[row + 1])
    return before, after


def _loaded(scene, before: tuple, after: tuple, impacts: list) -> list:
    """The contacts loaded through the step (before and after it, no impact in it)."""
    hit = {imp[0] for imp in impacts}
    return [i for i in range(len(scene.contacts))
            if i not in hit and int(after[3][i]) > 0 and after[0][i] > 0.0 and before[0][i] > 0.0]


def _projected(minv, rows: list, residual) -> np.ndarray:
    """The M-orthogonal correction −M⁻¹Hᵀ(H M⁻¹ Hᵀ)⁺ r taking H x to H x − r."""
    H = np.array(rows)
    return -minv * (H.T @ np.linalg.lstsq((H * minv) @ H.T, np.asarray(residual), rcond=None)[0])


def extrapolated(scene, att, before: tuple) -> tuple:
    """The Richardson state 2 x_{H/2} − x_H with the gaps of the contacts loaded through the step
    and their relative velocities (normal, and tangential where they stick) kept the half steps'
    (M-orthogonally), the velocities' taken at the new positions.

    Those are what the law decides on. A Moreau–Jean step holds a loaded contact with its
    Jacobian at the step's start, so it ends with a relative velocity O(h) (the Jacobian's turn)
    that the next step's impulse removes; the plain extrapolation cancels it to zero, and a
    contact at rest with zero slip velocity is one the two-coefficient law may let slide at μd
    (both stick and slide are admissible there). The positions along a sticking contact are
    extrapolated (its constraint is nonlinear in q: kept at the half steps', they were first
    order, and the rod sticking 0.3 s ended 2–3e-5 rad off at any tol); the gaps are not
    (extrapolated, they moved the rod's break-away by 10 ms)."""
    dq, dv = att.q_fine - att.q_coarse, att.v_fine - att.v_coarse
    q, v = att.q_fine + dq, att.v_fine + dv
    loaded = _loaded(scene, before, att.records, att.impacts)
    if not loaded:
        return q, v
    minv, n = scene.inverse_mass_diagonal, scene.n_dof
    normal = np.array([scene.contacts[i].kinematics(att.q_fine, att.v_fine, n).H_N for i in loaded])
    q = q + _projected(minv, normal, normal @ dq)
    fine, new = _velocity_rows(scene, loaded, att.q_fine, att.records), _velocity_rows(scene, loaded, q, att.records)
    return q, v + _projected(minv, new, new @ v - fine @ att.v_fine)


def _velocity_rows(scene, loaded: list, q, records: tuple) -> np.ndarray:
    """The loaded contacts' H_N at q, and H_T of those that stick."""
    rows = []
    for i in loaded:
        kin = scene.contacts[i].kinematics(q, np.zeros(scene.n_dof), scene.n_dof)
        rows += [kin.H_N] + ([kin.H_T] if STATE_NAMES[int(records[3][i])] == "stick" else [])
    return np.array(rows)


def samples_estimate(options, duration: float) -> float:
    """The accepted steps a run may hold (the driver's memory check): at most MAX_ACCEPTED_STEPS."""
    return 2.0 + min(MAX_ACCEPTED_STEPS, duration / (options.tol * MIN_STEP_FRACTION))


def first_point(t0: float, q0, v0, nc: int, resume: ResumeState | None) -> Point:
    """The run's start: fresh (no contact memory) or a Moreau–Jean end state."""
    if resume is None:
        memory = (np.zeros(nc, dtype=np.int64), np.zeros(nc, dtype=np.int64), np.zeros(nc))
        records = (np.zeros(nc), np.zeros(nc), np.zeros(nc), np.full(nc, -1, dtype=np.int64))
        return Point(t0, q0.copy(), v0.copy(), memory, records)
    memory = (resume.was_closed.copy(), resume.grazing.copy(), resume.slip_sign.copy())
    if resume.states.shape[0]:
        records = tuple(np.array(getattr(resume, name)[-1]) for name in ("p_normal", "p_tangent", "slip", "states"))
    else:
        records = (np.zeros(nc), np.zeros(nc), np.zeros(nc), np.full(nc, -1, dtype=np.int64))
    return Point(t0, q0.copy(), v0.copy(), memory, records, h=resume.last_h)


def run_adaptive(integrator, scene, q0, v0, t_end: float, t0: float, resume, save_every, stops, engine,
                 model, work, params, iparams, probe_steps: int, boundary_kind: dict) -> SimulationResult:
    """The error-controlled run of `integrator` (a MoreauJean whose options have tol) with its
    Engine (probe_steps: the steps a cold run probes before deciding to compile) and the event
    kind of each phase a boundary enters (boundary_kind: moreau_jean's)."""
    opts, names = integrator.options, [c.name for c in scene.contacts]
    stop_contact = names.index(opts.stop_at_impact) if opts.stop_at_impact in names else -1
    iparams[loop.I_STOP] = -1  # the stop contact's impact is judged on accepted steps only
    stepper = Stepper(integrator, engine, scene, model, work, params, iparams, probe_steps)
    ctrl = Controller(opts.tol, opts.h, first_point(t0, q0, v0, len(names), resume), t_end,
                      lambda att, before: extrapolated(scene, att, before))
    breakaways = BreakAways(scene, model, opts.tol, ctrl.h_event, opts.h, t_end)
    wall = time.process_time()
    ending = _steps(stepper, ctrl, breakaways, stops, stop_contact)
    cpu = time.process_time() - wall
    return _result(integrator, scene, ctrl, stepper, ending, names, save_every, cpu, boundary_kind)


def _steps(stepper: Stepper, ctrl: Controller, breakaways: BreakAways, stops, stop_contact: int):
    """Attempts until t_end, a stop or a failure: (status word, message, final event or None);
    each window's sticking contacts held unless the smooth phase breaks them away (breakaways)."""
    probe = contextlib.ExitStack()
    engine = stepper.engine
    if engine.compiled:
        probe.enter_context(engine.compiling())
    with probe, contextlib.ExitStack() as later:
        while ctrl.points[-1].t < ctrl.t_end:
            point = ctrl.points[-1]
            window = breakaways.window(ctrl.points, ctrl.next_step())
            H = window.H
            att = stepper.attempt(point, H, ctrl.window_steps, breakaways.holding(window))
            if att.status != loop.RUN_OK:
                return "failed", _failure(stepper, att.status, point, H), None
            if engine.probing and stepper.steps_run >= stepper.probe_steps:
                left = 3 * (ctrl.t_end - point.t) / max(H, ctrl.h_min)
                engine.measured(stepper.steps_run, stepper.seconds, int(left), loop.RUN_OK)
                if engine.compiled:
                    later.enter_context(engine.compiling())
            if breakaways.contradicted(window, att.records[3]) and H > ctrl.h_min * (1 + 1e-9):
                ctrl.refuse(H)
                continue
            if not ctrl.judge(H, att):
                continue
            ctrl.points[-1].at_switch = window.cut
            if len(ctrl.points) > MAX_ACCEPTED_STEPS:
                return "failed", (f"error control: more than {MAX_ACCEPTED_STEPS} steps before t = "
                                  f"{ctrl.points[-1].t:.9g} s; use a larger tol"), None
            new = ctrl.points[-1]
            hit = [imp[1] for imp in new.impacts if imp[0] == stop_contact]
            if hit:
                return "ok", f"stopped at the impact of {stepper.integrator.options.stop_at_impact}", None
            if stops and stop_holds(stops, new.t, new.q, new.v):
                return "stopped", stop_message(new.t), stop_event(new.t)
    return "ok", f"reached t_end = {ctrl.t_end:g} s", None


def _failure(stepper: Stepper, status: int, point: Point, H: float) -> str:
    where = f"t = {point.t:.9g} s, step {H:.3g} s, q = {np.array2string(point.q, precision=6)}"
    if status == loop.RUN_NONFINITE:
        return f"non-finite state in the step from {where}"
    if status == loop.RUN_BAD_GEOMETRY:
        return f"disk centres coincide in the step from {where}: the contact normal is undefined"
    if status == loop.RUN_PASSED_THROUGH:
        return f"a disk passed through its obstacle in the step from {where}"
    err = stepper.integrator._solver_error
    if err is not None:
        return str(err.with_context(where))
    return f"{stepper.integrator.options.solver}: no valid solution of the step problem ({where})"


def _samples(points: list, nc: int, save_every: float | None):
    """t, q, v, a, N, T, codes of the accepted points (one per save_every, first and last kept)."""
    t = np.array([p.t for p in points])
    q, v = np.array([p.q for p in points]), np.array([p.v for p in points])
    h = np.array([p.h if p.h else math.nan for p in points])[:, None]
    a = np.vstack([np.full((1, q.shape[1]), math.nan), np.diff(v, axis=0) / h[1:]])
    N = np.array([p.impulses[0] if p.impulses else np.zeros(nc) for p in points]) / np.where(np.isnan(h), 1, h)
    T = np.array([p.impulses[1] if p.impulses else np.zeros(nc) for p in points]) / np.where(np.isnan(h), 1, h)
    codes = np.array([p.states if p.states is not None else np.zeros(nc, dtype=np.int64) for p in points])
    if len(points) > 1:
        codes[0] = codes[1]  # the first sample: the mode of the first step, as fixed steps report it
    keep = np.ones(t.shape, dtype=bool)
    if save_every is not None:
        slot = save_slots(t - t[0], save_every)
        keep[1:] = slot[1:] != slot[:-1]
        keep[-1] = True
    return t[keep], q[keep], v[keep], a[keep], N[keep], T[keep], codes[keep]


def _impacts(scene, points: list, names: list, position_error: np.ndarray, resolution: float):
    """Impact records and events, each with its time error estimate: the step it lies in plus the
    position error estimate reached there over the closing speed; those `resolution` calls an
    accumulation's unresolved tail left out (integrators/accumulation.py)."""
    minv = scene.inverse_mass_diagonal
    impacts, events = [], []
    for k, point in enumerate(points):
        for i, t_hit, t_row, q_row, v_row, v_after, p_n, p_t, v_hit, v_after_hit in point.impacts:
            if v_hit is None:  # no smooth step before it in the window: the applied force's rate
                v_hit = v_row + (t_hit - t_row) * minv * scene.force(t_row, q_row, v_row)
            v_after = v_after if v_after_hit is None else v_after_hit
            q_hit = q_row + (t_hit - t_row) * v_row
            kin = scene.contacts[i].kinematics(q_hit, v_hit, scene.n_dof)
            speed = max(abs(float(kin.H_N @ v_hit)), 1e-300)
            if not accumulation.impact_resolved(scene, i, t_hit, q_hit, v_hit, resolution):
                continue
            error = point.h + points[k - 1].h + position_error[k] / speed
            impacts.append(Impact(t_hit, names[i], q_hit, v_hit, v_after, p_n, p_t))
            events.append(Event(t_hit, "impact", names[i], {"error": float(error)}))
    return impacts, events


def _phases(points: list, names: list, impacts: list, min_phase: float, t_stop: float | None, boundary_kind: dict):
    """Per-contact phases from each accepted window's state: a boundary at the start of the first
    fine step in the new state (an impact's at the impact), phases shorter than min_phase merged;
    one event per boundary, with its error (the fine steps on either side)."""
    t = np.array([p.t for p in points])
    codes = np.array([p.states for p in points[1:]])
    phases, events = {}, []
    for i, name in enumerate(names):
        found = phases_from_intervals(t, [STATE_NAMES[c] for c in codes[:, i]], 0.0)
        errors = {}
        for before, after in zip(found, found[1:]):
            k = int(np.searchsorted(t, after.t_start))  # the window ending at t[k + 1] changed the state
            window = points[min(k + 1, len(points) - 1)]
            switch = window.switches.get(i, after.t_start)
            if before.mode == "open":
                switch = min((imp.t for imp in impacts if imp.contact == name and abs(imp.t - switch) <= window.h),
                             key=lambda s: abs(s - switch), default=switch)
            before.t_end = after.t_start = float(switch)
            errors[after.t_start] = window.h / WINDOW_STEPS + points[k].h / WINDOW_STEPS
        if t_stop is not None and found:
            found[-1].t_end = max(found[-1].t_start, t_stop)
        found = merge_short_phases(found, min_phase)
        for before, after in zip(found, found[1:]):
            if before.mode != "open":
                events.append(Event(after.t_start, boundary_kind.get(after.mode, "stick-slip"), name,
                                    {"from": before.mode, "to": after.mode, "located": "refined",
                                     "error": float(errors.get(after.t_start, 0.0))}))
        phases[name] = found
    return phases, events


def position_error_estimate(points: list) -> np.ndarray:
    """At each point, the sum over the windows before it of their position error estimate and
    their velocity error estimate times the time since (an error in v moves q at that rate)."""
    t = np.array([p.t for p in points])
    err_q, err_v = np.array([p.err for p in points]), np.array([p.err_v for p in points])
    return np.cumsum(err_q) + t * np.cumsum(err_v) - np.cumsum(err_v * t)


def _result(integrator, scene, ctrl: Controller, stepper: Stepper, ending, names, save_every, cpu, boundary_kind):
    opts, points = integrator.options, ctrl.points
    status, message, final_event = ending
    if status == "failed" and final_event is None:
        final_event = Event(float(points[-1].t), "solver-failure", "", {"message": message})
    t, q, v, a, N, T, codes = _samples(points, len(names), save_every)
    modes = np.array(STATE_NAMES, dtype=object)[codes]
    position_error = position_error_estimate(points)
    impacts, events = _impacts(scene, points, names, position_error, opts.resolution)
    t_stop = max((imp.t for imp in impacts if imp.contact == opts.stop_at_impact), default=None) \
        if message.startswith("stopped at the impact") else None
    phases, phase_events = ({}, []) if len(points) < 2 else _phases(points, names, impacts, opts.min_phase, t_stop,
                                                                      boundary_kind)
    events = sorted(events + phase_events, key=lambda e: e.t) + ([final_event] if final_event else [])
    steps = np.array([p.h for p in points[1:]])
    stats = {"tol": opts.tol, "h": opts.h, "theta": opts.theta, "solver": opts.solver,
             "compiled": stepper.engine.compiled, "force_callback": scene.applied_force is not None,
             "unresolved_impacts": sum(len(p.impacts) for p in points) - len(impacts),
             "steps": len(points) - 1, "step_evaluations": stepper.steps_run, "rejected": ctrl.rejected,
             "taken_back": ctrl.taken_back, "forced_steps": ctrl.forced,
             "min_step": float(steps.min()) if steps.size else math.nan,
             "max_step": float(steps.max()) if steps.size else math.nan,
             "error_estimate": float(position_error[-1]),
             "event_time_error_estimate": float(max((e.detail["error"] for e in events if "error" in e.detail),
                                                    default=0.0))}
    result = SimulationResult(integrator.name, status, message, Trajectory(t, q, v, a, N, T, modes), names, events,
                              impacts, phases, steps=len(points) - 1, cpu_time_s=cpu, stats=stats)
    result.end_state = _end_state(points, ctrl) if status != "failed" else None
    return result


def _end_state(points: list, ctrl: Controller) -> ResumeState:
    """What a restart reads: off any grid, its last HISTORY steps' states and records."""
    last = points[-(HISTORY + 1):]
    recs = [np.array([p.records[j] for p in last[1:]]).reshape(len(last) - 1, -1) for j in range(4)]
    recs[3] = recs[3].astype(np.int64)
    return ResumeState(float(points[-1].t), 0, ctrl.H, False, points[-1].h or ctrl.H,
                       np.array([p.q for p in last]), np.array([p.v for p in last]), *recs,
                       *(np.array(m) for m in points[-1].memory))
