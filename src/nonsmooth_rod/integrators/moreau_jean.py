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
import functools
import math
import time
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from .. import _jit
from .._compile_split import compile_callees
from ..model.motion import N_NOW_COLUMNS, evaluate_python_motions
from ..model.joints import REACTION_NAMES, ROWS_PER_JOINT, pack_joints
from ..model.packing import C_MU_S, C_SURFACE_VELOCITY, pack_scene
from ..model.scene import Scene
from ..results import Event, Impact, Phase, SimulationResult, Status, Trajectory, phases_from_intervals
from ..solvers.registry import DEFAULT_SOLVER, EXACT_SOLVERS, SOLVER_CODES, SolverName, check_solver_options
from ..solvers._common import interpreted
from ..solvers.problem import STATE_OPEN, SolverError
from ..solvers.two_coefficient import STATE_NAMES, solve_two_coefficient
from ..validation import Flag, InputError, Number, Text, check_options, option
from . import accumulation
from . import moreau_jean_loop as loop
from .declaration import Declaration, Refusal, first_driven, first_joint
from .direct_entry import DirectEntry
from .carved import carve_zeros, owners
from .joint_step import work_size
from .sampling import first_hold, stop_event, stop_holds, stop_message, thinned_count
from .moreau_jean_loop import ACTIVATION_ROUNDOFF  # noqa: F401  (re-exported)
from .scene_plans import scene_plan
from .stick_decisions import stick_decisions
from .moreau_jean_records import (HISTORY, MAX_CHUNK, WORK_CLOSED, WORK_GRAZING, WORK_SLIP_SIGN, Collector, Grid,
                                  ResumeState, Window, compile_samples, kept_steps)

# A window row with the temporaries of collecting from it, in samples (bench_memory.py, ball,
# 65 536-step windows, save_every = 0.1 s: 8.1 MB measured for 1e6 and 1e7 steps).
WINDOW_SAMPLES = 1.1
STATE_CODES = {name: code for code, name in enumerate(STATE_NAMES)}
_STATE_WORDS = np.array(STATE_NAMES, dtype=object)  # a state code's word (the result's modes)
# Solver settings the compiled kernels take (the Python solvers read solver_options themselves);
# 0 means the kernel's own default (solvers/kernels.py).
DEFAULT_RTOL, DEFAULT_MAX_ITER = 0.0, 0
# The default step without tol; with tol, the default first and largest step (error control
# shortens it where the tolerance asks).
FIXED_STEP, MAX_STEP_WITH_TOL = 1e-4, 1e-2


@dataclass
class MoreauJeanOptions:
    """Step size, θ of the θ-method, contact activation and the one-step solver."""

    # the step size; with tol, the first and largest step (default FIXED_STEP, with tol MAX_STEP_WITH_TOL)
    h: float | None = option(None, Number(0.0, open_lo=True, optional=True), label="h (step size)")
    theta: float = option(0.5, Number(0.0, 1.0))
    # a contact enters the step when g + γ h u_N ≤ 0
    activation_gamma: float = option(0.5, Number(0.0, 1.0), label="activation_gamma")
    solver: str = option(DEFAULT_SOLVER, SolverName())
    solver_options: dict = option(None, None, default_factory=dict)  # checked per solver below
    stop_at_impact: str | None = option(None, Text())  # name of a contact whose first impact ends the run
    min_phase: float | None = option(None, Number(0.0, optional=True))  # shorter phases are merged (default 2h)
    allow_energy_gain: bool = option(False, Flag())  # θ < ½ amplifies energy; refused unless asked for
    fast: bool = option(True, Flag())  # use the compiled loop when the scene and solver allow it
    # repeat an exact rest (a fixed point of the step) instead of solving it again: the same run
    # bit for bit, in a fraction of the time (docs/performance.md); off to time the steps themselves
    repeat_rest: bool = option(True, Flag())
    # error control (integrators/adaptive.py): step sizes chosen for this tolerance on positions (m, rad)
    # and on located event times (s); None: fixed steps of h
    tol: float | None = option(None, Number(0.0, 0.1, open_lo=True, optional=True), label="tol")
    # impacts closing slower than a fall from this height (m) are an accumulation's unresolved
    # tail: applied, not reported (integrators/accumulation.py, the rule of every method); 0: all
    resolution: float = option(0.0, Number(0.0, 1.0))

    def __post_init__(self):
        check_options(self)
        self.solver_options = check_solver_options(self.solver, self.solver_options)
        if self.theta < 0.5 and not self.allow_energy_gain:
            raise InputError(
                f"theta = {self.theta:g} < 0.5 makes Moreau–Jean gain energy; use theta in [0.5, 1] "
                "(or allow_energy_gain=True to study it)"
            )
        if self.h is None:
            self.h = FIXED_STEP if self.tol is None else MAX_STEP_WITH_TOL
        if self.min_phase is None:
            self.min_phase = 2 * (self.h if self.tol is None else self.tol)


_ENTRY_POINTS = ("run_steps", "step_force", "begin_step", "assemble", "finish_step", "end_of_step",
                 "drive_step", "hold_driven_velocities", "place_driven_bodies", "step_time")


def loop_kernels(compiled: bool):
    """The loop's entry points: compiled (the module itself), or their plain-Python twins from
    the same source (solvers._common.interpreted rebinds every kernel they call)."""
    if compiled or not _jit.ENABLED:
        return loop
    return SimpleNamespace(**{name: interpreted(getattr(loop, name)) for name in _ENTRY_POINTS})


def _model_and_work(packed, resume: ResumeState | None, driven_origin=None, joints=None):
    """The model and work tuples of moreau_jean_loop; the contact memory from `resume`; `joints`
    the scene's joint table (model.joints.pack_joints; None: no joints)."""
    model = _model(packed, driven_origin, joints)
    work = _new_work(packed.n_contacts, packed.minv.shape[0], model.joints)
    _restore_memory(work, resume)
    return model, work


def _model(packed, driven_origin=None, joints=None):
    """moreau_jean_loop's Model of a packed scene (its arrays themselves, not copies)."""
    if joints is None:
        joints = pack_joints((), packed.minv.shape[0] // 3)
    return loop.Model(packed.minv, packed.weight, packed.contacts, packed.contact_index, packed.force_table,
                      packed.force_index, packed.force_times, packed.force_values, packed.disks, packed.disk_body,
                      packed.pair_keys, packed.pair_contact, *_drive_slots(packed, driven_origin), joints)


def _new_work(nc: int, n_dof: int, joints):
    """moreau_jean_loop's Work, zeroed: no contact closed, no memory."""
    f, i = np.float64, np.int64  # one buffer a dtype: a lent Work is zeroed by two fills (integrators/carved.py)
    return loop.Work(*carve_zeros((((nc,), f), ((nc,), f), ((nc, 6), f), ((nc, 6), f), ((nc,), i), ((nc,), i),
                                   ((nc,), i), ((nc,), f), ((n_dof,), f), ((n_dof,), f), ((nc,), i),
                                   ((work_size(joints, n_dof),), f))))


def _restore_memory(work, resume: ResumeState | None) -> None:
    """The contact memory (closed, grazing, slip signs) of the end state a run resumes from."""
    if resume is not None:
        work[WORK_CLOSED][:], work[WORK_GRAZING][:], work[WORK_SLIP_SIGN][:] = \
            resume.was_closed, resume.grazing, resume.slip_sign


def _drive_slots(packed, driven_origin):
    """The model's slots M_MOTIONS … M_DRIVEN_ORIGIN (moreau_jean_loop): the packed motions, their
    per-step evaluation and the driven bodies with the placement each motion displaces."""
    origin = np.zeros((len(packed.driven), 3)) if driven_origin is None else driven_origin
    return (packed.motion_table, packed.motion_times, packed.motion_values,
            np.zeros((packed.motion_table.shape[0], N_NOW_COLUMNS)), packed.driven, origin)


def driven_start(packed, q0, v0, t0: float):
    """(origin of each driven body's motion, v0 with the driven bodies' prescribed velocities):
    a driven body starts where q0 puts it and follows q0 + d(t) − d(t0)."""
    origin, v0 = np.zeros((len(packed.driven), 3)), np.array(v0, dtype=float)
    for r, (body, m) in enumerate(packed.driven):
        d, w = packed.motions[m].at(t0)
        origin[r] = q0[3 * body: 3 * body + 3] - d
        v0[3 * body: 3 * body + 3] = w
    return origin, v0


def _run_data(plan, q0, v0, grid: Grid, resume, lent):
    """(model, work, v0) of a run: the plan's model when the scene has no driven motion (else one
    with their origins, and v0 with the driven bodies' prescribed velocities), and a zeroed Work
    (of the set `lent` by the plan, or new), with the contact memory of `resume`."""
    if plan.static:
        if plan.model is None:
            plan.model = _model(plan.packed, None, plan.joints)
        model = plan.model
    else:
        origin, v0 = driven_start(plan.packed, q0, v0, float(grid.time(grid.first)))
        model = _model(plan.packed, origin, plan.joints)
    work = lent[0] if lent is not None else _new_work(plan.packed.n_contacts, plan.packed.minv.shape[0], plan.joints)
    _restore_memory(work, resume)
    return model, work, v0


# A run's Work and window records a scene's plan lends to its next run of as many rows, up to this
# size (a short run's: zeroing a long window's rows again would cost more than new zeroed pages,
# and a plan keeps them). One set, one borrow and one return a run (each ~1 µs of a short call).
LENT_WINDOW_BYTES = 1 << 18


# Record columns a window starts with, per body (at least MIN_RECORD_COLUMNS; at most one a
# contact): a tower of 5 boxes has 20 candidates among its 340 found contacts (each box's corners
# on the top below and the floor, the top corners below on its bottom edge); more widen it. Each
# column is a step's 4 records: a 5000-step window of 8 a body wrote (zeroed) 6.4 MB for the tower.
RECORD_COLUMNS_PER_BODY, MIN_RECORD_COLUMNS = 4, 16


def _window(n_dof: int, n_contacts: int, chunk: int, joint_rows: int, slip_default, lent, work) -> Window:
    """The run's window: with the records of the set an earlier run of the scene `lent` (zeroed),
    or new, with a column of records for the contacts that are candidates (new_records)."""
    columns = max(MIN_RECORD_COLUMNS, RECORD_COLUMNS_PER_BODY * (n_dof // 3))
    window = Window(n_dof, n_contacts, chunk, joint_rows, None if lent is None else lent[1], columns, slip_default)
    # a window small enough to lend leaves its last rows to be taken on first need (Collector.settle_rows:
    # its result then holds it); a larger one has them taken in the run, as its result's end state
    window.defer_rows = lent is not None or sum(a.nbytes for a in (*work, *window.out)) <= LENT_WINDOW_BYTES
    return window


def _snapshot(work, window: Window):
    """(the work arrays' buffers and their copies, the window's counters' copy) at a chunk's start,
    for the chunk to be run again from it (a Work is carved from a buffer per dtype: two copies)."""
    buffers = owners(work)
    return (buffers, [b.copy() for b in buffers]), window.out.counters.copy()


def _same_float(a: float, b: float) -> bool:
    """The same float, sign of zero included (−0.0 is not 0.0: the grid's times would differ in it)."""
    return a == b and math.copysign(1.0, a) == math.copysign(1.0, b)


def _lend(plan, lent, work, window: Window, holder=None) -> bool:
    """The run's Work and window records back to the scene's plan, for its next run of as many
    rows, when small; True if lent (`holder`: the result whose end state is built from them on
    first read). The set `lent` itself when the run kept it (the plan knows its buffers)."""
    kept = lent if lent is not None and lent[1] is window.out else (work, window.out)
    return plan.give_back(window.rows, kept, LENT_WINDOW_BYTES, holder)


def _chunk_size(grid: Grid, stopping: bool) -> int:
    """Steps per window: the whole run up to MAX_CHUNK; with a stop condition, a 64th of the run
    (tried between windows: a stop costs at most ~2/64 of the run past the step where it holds)."""
    if stopping:
        return max(64, min(MAX_CHUNK, grid.n_steps // 64))
    return max(1, min(MAX_CHUNK, grid.n_steps))


def check_resume(resume, scene, q0, v0) -> None:
    """Refuse an end state that is not a Moreau–Jean one of this scene, ending in (q0, v0)."""
    n_dof, nc = scene.n_dof, len(scene.contacts)
    if not isinstance(resume, ResumeState):
        raise InputError(f"resume must be the end_state of a Moreau–Jean result, got {type(resume).__name__}")
    if resume.q.shape[1:] != (n_dof,) or resume.states.shape[1:] != (nc,) or resume.q.shape[0] != \
            resume.states.shape[0] + 1 or resume.states.shape[0] > HISTORY:
        raise InputError("resume state does not match the scene (degrees of freedom or contacts)")
    if not (np.array_equal(q0, resume.q[-1]) and np.array_equal(v0, resume.v[-1])):
        raise InputError("resume: q0 and v0 must be the end state's (resume.q[-1], resume.v[-1])")


# Steps run interpreted to measure a cold run's per-step cost before deciding whether to compile.
PROBE_STEPS = 16


def compiled_part(solver: str, solver_code, callback: bool):
    """(cache part, what it is in words, background job's arguments) of the compiled entry a run
    uses: the loop (whole runs, and one step a call where a Python force is called back between
    steps — `callback`), or the step kernels around a Python (QP) solver. The exact solvers share
    the compiled loop."""
    if solver_code is None:
        return "moreau-jean-python-step", "the step kernels around Python solvers", ["--python-step", solver]
    return LOOP_PART, _LOOP_IN_WORDS, []  # callbacks run it step by step


LOOP_PART = "moreau-jean"


_LOOP_IN_WORDS = f"the Moreau–Jean loop ({', '.join(EXACT_SOLVERS)})"


_NOTHING = contextlib.nullcontext()  # (reusable: it holds nothing)
# A run of at least this many steps holds BLAS to one thread (_jit.one_blas_thread: the hold
# search's small SVDs once woke OpenBLAS's thread pool, which then slowed the steps and whatever
# ran next). A shorter one leaves it as it is: setting and restoring the limit costs ~1 yardstick,
# more than its few LAPACK calls can lose (the row of 16 balls and the 4- and 8-row piles measured
# the same without the limit, 2026-11-26: docs/performance.md).
BLAS_LIMIT_STEPS = 64
NO_EXTRA_FORCE = np.zeros(0)  # run_steps' `extra` when no Python force is called back
_DIRECT = DirectEntry()  # run_steps without numba's overload search for the model, work, records it knows


class Engine:
    """The kernels a run's steps use: compiled, or their interpreted twins (the same source).

    A cold compiled part under the default policy (_jit) runs its first PROBE_STEPS steps
    interpreted and times them: when the rest of the run is shorter than compiling, it goes on
    interpreted while a detached process compiles the part for later runs; otherwise it compiles
    now (once, said with the time measured here) and goes on compiled from the step it reached.
    """

    def __init__(self, compiled: bool, part: str, what: str, job: list):
        self.part, self.what, self.job = part, what, job
        self.probing = compiled and not _jit.engine_is_warm(part) and _jit.compile_policy() == "auto"
        self.compiled = compiled and not self.probing  # the kernels are numba's (not the interpreted twins)
        self.kernels = loop_kernels(self.compiled)
        self.warm = self.compiled and _jit.engine_is_warm(part)  # compiled and in the cache: no notice, ever

    def steps(self, n: int) -> int:
        """How many of the n steps the next call may run (the probe's, while probing)."""
        return min(n, PROBE_STEPS) if self.probing else n

    def measured(self, steps: int, seconds: float, steps_left: int, status) -> None:
        """After a call: decide, once the probe has run, whether the rest runs compiled."""
        if not self.probing or steps <= 0:
            return
        self.probing = False
        compile_s, _ = _jit.compile_estimate_s(self.part)
        if seconds / steps * steps_left > compile_s and status == loop.RUN_OK:
            self.compiled, self.kernels = True, loop
        else:
            _jit.compile_in_background(self.part, self.job, self.what, compile_s)

    def compiling(self):
        """The compile notice and lock around a call of the compiled kernels (nothing when warm)."""
        if not self.compiled or _jit.engine_is_warm(self.part):  # (a set lookup once known warm)
            return _NOTHING
        # the loop's callees compiled on two cores before it (_compile_split)
        return _jit.compiling(self.part, self.what, prepare=_prepare_loop if self.part == LOOP_PART else None)


def _prepare_loop(log) -> None:
    """Before the loop compiles: its callees on two cores, and the samples' kernel (what a run
    calls compiled besides the loop)."""
    compile_callees(log)
    compile_samples()


_WARM_ENGINES: dict = {}  # part → its Engine once warm: compiled, probing nothing, it holds no run's state


def run_engine(compiled: bool, part: str, what: str, job: list) -> Engine:
    """A run's Engine: the part's shared one while its compiled kernels are warm (a set lookup:
    _jit.engine_is_warm), else a new one (it may probe, then compile or go on interpreted)."""
    if compiled and _jit.engine_is_warm(part):
        engine = _WARM_ENGINES.get(part)
        if engine is None:
            engine = _WARM_ENGINES[part] = Engine(compiled, part, what, job)
        return engine
    return Engine(compiled, part, what, job)


# The endings of a chunk of steps whose break-aways are reviewed (stick_decisions): every step
# of it done (a stop at an impact included: a break-away before it may move the impact)
REVIEWED = (loop.RUN_OK, loop.RUN_STOPPED)


class MoreauJean:
    """The Moreau–Jean one-step integrator over a Scene (one loop: moreau_jean_loop)."""

    name = "moreau-jean"

    def __init__(self, options: MoreauJeanOptions | None = None):
        self.options = options or MoreauJeanOptions()
        self._predicted_switches = {}  # the last run's break-aways at predicted times (stick_decisions)

    SAMPLES_KNOB = "a larger h, a coarser save_every or a shorter t_end"  # what keeps fewer samples (the driver's memory refusal says it)

    @staticmethod
    def samples_estimate(options, duration: float, save_every: float | None) -> float:
        """How many samples a run keeps (the driver's memory check), counting the window of
        per-step rows it runs in and the temporaries of taking samples from it (measured:
        WINDOW_SAMPLES samples' worth a row, benchmarks/bench_memory.py)."""
        if options.tol is not None:  # error control keeps its accepted steps until the run ends
            from .adaptive import samples_estimate
            return samples_estimate(options, duration)
        steps = duration / options.h
        return thinned_count(steps, duration, save_every) + 2 + WINDOW_SAMPLES * min(steps, MAX_CHUNK)

    def run(self, scene: Scene, q0, v0, t_end: float, *, t0: float = 0.0, resume: ResumeState | None = None,
            save_every: float | None = None, stop=()) -> SimulationResult:
        """From (q0, v0) at t0 (or the end state `resume` of an earlier run) to exactly t_end,
        keeping one sample per `save_every` (default: every step); `stop`: callables (t, q, v)
        tried at each kept sample, ending the run at the first that holds."""
        opts = self.options
        q0, v0 = np.asarray(q0, dtype=float), np.asarray(v0, dtype=float)  # checked by the driver
        if opts.tol is not None:
            return self._run_with_tol(scene, q0, v0, t_end, t0, resume, save_every, stop,
                                      [c.name for c in scene.contacts])
        plan = scene_plan(scene)  # packed once for the runs that repeat the scene
        packed, names = plan.packed, list(plan.names)
        grid, params, iparams, slip_default = self._run_parameters(plan, scene, t0, t_end, resume, names)
        chunk = _chunk_size(grid, bool(stop))
        lent = plan.borrow(HISTORY + chunk)  # (Work, Records) of an earlier run of as many rows, zeroed
        model, work, v0 = _run_data(plan, q0, v0, grid, resume, lent)
        window = _window(scene.n_dof, len(names), chunk, ROWS_PER_JOINT * len(scene.joints), slip_default, lent, work)
        window.seed(q0, v0, grid.first, resume)
        collector = Collector(grid, scene.n_dof, len(names), save_every, resume, ROWS_PER_JOINT * len(scene.joints))
        solver_code = SOLVER_CODES.get(opts.solver)
        # a step needs Python: a Python applied_force or a Python (Prescribed) motion
        self._motions_in_python = plan.python_motions
        self._calls_back = scene.applied_force is not None or bool(self._motions_in_python)
        self._whole_loop = not self._calls_back and solver_code is not None  # one compiled call a chunk
        engine = run_engine(bool(opts.fast and _jit.ENABLED), *compiled_part(opts.solver, solver_code, self._calls_back))
        self._solver_error = None
        wall = time.process_time()
        decisions = stick_decisions(scene, model, grid, plan, engine)
        with _jit.one_blas_thread() if grid.n_steps >= BLAS_LIMIT_STEPS else _NOTHING:
            ending = self._windows(engine, scene, grid, window, collector, params, iparams, model, work, list(stop),
                                   decisions)
        cpu = time.process_time() - wall
        stats = {"h": opts.h, "theta": opts.theta, "solver": opts.solver,
                 "compiled": engine.compiled and solver_code is not None,
                 "force_callback": self._calls_back, "stick_predictions": decisions.predictions if decisions else 0}
        self._predicted_switches = decisions.switches if decisions else None
        result = self._result(scene, packed, grid, window, collector, work, ending, names, cpu, stats)
        # lent to the next run of the scene, which first has the result copy its end state out of
        # them if it is still alive (a loop that drops each result never copies); a window too
        # large to lend is not kept alive by the result: its end state is copied now
        if not _lend(plan, lent, work, window, result):
            result.settle_end_state()
        return result

    def _run_with_tol(self, scene, q0, v0, t_end, t0, resume, save_every, stop, names) -> SimulationResult:
        """The error-controlled run (integrators/adaptive.py) on this integrator's loop and kernels."""
        from .adaptive import run_adaptive

        packed = pack_scene(scene)
        model, work = _model_and_work(packed, resume)
        params, iparams = self._parameters(scene, Grid.of(self.options.h, t0, t_end, None), names)
        engine = Engine(bool(self.options.fast and _jit.ENABLED),
                        *compiled_part(self.options.solver, SOLVER_CODES.get(self.options.solver),
                                       scene.applied_force is not None))
        self._solver_error, self._motions_in_python = None, []  # tol: no driven motions (declares)
        with _jit.one_blas_thread():
            return run_adaptive(self, scene, q0, v0, t_end, t0, resume, save_every, list(stop), engine,
                                model, work, params, iparams, PROBE_STEPS, _BOUNDARY_KIND)

    def _run_parameters(self, plan, scene, t0, t_end, resume, names):
        """(grid, params, iparams, slip record of a contact out of reach) of a run: kept by the
        scene's plan for its next run from (q0, v0) with the same options object (the driver hands
        the same checked options to runs with the same values), start and end; the parameters
        copied, for the loop writes into them (a grid is never changed)."""
        kept = plan.parameters
        if resume is None and kept is not None and kept[0] is self.options and _same_float(kept[1], t0) \
                and _same_float(kept[2], t_end):
            grid, params, iparams, slip_default = kept[3:]
        else:
            grid = Grid.of(self.options.h, t0, t_end, resume)
            params, iparams = self._parameters(scene, grid, names, plan.varies_in_time)
            slip_default = -plan.packed.contacts[:, C_SURFACE_VELOCITY]
            if resume is None:
                plan.parameters = (self.options, t0, t_end, grid, params, iparams, slip_default)
        return grid, params.copy(), iparams.copy(), slip_default

    def _parameters(self, scene, grid, names, varies_in_time=None):
        opts = self.options
        if varies_in_time is None:
            varies_in_time = scene.forces_vary_in_time()
        solver_code = SOLVER_CODES.get(opts.solver)
        solver_options = opts.solver_options
        values = [0.0] * loop.N_PARAMS  # one array from Python floats: cheaper than writing its items
        values[loop.P_H], values[loop.P_THETA], values[loop.P_GAMMA] = opts.h, opts.theta, opts.activation_gamma
        values[loop.P_H_GRID] = opts.h
        values[loop.P_T0], values[loop.P_RTOL] = grid.origin, float(solver_options.get("tol", DEFAULT_RTOL))
        params = np.array(values, dtype=float)
        iparams = np.array([-1 if solver_code is None else solver_code,
                            int(solver_options.get("max_iter", DEFAULT_MAX_ITER)),
                            names.index(opts.stop_at_impact) if opts.stop_at_impact in names else -1,
                            int(opts.repeat_rest and not varies_in_time)], dtype=np.int64)
        return params, iparams

    def _windows(self, engine, scene, grid, window, collector, params, iparams, model, work, stops, decisions):
        """Run the grid's steps window by window, each chunk of steps in the holds and releases
        `decisions` plans (integrators/stick_decisions.py; None: the step's law alone) and its
        break-aways reviewed by them; returns (run status, global step the run ended at)."""
        k = grid.first
        if stops and stop_holds(stops, grid.time(k), window.out.q[window.r], window.out.v[window.r]):
            collector.take(window, k, k, True, engine.compiled)
            return loop.RUN_STOPPED_BY_CONDITION, k
        while k < grid.last:
            if window.room() == 0:
                if decisions is not None:
                    decisions.keep_start()  # (its rows move)
                window.slide()
            last = bool(grid.h_last) and k == grid.last - 1
            n = engine.steps(1 if last else min(window.room(), grid.first + grid.n_full - k))
            held, taken_back = None, False
            if decisions is not None:  # cut at the holds it plans, run in them
                n, held, taken_back = decisions.chunk(window, k, n)
            step_params = self._shortened(params, grid, window, k) if last else params
            params[loop.P_K0] = window.k_base
            snapshot = _snapshot(work, window) if stops or taken_back else None
            started = time.perf_counter() if engine.probing else None
            status, k_done = self._advance(engine, scene, window, n, step_params, iparams, model, work, held)
            if started is not None:
                engine.measured(k_done - k, time.perf_counter() - started, grid.last - k_done, status)
            k_back = decisions.review(window, k, k_done) if decisions and status in REVIEWED else None
            if k_back is not None:  # its steps from k_back on are run again, as the review planned
                k_done = self._replay(engine, scene, window, snapshot, k, k_back, (step_params, iparams, model, work), held)
                status = loop.RUN_OK
            k_hold = self._first_hold(stops, collector, window, k, k_done) if stops else None
            if k_hold is not None:
                if k_hold < k_done:  # replay to the step where it holds: the end state is that step's
                    self._replay(engine, scene, window, snapshot, k, k_hold, (step_params, iparams, model, work), held)
                collector.take(window, k, k_hold, True, engine.compiled)
                return loop.RUN_STOPPED_BY_CONDITION, k_hold
            final = status != loop.RUN_OK or k_done == grid.last
            collector.take(window, k, k_done, final, engine.compiled)
            k = k_done
            if status != loop.RUN_OK:
                return status, k
        return loop.RUN_OK, k

    def _replay(self, engine, scene, window, snapshot, k, k_to, arrays, held) -> int:
        """The chunk's steps from k run again to k_to, from the work memory and counters of
        `snapshot` (taken at k), in the context `held` it ran in; returns k_to."""
        for buffer, saved in zip(*snapshot[0]):
            buffer[...] = saved
        window.out.counters[:] = snapshot[1]
        window.r = k - window.k_base
        if k_to > k:
            self._advance(engine, scene, window, k_to - k, *arrays, held)
        return k_to

    @staticmethod
    def _shortened(params, grid, window, k):
        """Parameters of the last step, shortened to end at t_end: it starts at t_k of the grid."""
        p = params.copy()
        p[loop.P_H], p[loop.P_T0], p[loop.P_K0] = grid.h_last, grid.origin + float(k) * grid.h, -float(k - window.k_base)
        return p

    def _advance(self, engine, scene, window, n, params, iparams, model, work, held=None):
        """n steps from the window's current row with the engine's kernels (compiled, or their
        interpreted twins) in the context `held` (the chunk's holds: stick_decisions; None: none); returns
        (run status, global step reached)."""
        r0 = window.r
        window.out.counters[loop.K_DONE] = r0
        compiling = _NOTHING if engine.warm else engine.compiling()
        if held is None and compiling is _NOTHING:  # (most chunks: no context's Python calls)
            status = self._steps(engine.kernels, scene, window, r0, n, params, iparams, model, work)
        else:
            with held or _NOTHING, compiling:
                status = self._steps(engine.kernels, scene, window, r0, n, params, iparams, model, work)
        window.r = int(window.out.counters[loop.K_DONE])
        return int(status), window.k_base + window.r

    def _steps(self, kernels, scene, window, r0, n, params, iparams, model, work):
        """Steps r0 … r0 + n − 1 of the window, its records widened whenever a new candidate finds
        their columns taken (and that step run again); returns the run status."""
        r = r0
        while True:
            out = window.out
            if self._whole_loop:
                status = _DIRECT.run_steps(kernels, r, r0 + n, params, iparams, model, work, out, NO_EXTRA_FORCE)
            else:
                status = self._run_stepwise(kernels, scene, r, r0 + n, params, iparams, model, work, out)
            if status != loop.RUN_RECORDS_SHORT:
                return status
            window.widen()  # and step K_DONE again, from its start
            r = int(window.out.counters[loop.K_DONE])

    def _first_hold(self, stops, collector, window, k_from, k_to):
        """The first kept step in (k_from, k_to] where a stop condition holds, or None."""
        ks = kept_steps(collector.grid, k_from + 1, k_to, collector.save_every)
        ks = ks[ks > k_from]
        rows = ks - window.k_base  # q, v rows copied (fancy indexing): the conditions' own
        held = first_hold(stops, collector.grid.time(ks), window.out.q[rows], window.out.v[rows])
        return None if held is None else int(ks[held])

    def _run_stepwise(self, kernels, scene, r_start, r_end, params, iparams, model, work, out):
        """The loop step by step from Python: for a Python `applied_force` (called back for each
        step's force) and for the Python (QP) solvers."""
        q, v, counters = out.q, out.v, out.counters
        f, extra = np.empty(scene.n_dof), np.zeros(scene.n_dof)
        compiled = int(iparams[loop.I_SOLVER]) >= 0  # an exact solver: the compiled loop, one step a call
        motions = self._motions_in_python
        for k in range(r_start, r_end):
            if motions:
                t = kernels.step_time(params, k)
                evaluate_python_motions(motions, t, t + params[loop.P_H], model[loop.M_MOTION_NOW])
            if scene.applied_force is not None:
                t = params[loop.P_T0] + ((params[loop.P_K0] + k) + params[loop.P_THETA]) * params[loop.P_H]
                extra[:] = scene.applied(t, q[k], v[k])
            if compiled:  # books the step itself (end_of_step)
                status = kernels.run_steps(k, k + 1, params, iparams, model, work, out, extra)
                if status != loop.RUN_OK:
                    return status if status == loop.RUN_RECORDS_SHORT else counters[loop.K_STATUS]
                continue
            kernels.step_force(k, params, model, out, f)
            f += extra
            status = self._python_solver_step(kernels, k, f, params, iparams, model, work, out)
            if status == loop.RUN_RECORDS_SHORT:
                return status  # (_advance widens the records and runs step k again)
            if kernels.end_of_step(k, status, counters) != loop.RUN_OK:
                return counters[loop.K_STATUS]
        return loop.RUN_OK

    def _python_solver_step(self, kernels, k, f, params, iparams, model, work, out):
        """One step with a Python solver (QP backends): the loop's kernels around
        solve_two_coefficient."""
        q, v, counters = out.q, out.v, out.counters
        kernels.drive_step(k, params, model)
        na = kernels.begin_step(params, q[k], v[k], f, model, work, k, out)
        if na < 0:
            return loop.geometry_failure(na, model[2].shape[0], counters)
        kernels.hold_driven_velocities(model, work)
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
        status = kernels.finish_step(k, params, iparams, na, p, u, states, q[k], v[k], model, work, out)
        kernels.place_driven_bodies(k, model, out)
        return status

    def _ending(self, status, k_end, grid, window, names):
        """(status word, message, solver-failure event or None) of how the run ended at step k_end."""
        if status == loop.RUN_OK:
            return Status.OK, grid.reached, None
        if status == loop.RUN_STOPPED:
            return Status.OK, f"stopped at the impact of {self.options.stop_at_impact}", None
        out = window.out
        q, counters = out.q, out.counters
        t_end = float(grid.time(k_end))
        if status == loop.RUN_STOPPED_BY_CONDITION:
            return Status.STOPPED, stop_message(t_end), stop_event(t_end)
        k = window.k_base + int(counters[loop.K_FAIL_STEP])  # the failing step
        t_k = float(grid.origin + k * grid.h)
        if status == loop.RUN_NONFINITE:
            return Status.FAILED, f"non-finite state at step {k + 1}, t = {float(grid.time(k + 1)):.9g} s", None
        if status == loop.RUN_BAD_GEOMETRY:
            name = names[int(counters[loop.K_FAIL_CONTACT])]
            return Status.FAILED, (f"{name}: disk centres coincide at step {k}, t = {t_k:.9g} s, the contact "
                              "normal is undefined"), None
        if status == loop.RUN_PASSED_THROUGH:
            name = names[int(counters[loop.K_FAIL_CONTACT])]
            return Status.FAILED, (f"{name}: the disk is deeper than its radius at step {k}, t = {t_k:.9g} s: it "
                              f"passed through its obstacle within a step; use a smaller h than {grid.h:g} s"), None
        r = k - window.k_base
        states = window.full(5, r - 1) if r else None  # every contact's
        state_txt = _states_text(names, states)
        closed = int(np.count_nonzero(states != STATE_OPEN)) if r else 0
        if closed > q.shape[1]:  # (measured on the 50-box heap: no duplicate rows, not the pivot limit)
            state_txt += (f"; {closed} contacts closed on {q.shape[1]} degrees of freedom: a redundant, "
                          "degenerate step problem whose solution failed the solver's accuracy check")
        where = f"step {k}, t = {t_k:.9g} s, contact states {state_txt}, q = {np.array2string(q[r], precision=6)}"
        if self._solver_error is not None:
            message = str(self._solver_error.with_context(where))
        else:
            message = f"{self.options.solver}: {_KERNEL_FAILURES.get(int(counters[loop.K_SOLVER_STATUS]), 'failed')} ({where})"
        return Status.FAILED, message, Event(t_k, "solver-failure", "", {"message": message})

    def _impacts(self, scene, grid, collector, names):
        minv = scene.inverse_mass_diagonal
        impacts, events = [], []
        for k, i, t_hit, q_k, v_k, v_next, p_n, p_t in collector.impact_rows:
            t_k = float(grid.origin + k * grid.h)
            f = scene.force(t_k, q_k, v_k)
            v_hit = v_k + (t_hit - t_k) * minv * f
            q_hit = q_k + (t_hit - t_k) * v_k
            if not accumulation.impact_resolved(scene, i, t_hit, q_hit, v_hit, self.options.resolution):
                continue
            impacts.append(Impact(t_hit, names[i], q_hit, v_hit, v_next, p_n, p_t))
            events.append(Event(t_hit, "impact", names[i], {"step": k}))
        return impacts, events

    def _result(self, scene, packed, grid, window, collector, work, ending, names, cpu, stats) -> SimulationResult:
        """The run's result (`stats`: the run's own dict, completed here with the loop's counts)."""
        run_status, k_end = ending
        status, message, final_event = self._ending(run_status, k_end, grid, window, names)
        impacts, events = self._impacts(scene, grid, collector, names) if collector.impact_rows else ([], [])
        counters = window.out.counters
        t, q, v, a, N, T, codes = collector.trajectory_arrays()
        modes = _STATE_WORDS.take(codes)
        if k_end == grid.first and collector.resume is None:
            modes[:] = "open"
        t_stop = None
        if run_status == loop.RUN_STOPPED:
            t_stop = max(i.t for i in impacts if i.contact == self.options.stop_at_impact)
        n_done, counts = k_end - grid.first, counters.tolist()
        stats.update(steps=n_done, solves=counts[loop.K_SOLVES], solver_iterations=counts[loop.K_ITERATIONS],
                     inconsistent_steps=counts[loop.K_INCONSISTENT], solver_fallbacks=counts[loop.K_FALLBACKS],
                     steps_at_rest=counts[loop.K_REPEATED], unresolved_impacts=len(collector.impact_rows) - len(impacts))
        result = SimulationResult(self.name, status, message, Trajectory(t, q, v, a, N, T, modes), names, [],
                                  impacts, {}, steps=n_done, cpu_time_s=cpu, stats=stats)
        result.defer(functools.partial(_locate, scene, collector, packed, impacts, grid, k_end, self.options.min_phase,
                                       t_stop, self._predicted_switches, events, final_event))
        if status == "failed":  # located now: a failed run's contacts may not bear evaluating later
            result._settle()
        if scene.joints:
            result.joint_forces = joint_forces(scene.joints, collector.joint_force[:collector.n])
        on_grid = k_end < grid.last or not grid.h_last
        last_h = grid.h_last if k_end == grid.last and grid.h_last else (
            collector.resume.last_h if k_end == grid.first and collector.resume is not None else grid.h)
        if status == "failed":
            result.end_state = None
        else:  # built on first read (run() settles it before its arrays are reused), the rows with it
            result.build_end_state(functools.partial(_end_state, collector, window, grid, work, last_h, on_grid))
        return result


def _locate(scene, collector, packed, impacts, grid, k_end, min_phase, t_stop, predicted, events, final_event,
            result) -> None:
    """A run's phases and events, on first use of result.phases or result.events (SimulationResult.defer)."""
    collector.settle_rows()
    phases, phase_events = located_phases(scene, collector, packed, impacts, grid, k_end, min_phase, t_stop, predicted)
    result.phases = phases
    result.events = sorted(events + phase_events, key=lambda e: e.t) + ([final_event] if final_event else [])


def _end_state(collector, window, grid, work, last_h, on_grid) -> ResumeState:
    """A run's end state, on its first read (SimulationResult.build_end_state), the rows with it."""
    collector.settle_rows()
    return window.resume_state(grid, work, last_h, on_grid)


def _tol_with_joints_or_driven(scene, options, duration) -> dict | None:
    if options.tol is None:
        return None
    found = first_joint(scene) or first_driven(scene)
    return None if found is None else {"item": found["item"] + ("" if scene.joints else " (driven)")}


MoreauJean.declares = Declaration(
    options=MoreauJeanOptions,
    contacts=("DiskOnLine", "DiskOnDisk", "DiskOnSegment", "SegmentEndOnEdge", "VertexOnEdge",
              "LinearRelation"),
    samples_estimate=MoreauJean.samples_estimate, samples_knob=MoreauJean.SAMPLES_KNOB,
    refusals=(Refusal(_tol_with_joints_or_driven, "tol: error control does not handle joints or driven obstacles "
                                                  "and bodies yet ({item}); give a fixed step h instead"),),
    resumes=check_resume, compiles=lambda options: options.fast)

def joint_forces(joints, impulses_over_h) -> dict:
    """{joint name: {reaction: samples}}: a pin's world force (Fx, Fy) on body_a, a slider's force
    F along its line's normal and torque M on body_a (N, N·m: the step's impulses / h)."""
    return {joint.name: {what: impulses_over_h[:, ROWS_PER_JOINT * i + r]
                         for r, what in enumerate(REACTION_NAMES[joint.kind])} for i, joint in enumerate(joints)}


# A failure message lists every contact's state up to this many contacts; beyond, only those not
# open (a heap of 50 boxes lists 39 800 candidates: a message of a megabyte).
MESSAGE_ALL_STATES = 12


def _states_text(names, states) -> str:
    """The contacts' states at the step before a failure ('initial' at the first step)."""
    if states is None:
        return ", ".join(f"{name}:initial" for name in names[:MESSAGE_ALL_STATES]) + (
            f" (+{len(names) - MESSAGE_ALL_STATES} more)" if len(names) > MESSAGE_ALL_STATES else "")
    shown = [i for i in range(len(names)) if len(names) <= MESSAGE_ALL_STATES or states[i] != STATE_OPEN]
    text = ", ".join(f"{names[i]}:{STATE_NAMES[states[i]]}" for i in shown)
    return text if len(shown) == len(names) else f"{text} (the other {len(names) - len(shown)} open)"


_KERNEL_FAILURES = {1: "no valid solution of the step problem (secondary ray)",
                    2: "no valid solution of the step problem (no convergence)",
                    3: "the step problem has more contacts than the solver takes",
                    4: "non-finite data in the step problem"}


# --- phase boundaries located inside the step ------------------------------------------------
_BOUNDARY_KIND = {"open": "liftoff", "stick": "slip-zero"}  # by the mode entered; otherwise:
SLIP_MODES = ("slip+", "slip-")


def _crossing(values, level, k, h):
    """Where the linear extrapolation of step impulses values(k−2), values(k−1) reaches `level`,
    as an offset from t_k; None without a usable slope.

    The impulse of step j that keeps a persistent contact closed answers the change of its
    Jacobian from q_{j−1} to q_j (a backward difference): it is the force at t_j − h/2, not at
    the step's midpoint (measured on the rolling rod: T/N of step j is the exact one at
    t_j − 0.58 h in the paper's case 3, later in case 2); we take it at the step's start t_j."""
    if k < 2:
        return None
    slope = (values(k - 1) - values(k - 2)) / h
    if slope == 0.0 or math.isnan(slope):
        return None
    return (level - values(k - 1)) / slope - h


def _boundary_offset(before, after, k, i, records, mu_s, h, slip_velocity):
    """Offset from t_k of the switch before → after of contact i at step k (None: t_k).

    Extrapolated from the last two steps spent in `before` (a one-step blip merged into a phase,
    e.g. the stick step of a slip reversal, is skipped). `records` gives each step's impulses
    and state by global step index (moreau_jean_records.Collector)."""
    code = STATE_CODES[before]

    def in_before(j):  # steps j − 1 and j − 2 both in `before`
        return records.state(j - 1, i) == code == records.state(j - 2, i)

    j = k  # one past the last step in `before` whose predecessor is in `before` too
    while j >= 2 and j > k - 3 and not in_before(j):
        j -= 1
    if j < 2 or not in_before(j):
        return None
    shift = (j - k) * h
    if after == "open":  # the normal impulse fades to zero
        offset = _crossing(lambda m: records.p_normal(m, i), 0.0, j, h)
    elif before == "stick":  # the friction ratio reaches μs
        offset = _crossing(lambda m: abs(records.p_tangent(m, i)) / max(records.p_normal(m, i), 1e-300), mu_s, j, h)
    else:  # slip → stick or reversal: the slip velocity at the steps' ends reaches zero
        s1, s2 = slip_velocity(j - 1), slip_velocity(j)
        slope = (s2 - s1) / h
        # (it may already have crossed at t_j: the law judged H_T(q_j) v_{j+1}, not H_T(q_{j+1}))
        offset = -s2 / slope if slope * s2 < 0.0 or s1 * s2 < 0.0 else None
    return None if offset is None else offset + shift


def _contact_phases(runs, grid, k_end, t_final, min_phase):
    """The phases of one contact's runs of one state (first step, code) up to step k_end."""
    runs = [(k, c) for k, c in runs if k < k_end]
    if len(runs) == 1:  # one state all along (most contacts of a short run): one phase
        return [Phase(STATE_NAMES[runs[0][1]], grid.origin + float(runs[0][0]) * grid.h, t_final)]
    starts = np.array([k for k, _ in runs], dtype=np.int64)
    bounds = np.r_[grid.origin + starts.astype(float) * grid.h, t_final]
    return phases_from_intervals(bounds, [STATE_NAMES[c] for _, c in runs], min_phase)


def located_phases(scene, records, packed, impacts, grid, k_end, min_phase, t_stop, predicted=None):
    """Per-contact phases with each boundary placed inside its step (interpolating the slip
    velocity, the friction ratio or the normal impulse between steps; an impact's boundary at the
    impact time; a break-away the smooth phase decided at its predicted time, `predicted`:
    (contact, step) → t, stick_decisions), and one event per boundary; from the run's start
    t_first on."""
    predicted = predicted or {}
    phases, events = {}, []
    if k_end <= grid.first:
        return phases, events
    h, t_first = grid.h, float(grid.time(grid.first))
    t_final = float(grid.time(k_end)) if t_stop is None else max(float(t_stop), float(grid.time(k_end - 1)))
    impact_time = {(imp.contact, int(round((imp.t - grid.origin) / h))): imp.t for imp in impacts}
    for i, contact in enumerate(scene.contacts):
        found = _contact_phases(records.runs[i], grid, k_end, t_final, min_phase)
        for before, after in zip(found, found[1:]):
            k = int(round((after.t_start - grid.origin) / h))
            t_k = grid.origin + k * h
            by_prediction = before.mode == "stick" and after.mode in SLIP_MODES and (i, k) in predicted
            if before.mode == "open":
                t_switch = min((t for (c, step), t in impact_time.items() if c == contact.name and abs(step - k) <= 1),
                               key=lambda t: abs(t - t_k), default=t_k)
                kind = "impact"
            elif by_prediction:
                t_switch, kind = predicted[(i, k)], "stick-slip"
            else:
                def slip_velocity(j, contact=contact):  # with the Jacobian at q_j itself
                    qv = records.qv(j)
                    if qv is None:
                        return math.nan
                    kin = contact.kinematics(qv[0], qv[1], scene.n_dof, float(grid.time(j)))
                    return float(kin.H_T @ qv[1]) - kin.surface_velocity

                offset = _boundary_offset(before.mode, after.mode, k, i, records, packed.contacts[i, C_MU_S], h,
                                          slip_velocity)
                t_switch = t_k + (0.0 if offset is None else min(max(offset, -2 * h), h))
                kind = _BOUNDARY_KIND.get(after.mode, "stick-slip")
            t_switch = min(max(t_switch, before.t_start), after.t_end)
            before.t_end = after.t_start = float(t_switch)
            if kind != "impact" and t_switch >= t_first:
                events.append(Event(float(t_switch), kind, contact.name,
                                    {"from": before.mode, "to": after.mode, "step": k,
                                     "located": "predicted" if by_prediction else "interpolated"}))
        phases[contact.name] = _from(found, t_first)
    return phases, events


def _from(phases, t_first):
    """The phases from t_first on (a resumed run's history starts a few steps before it)."""
    kept = [p for p in phases if p.t_end > t_first or p is phases[-1]]
    if kept:
        kept[0].t_start = max(kept[0].t_start, t_first)
    return kept
