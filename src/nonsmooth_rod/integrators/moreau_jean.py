"""Moreau–Jean time-stepping (θ-method) for planar rigid bodies with unilateral frictional contact.

Per step of size h, from (q_k, v_k):

    v_free  = v_k + h M⁻¹ f(t_k + θh, q_k, v_k)
    active  = contacts whose predicted gap g + γ h u_N closes (γ = ½ by default)
    u       = W p + q_step,  W = H M⁻¹ Hᵀ,  q_step = (H v_free + e u_N^k for the normal rows)
    p       from the exact two-coefficient law (solvers.two_coefficient)
    v_{k+1} = v_free + M⁻¹ Hᵀ p
    q_{k+1} = q_k + h ((1 − θ) v_k + θ v_{k+1})

Impacts need no special case: a contact that closes within a step gets the impulse that makes
u_N⁺ + e u_N⁻ ≥ 0 ⊥ p_N ≥ 0 hold at the end of the step. The scheme is first order on
nonsmooth solutions; with e = 0 and θ = ½ a step gains at most the work ½ pᵀH(q_k)v_k of its
impulses on the start velocity, O(h²) for a persistent contact (docs/friction.md, "Energy").
"""
from __future__ import annotations

import contextlib
import math
import time
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from .. import _jit
from ..model.packing import C_MU_S, pack_scene
from ..model.scene import Scene
from ..results import Event, Impact, SimulationResult, Trajectory, phases_from_intervals
from ..solvers import available_solvers, check_solver_options
from ..solvers._common import interpreted
from ..solvers.problem import SolverError
from ..solvers.two_coefficient import COMPILED_SOLVERS, STATE_NAMES, solve_two_coefficient
from ..validation import Choice, Flag, InputError, Number, Text, check_options, option, require_positive, require_state
from . import moreau_jean_loop as loop
from .moreau_jean_loop import ACTIVATION_ROUNDOFF  # noqa: F401  (re-exported)

STATE_CODES = {name: code for code, name in enumerate(STATE_NAMES)}
# Solver settings the compiled kernels take (the Python solvers read solver_options themselves);
# 0 means the kernel's own default (solvers/kernels.py).
DEFAULT_RTOL, DEFAULT_MAX_ITER = 0.0, 0


@dataclass
class MoreauJeanOptions:
    """Step size, θ of the θ-method, contact activation and the one-step solver."""

    h: float = option(1e-4, Number(0.0, open_lo=True), label="h (step size)")
    theta: float = option(0.5, Number(0.0, 1.0))
    # a contact enters the step when g + γ h u_N ≤ 0
    activation_gamma: float = option(0.5, Number(0.0, 1.0), label="activation_gamma")
    solver: str = option("lemke", Choice(available_solvers))
    solver_options: dict = option(None, None, default_factory=dict)  # checked per solver below
    stop_at_impact: str | None = option(None, Text())  # name of a contact whose first impact ends the run
    min_phase: float | None = option(None, Number(0.0, optional=True))  # shorter phases are merged (default 2h)
    allow_energy_gain: bool = option(False, Flag())  # θ < ½ amplifies energy; refused unless asked for
    fast: bool = option(True, Flag())  # use the compiled loop when the scene and solver allow it

    def __post_init__(self):
        check_options(self)
        self.solver_options = check_solver_options(self.solver, self.solver_options)
        if self.theta < 0.5 and not self.allow_energy_gain:
            raise InputError(
                f"theta = {self.theta:g} < 0.5 makes Moreau–Jean gain energy; use theta in [0.5, 1] "
                "(or allow_energy_gain=True to study it)"
            )
        if self.min_phase is None:
            self.min_phase = 2 * self.h


_ENTRY_POINTS = ("run_steps", "compiled_step", "step_force", "begin_step", "assemble", "finish_step", "end_of_step")


def loop_kernels(compiled: bool):
    """The loop's entry points: compiled (the module itself), or their plain-Python twins from
    the same source (solvers._common.interpreted rebinds every kernel they call)."""
    if compiled or not _jit.ENABLED:
        return loop
    return SimpleNamespace(**{name: interpreted(getattr(loop, name)) for name in _ENTRY_POINTS})


def _allocate(packed, q0, v0, n_steps):
    """The model, work and out tuples of moreau_jean_loop."""
    n_dof, nc = packed.minv.shape[0], packed.n_contacts
    model = (packed.minv, packed.weight, packed.contacts, packed.contact_index, packed.force_table,
             packed.force_index, packed.force_times, packed.force_values, packed.disks, packed.disk_body,
             packed.pair_keys, packed.pair_contact)
    work = (np.zeros(nc), np.zeros(nc), np.zeros((nc, 6)), np.zeros((nc, 6)), np.zeros(nc, dtype=np.int64),
            np.zeros(nc, dtype=np.int64), np.zeros(nc, dtype=np.int64), np.zeros(nc), np.zeros(n_dof),
            np.zeros(n_dof), np.zeros(nc, dtype=np.int64))
    q = np.empty((n_steps + 1, n_dof))
    v = np.empty((n_steps + 1, n_dof))
    q[0], v[0] = q0, v0
    per_step = [np.zeros((n_steps, nc)) for _ in range(3)]
    capacity = n_steps + 4 * nc
    out = (q, v, *per_step, np.zeros((n_steps, nc), dtype=np.int64), np.zeros(capacity),
           np.zeros(capacity, dtype=np.int64), np.zeros(capacity, dtype=np.int64),
           np.zeros(loop.N_COUNTERS, dtype=np.int64))
    return model, work, out


# Steps run interpreted to measure a cold run's per-step cost before deciding whether to compile.
PROBE_STEPS = 16


def compiled_part(solver: str, solver_code, callback: bool):
    """(cache part, what it is in words, background job's arguments) of the compiled entry a run
    uses: the whole-run loop, the step-wise loop (Python force callbacks), or the step kernels
    around a Python (QP) solver. The exact solvers share each compiled loop."""
    if solver_code is None:
        return "moreau-jean-python-step", "the step kernels around Python solvers", ["--python-step", solver]
    if callback:
        return "moreau-jean-step", "the step-wise Moreau–Jean loop (Python force callback)", ["--step"]
    return "moreau-jean", "the Moreau–Jean loop (lemke, pgs and enum)", []


class MoreauJean:
    """The Moreau–Jean one-step integrator over a Scene (one loop: moreau_jean_loop)."""

    name = "moreau-jean"

    def __init__(self, options: MoreauJeanOptions | None = None):
        self.options = options or MoreauJeanOptions()

    def run(self, scene: Scene, q0, v0, t_end: float) -> SimulationResult:
        require_positive("t_end", t_end)
        opts = self.options
        n_steps = max(1, int(math.ceil(t_end / opts.h - 1e-9)))
        names = [c.name for c in scene.contacts]
        q0, v0 = require_state("q0", q0, scene.n_dof), require_state("v0", v0, scene.n_dof)
        packed = pack_scene(scene)
        model, work, out = _allocate(packed, q0, v0, n_steps)
        solver_code = COMPILED_SOLVERS.get(opts.solver)
        solver_options = dict(opts.solver_options)
        params = np.array([opts.h, opts.theta, opts.activation_gamma, 0.0,
                           float(solver_options.get("tol", DEFAULT_RTOL))])
        iparams = np.array([-1 if solver_code is None else solver_code,
                            int(solver_options.get("max_iter", DEFAULT_MAX_ITER)),
                            names.index(opts.stop_at_impact) if opts.stop_at_impact in names else -1],
                           dtype=np.int64)
        callback = scene.applied_force is not None
        self._solver_error = None
        wall = time.process_time()
        with _jit.one_blas_thread():  # the hold search's small SVDs: no thread pool to wake (_jit)
            compiled = self._run_loop(scene, n_steps, solver_code, params, iparams, model, work, out)
        cpu = time.process_time() - wall
        stats = {"h": opts.h, "theta": opts.theta, "solver": opts.solver,
                 "compiled": compiled and solver_code is not None, "force_callback": callback}
        return self._result(scene, packed, out, names, t_end, cpu, stats)

    def _run_loop(self, scene, n_steps, solver_code, params, iparams, model, work, out) -> bool:
        """Steps 0 … n_steps − 1, compiled when it pays (_jit: no run waits for the compiler
        longer than it would run without it); True if they ran compiled."""
        compiled = bool(self.options.fast and _jit.ENABLED)
        part, what, job = compiled_part(self.options.solver, solver_code, scene.applied_force is not None)
        done = 0
        if compiled and not _jit.engine_is_warm(part) and _jit.compile_policy() == "auto":
            done, compiled = self._probe_interpreted(part, what, job, scene, n_steps, solver_code, params,
                                                     iparams, model, work, out)
        if done < n_steps and out[9][loop.K_STATUS] == loop.RUN_OK:
            with _jit.compiling(part, what) if compiled else contextlib.nullcontext():
                self._advance(loop_kernels(compiled), scene, done, n_steps, solver_code, params, iparams,
                              model, work, out)
        return compiled

    def _probe_interpreted(self, part, what, job, scene, n_steps, solver_code, params, iparams, model, work,
                           out):
        """A cold compiled part: time the first steps interpreted, then (steps done, compile now?):
        go on interpreted — compiling in the background — when the rest is shorter than compiling."""
        probe = min(n_steps, PROBE_STEPS)
        start = time.perf_counter()
        self._advance(loop_kernels(False), scene, 0, probe, solver_code, params, iparams, model, work, out)
        rest = (time.perf_counter() - start) / probe * (n_steps - probe)
        compile_s, _ = _jit.compile_estimate_s(part)
        if rest <= compile_s or out[9][loop.K_STATUS] != loop.RUN_OK:
            _jit.compile_in_background(part, job, what, compile_s)
            return probe, False
        return probe, True

    def _advance(self, kernels, scene, k_start, k_end, solver_code, params, iparams, model, work, out):
        """Steps k_start … k_end − 1 with the given kernels (compiled, or their interpreted twins)."""
        if scene.applied_force is None and solver_code is not None:
            kernels.run_steps(k_start, k_end, params, iparams, model, work, out)
        else:
            self._run_stepwise(kernels, scene, k_start, k_end, params, iparams, model, work, out)

    def _run_stepwise(self, kernels, scene, k_start, k_end, params, iparams, model, work, out):
        """The loop step by step from Python: for a Python `applied_force` (called back for each
        step's force) and for the Python (QP) solvers."""
        q, v, counters = out[0], out[1], out[9]
        h, th = params[loop.P_H], params[loop.P_THETA]
        f = np.empty(scene.n_dof)
        solver_code = int(iparams[loop.I_SOLVER])
        compiled_step = kernels.compiled_step if solver_code >= 0 else None
        for k in range(k_start, k_end):
            kernels.step_force(k, params, model, out, f)
            if scene.applied_force is not None:
                f += scene.applied((k + th) * h, q[k], v[k])
            if compiled_step is not None:
                status = compiled_step(k, f, params, iparams, model, work, out)
            else:
                status = self._python_solver_step(kernels, k, f, params, iparams, model, work, out)
            if kernels.end_of_step(k, status, counters) != loop.RUN_OK:
                break

    def _python_solver_step(self, kernels, k, f, params, iparams, model, work, out):
        """One step with a Python solver (QP backends): the loop's kernels around
        solve_two_coefficient."""
        q, v, counters = out[0], out[1], out[9]
        na = kernels.begin_step(params, q[k], v[k], f, model, work)
        if na < 0:
            counters[loop.K_FAIL_CONTACT] = -1 - na
            return loop.RUN_BAD_GEOMETRY
        p, u, states = np.zeros(0), np.zeros(0), np.zeros(0, dtype=np.int64)
        if na > 0:
            W, q_step = np.zeros((2 * na, 2 * na)), np.empty(2 * na)
            guess, mu_s, mu_d, closing, resting = (np.empty(na) for _ in range(5))
            kernels.assemble(params, na, q[k], v[k], model, work, W, q_step, guess, mu_s, mu_d, closing, resting)
            try:
                res = solve_two_coefficient(W, q_step, mu_s, mu_d, guess, self.options.solver,
                                            self.options.solver_options, closing=closing, resting=resting)
            except SolverError as err:
                self._solver_error = err
                return loop.RUN_SOLVER_FAILED
            counters[loop.K_SOLVES] += res.solves
            counters[loop.K_ITERATIONS] += res.iterations
            counters[loop.K_INCONSISTENT] += not res.consistent
            p, u = res.p, res.u
            states = np.array([STATE_CODES[s] for s in res.states], dtype=np.int64)
        return kernels.finish_step(k, params, iparams, na, p, u, states, q[k], v[k], model, work, out)

    def _ending(self, out, names, t_end):
        """(status word, message, steps done, solver-failure event or None) from the counters."""
        q, states, counters = out[0], out[5], out[9]
        h, code, k = self.options.h, int(counters[loop.K_STATUS]), int(counters[loop.K_FAIL_STEP])
        n_done = int(counters[loop.K_DONE]) if code != loop.RUN_OK else q.shape[0] - 1
        if code == loop.RUN_OK:
            return "ok", f"reached t_end = {t_end:g} s", n_done, None
        if code == loop.RUN_STOPPED:
            return "ok", f"stopped at the impact of {self.options.stop_at_impact}", n_done, None
        if code == loop.RUN_NONFINITE:
            return "failed", f"non-finite state at step {k + 1}, t = {(k + 1) * h:.9g} s", n_done, None
        if code == loop.RUN_BAD_GEOMETRY:
            name = names[int(counters[loop.K_FAIL_CONTACT])]
            return "failed", (f"{name}: disk centres coincide at step {k}, t = {k * h:.9g} s, the contact "
                              "normal is undefined"), n_done, None
        state_txt = ", ".join(f"{name}:{STATE_NAMES[states[k - 1, i]] if k else 'initial'}"
                              for i, name in enumerate(names))
        where = f"step {k}, t = {k * h:.9g} s, contact states {state_txt}, q = {np.array2string(q[k], precision=6)}"
        if self._solver_error is not None:
            message = str(self._solver_error.with_context(where))
        else:
            message = f"{self.options.solver}: {_KERNEL_FAILURES.get(int(counters[loop.K_SOLVER_STATUS]), 'failed')} ({where})"
        return "failed", message, n_done, Event(k * h, "solver-failure", "", {"message": message})

    def _impacts(self, scene, out, names, n_done):
        q, v, p_n, p_t = out[0], out[1], out[2], out[3]
        impact_t, impact_step, impact_contact, counters = out[6], out[7], out[8], out[9]
        h, minv = self.options.h, scene.inverse_mass_diagonal
        impacts, events = [], []
        for n in range(min(int(counters[loop.K_N_IMPACTS]), impact_t.shape[0])):
            k, i, t_hit = int(impact_step[n]), int(impact_contact[n]), float(impact_t[n])
            if k >= n_done:
                continue
            f = scene.force(k * h, q[k], v[k])
            v_hit = v[k] + (t_hit - k * h) * minv * f
            q_hit = q[k] + (t_hit - k * h) * v[k]
            impacts.append(Impact(t_hit, names[i], q_hit, v_hit, v[k + 1].copy(), p_n[k].copy(), p_t[k].copy()))
            events.append(Event(t_hit, "impact", names[i], {"step": k}))
        return impacts, events

    def _result(self, scene, packed, out, names, t_end, cpu, stats) -> SimulationResult:
        h = self.options.h
        status, message, n_done, failure = self._ending(out, names, t_end)
        impacts, events = self._impacts(scene, out, names, n_done)
        counters = out[9]
        t = np.arange(n_done + 1) * h
        q, v = out[0][: n_done + 1], out[1][: n_done + 1]
        a = np.full_like(v, np.nan)
        a[1:] = np.diff(v, axis=0) / h
        N = np.zeros((n_done + 1, len(names)))
        T = np.zeros_like(N)
        N[1:], T[1:] = out[2][:n_done] / h, out[3][:n_done] / h
        modes = np.empty((n_done + 1, len(names)), dtype=object)
        modes[1:] = np.array(STATE_NAMES, dtype=object)[out[5][:n_done]]
        modes[0] = modes[1] if n_done else "open"
        t_stop = None
        if int(counters[loop.K_STATUS]) == loop.RUN_STOPPED:
            t_stop = max(i.t for i in impacts if i.contact == self.options.stop_at_impact)
        phases, phase_events = located_phases(scene, out, packed, impacts, n_done, h, self.options.min_phase,
                                              t_stop)
        events = sorted(events + phase_events, key=lambda e: e.t) + ([failure] if failure else [])
        stats = dict(stats, steps=n_done, solves=int(counters[loop.K_SOLVES]),
                     solver_iterations=int(counters[loop.K_ITERATIONS]),
                     inconsistent_steps=int(counters[loop.K_INCONSISTENT]),
                     solver_fallbacks=int(counters[loop.K_FALLBACKS]))
        traj = Trajectory(t, q, v, a, N, T, modes)
        return SimulationResult(self.name, status, message, traj, names, events, impacts, phases,
                                steps=n_done, cpu_time_s=cpu, stats=stats)


_KERNEL_FAILURES = {1: "no valid solution of the step problem (secondary ray)",
                    2: "no valid solution of the step problem (no convergence)",
                    3: "the step problem has more contacts than the solver takes",
                    4: "non-finite data in the step problem"}


# --- phase boundaries located inside the step ------------------------------------------------
_BOUNDARY_KIND = {"open": "liftoff", "stick": "slip-zero"}  # by the mode entered; otherwise:
SLIP_MODES = ("slip+", "slip-")


def _crossing(values, level, k, h):
    """Where the linear extrapolation of step impulses values[k−2], values[k−1] reaches `level`,
    as an offset from t_k; None without a usable slope.

    The impulse of step j that keeps a persistent contact closed answers the change of its
    Jacobian from q_{j−1} to q_j (a backward difference): it is the force at t_j − h/2, not at
    the step's midpoint (measured on the rolling rod: T/N of step j is the exact one at
    t_j − 0.58 h in the paper's case 3, later in case 2); we take it at the step's start t_j."""
    if k < 2:
        return None
    slope = (values[k - 1] - values[k - 2]) / h
    if slope == 0.0:
        return None
    return (level - values[k - 1]) / slope - h


def _boundary_offset(before, after, k, i, out, mu_s, h, slip_velocity):
    """Offset from t_k of the switch before → after of contact i at step k (None: t_k).

    Extrapolated from the last two steps spent in `before` (a one-step blip merged into a phase,
    e.g. the stick step of a slip reversal, is skipped)."""
    p_n, p_t, states = out[2][:, i], out[3][:, i], out[5][:, i]
    j = k  # one past the last step in `before` whose predecessor is in `before` too
    while j >= 2 and j > k - 3 and not (STATE_NAMES[states[j - 1]] == before == STATE_NAMES[states[j - 2]]):
        j -= 1
    if j < 2 or not (STATE_NAMES[states[j - 1]] == before == STATE_NAMES[states[j - 2]]):
        return None
    shift = (j - k) * h
    if after == "open":  # the normal impulse fades to zero
        offset = _crossing(p_n, 0.0, j, h)
    elif before == "stick":  # the friction ratio reaches μs
        ratio = np.abs(p_t[:j]) / np.maximum(p_n[:j], 1e-300)
        offset = _crossing(ratio, mu_s, j, h)
    else:  # slip → stick or reversal: the slip velocity at the steps' ends reaches zero
        s1, s2 = slip_velocity(j - 1), slip_velocity(j)
        slope = (s2 - s1) / h
        # (it may already have crossed at t_j: the law judged H_T(q_j) v_{j+1}, not H_T(q_{j+1}))
        offset = -s2 / slope if slope * s2 < 0.0 or s1 * s2 < 0.0 else None
    return None if offset is None else offset + shift


def located_phases(scene, out, packed, impacts, n_done, h, min_phase, t_stop):
    """Per-contact phases with each boundary placed inside its step (interpolating the slip
    velocity, the friction ratio or the normal impulse between steps; an impact's boundary at the
    impact time), and one event per boundary."""
    phases, events = {}, []
    names = [c.name for c in scene.contacts]
    if not n_done:
        return phases, events
    bounds = np.arange(n_done + 1) * h
    if t_stop is not None and n_done >= 1:
        bounds[-1] = max(float(t_stop), bounds[-2])
    impact_time = {(imp.contact, int(round(imp.t / h))): imp.t for imp in impacts}
    for i, name in enumerate(names):
        codes = out[5][:n_done, i]
        starts = np.flatnonzero(codes[1:] != codes[:-1]) + 1  # runs of one state
        starts = np.concatenate((np.zeros(1, dtype=starts.dtype), starts))
        found = phases_from_intervals(np.append(bounds[starts], bounds[-1]), [STATE_NAMES[c] for c in codes[starts]],
                                      min_phase)
        for before, after in zip(found, found[1:]):
            k = int(round(after.t_start / h))
            if before.mode == "open":
                t_switch = min((t for (c, step), t in impact_time.items() if c == name and abs(step - k) <= 1),
                               key=lambda t: abs(t - k * h), default=k * h)
                kind = "impact"
            else:
                def slip_velocity(j, contact=scene.contacts[i]):  # with the Jacobian at q_j itself
                    kin = contact.kinematics(out[0][j], out[1][j], scene.n_dof)
                    return float(kin.H_T @ out[1][j]) - kin.surface_velocity

                offset = _boundary_offset(before.mode, after.mode, k, i, out, packed.contacts[i, C_MU_S], h,
                                          slip_velocity)
                t_switch = k * h + (0.0 if offset is None else min(max(offset, -2 * h), h))
                kind = _BOUNDARY_KIND.get(after.mode, "stick-slip")
            t_switch = min(max(t_switch, before.t_start), after.t_end)
            before.t_end = after.t_start = float(t_switch)
            if kind != "impact":
                events.append(Event(float(t_switch), kind, name,
                                    {"from": before.mode, "to": after.mode, "step": k, "located": "interpolated"}))
        phases[name] = found
    return phases, events
