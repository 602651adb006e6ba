"""Event-driven stepping at a fixed step ("hybrid"): each smooth phase integrated with explicit
Runge–Kutta steps of h (order 2, 3 or 4) on the mode-fixed ODE, events located on the steps'
dense output. docs/error_control.md ("A higher order between events") has the why and the
measurements.

Between events the contact modes (open, stick, slip±) are fixed and the scene is the smooth
constrained ODE of model/dynamics.mode_dynamics: its error is C h^order, whatever the contact
forces (Moreau–Jean, whose step holds the contacts with their Jacobian at the step's start, is
first order there). Everything at an event is the event-driven reference's
(integrators/event_driven.py, whose class this one extends): the switching indicators, the
choice of the modes after a switch (stick first), the impact law at impulse level at the
located instant, rest. Only the watch differs: the reference interpolates every indicator on 13
Chebyshev points of each step; here each step gives three samples for free — its start, its
end and its midpoint stage (the state y + h/2 k of the stage at t + h/2, the forces the stage
solved for anyway) — and only a sign change, or a dip between them (a parabola through the
three with an interior minimum at most half the smaller end value: a grazing peak of T/N inside
the step), is looked at closely on the step's cubic Hermite interpolant (brentq, or a bounded
minimisation then brentq). Events are located to the interpolant's accuracy, O(h⁴). A prediction
(`first_event`) runs its steps and the watch's tests on them in one compiled call up to the first
step the watch must look at closely (watch_screen.py): the same event, from the same numbers.

Every mode solve — the stages, the watch's values, the reference's mode decisions, rest test and
samples (`_dynamics`) — runs through model/dynamics.ModeSystem, mode_dynamics' equations set up
once per mode and compiled with the indicators' values, a whole step's stages and end in one
compiled call (`ModeSystem.runge_kutta`) where the forces are constant; mode_dynamics itself
where it declines (a statically indeterminate A).
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ..model.dynamics import ModeDynamics, ModeSystem, hermite_into, mode_dynamics
from ..solvers import available_solvers
from ..solvers._common import interpreted
from ..validation import Choice, Integer, Number, Text, check_options, option
from .declaration import NO_DRIVEN, NO_JOINTS, Declaration
from .sampling import thinned_count
from .watch_screen import screened_steps_into
from .watch_tests import looked_at, start_band
from .event_driven import (_EPS, _TINY, EventDriven, _first_of, _force_scale, _indicator_values, _indicators,
                           _Watch)

# Explicit Runge–Kutta tableaux (c, a, b) and the stage at c = 1/2 sampled for the watch:
# the explicit midpoint rule, Kutta's third-order rule, the classical fourth-order rule.
TABLEAUX = {
    2: ((0.0, 0.5), ((), (0.5,)), (0.0, 1.0), 1),
    3: ((0.0, 0.5, 1.0), ((), (0.5,), (-1.0, 2.0)), (1 / 6, 2 / 3, 1 / 6), 1),
    4: ((0.0, 0.5, 0.5, 1.0), ((), (0.5,), (0.0, 0.5), (0.0, 0.0, 1.0)), (1 / 6, 1 / 3, 1 / 3, 1 / 6), 2),
}
# The tableaux's a (lower triangular, square) and b as arrays, for the compiled step.
TABLEAU_ARRAYS = {order: (np.array([[row[j] if j < len(row) else 0.0 for j in range(len(c))] for row in a]),
                          np.array(b, dtype=float))
                  for order, (c, a, b, _) in TABLEAUX.items()}
# A dip of an indicator between a step's samples is looked at closely when the parabola through
# them has an interior minimum below this fraction of the smaller end value.
DIP_FRACTION = 0.5
# A segment's first step is at most GROWTH times the segment before it, each next one GROWTH
# times the one before (up to h): steps follow the time scale of accumulating events.
GROWTH = 2.0
# A prediction's steps (Hybrid.first_event) are laid out this many at a time for the compiled
# watch (watch_screen), which stops at the first step it flags: the rod's stick (~0.1 s at 1e-2) in one.
BLOCK = 16
# Halvings of a step's first interval looking for the side an indicator starting at zero leaves to.
MAX_HALVINGS = 60


@dataclass
class HybridOptions:
    """Step, order and the event-driven reference's event controls."""

    h: float = option(1e-2, Number(0.0, 1.0, open_lo=True), label="h (step size)")
    order: int = option(4, Integer(2, 4))
    stop_at_impact: str | None = option(None, Text())  # name of a contact whose first impact ends the run
    max_events: int = option(10_000, Integer(1, 10**9))
    zeno_interval: float = option(1e-9, Number(0.0, 1e-3))  # impacts closer than this: accumulation (s)
    impact_solver: str = option("enum", Choice(available_solvers))
    gap_tol: float = option(1e-9, Number(0.0, 1e-3, open_lo=True))  # m
    velocity_tol: float = option(1e-9, Number(0.0, 1e-3, open_lo=True))  # m/s
    # flights lower than this (m) are not resolved: the reference's rule (integrators/accumulation.py)
    resolution: float = option(0.0, Number(0.0, 1.0))

    def __post_init__(self):
        check_options(self)

    @property
    def output_dt(self) -> float:
        """The samples a run at rest keeps (the reference's `_hold_rest` reads it): one a step."""
        return self.h


# The indicators of event_driven._indicators as the compiled mode solve watches them
# (model/dynamics.WATCH_CODES); a mode with another (a vertex's region) is solved by mode_dynamics.
WATCHED_AS = {"touchdown": "gap", "slip-zero": "slip", "liftoff": "normal", "break-upper": "upper",
              "break-lower": "lower", "painleve": "det"}


class _Mode:
    """One segment's mode: the derivative of the state and the indicators' values at any state,
    from the compiled mode solve (model/dynamics.ModeSystem), or from mode_dynamics and
    event_driven._indicator_values where it declines."""

    def __init__(self, scene, modes, indicators, system_of):
        self.scene, self.modes, self.indicators = scene, list(modes), indicators
        watched = tuple((WATCHED_AS.get(ind.kind), ind.contact, ind.offset) for ind in indicators)
        self.system = system_of(scene, modes, watched) if all(w[0] for w in watched) else None

    def evaluate(self, t: float, y: np.ndarray):
        """(ẏ, the indicators' values, what the trajectory's sample reads) at (t, y)."""
        out = self.system.evaluate(t, y) if self.system is not None else None
        if out is not None:
            return out[self.system.rates], out[self.system.values], out
        n = self.scene.n_dof
        kin = self.scene.kinematics(y[:n], y[n:])
        dyn = mode_dynamics(self.scene, t, y[:n], y[n:], self.modes, kin)
        values = _indicator_values(self.scene, self.modes, self.indicators, t, y, kin, dyn)
        return np.concatenate([y[n:], dyn.a]), values, dyn

    def dynamics(self, solved) -> ModeDynamics:
        """The accelerations and forces of an evaluation, for the trajectory's samples."""
        return solved if isinstance(solved, ModeDynamics) else self.system.dynamics(solved)


class _Stage:
    """The mode's dynamics at one state: its derivative, what the indicators read there."""

    def __init__(self, mode: _Mode, t, y, out=None):
        self.t, self.y, self.mode = t, y, mode
        if out is None:
            self.f, self.values, self._solved = mode.evaluate(t, y)
        else:  # the compiled mode solve's evaluation at (t, y), made already (ModeSystem.runge_kutta)
            self.f, self.values, self._solved = out[mode.system.rates], out[mode.system.values], out

    def dynamics(self) -> ModeDynamics:
        return self.mode.dynamics(self._solved)


@functools.cache
def _mode_system_twins():
    """ModeSystem's compiled mode solve and step as plain-Python twins (made once)."""
    from ..model import dynamics

    return interpreted(dynamics.mode_rates_into), interpreted(dynamics.runge_kutta_into)


def _hermite(a: _Stage, b: _Stage, interpolate_into=hermite_into):
    """The step's cubic Hermite interpolant of (q, v) from both ends' (q, v) and (v, a)."""
    h = b.t - a.t

    def dense(t: float) -> np.ndarray:
        s = (t - a.t) / h
        out = np.empty_like(a.y)
        interpolate_into(((1 + 2 * s) * (1 - s) ** 2, s * s * (3 - 2 * s), s * (1 - s) ** 2, s * s * (s - 1)), h,
                         a.y, b.y, a.f, b.f, out)
        return out
    return dense


class _StepWatch(_Watch):
    """The reference's watch (noise bands, near-miss refinement, first fall) fed with a step's
    three samples instead of 13 Chebyshev points."""

    def __init__(self, mode: _Mode, start: _Stage):
        super().__init__(mode.scene, mode.modes, mode.indicators, start.t, start.y, start=start.values)
        self.mode = mode

    def values(self, stage: _Stage) -> np.ndarray:
        self.evaluations += 1
        return self.sign * stage.values

    def safe_values(self, t, dense) -> np.ndarray:
        self.evaluations += 1
        return self.sign * self.mode.evaluate(t, dense(t))[1]

    def first_event_sampled(self, dense, ts, s):
        """(t, j): the first crossing in [ts[0], ts[-1]] given the safe values s (3 × indicators)."""
        found = []
        for j, column in enumerate(s.T.tolist()):  # Python floats: the three samples' tests are scalar
            start_band(ts, column, self.t0, self.noise[j], self.band_exit, j)
            looked, dip, t_vertex = looked_at(ts[0], ts[1], ts[2], column[0], column[1], column[2], DIP_FRACTION)
            if not looked:
                continue
            # Looked at closely on the interpolant: the middle sample (a stage's state, not the
            # interpolant's) is taken again from it, so that the brackets are the root finder's.
            column[1] = self.safe_values(ts[1], dense)[j]
            nodes_t, nodes_s = list(ts), list(column)
            if dip and min(column) > 0.0:
                k = 1 if t_vertex <= ts[1] else 2
                nodes_t.insert(k, t_vertex)
                nodes_s.insert(k, self.safe_values(t_vertex, dense)[j])
            self._start_band(j, nodes_t, nodes_s)
            self._refine_near_misses(j, nodes_t, nodes_s, dense, math.inf)
            self._leave_start_band(j, nodes_t, nodes_s, dense)
            t_cross = self._first_fall(j, nodes_t, nodes_s, dense)
            if t_cross is not None:
                found.append((t_cross, j))
        return _first_of(found, self.indicators)

    def _leave_start_band(self, j, nodes_t, nodes_s, dense):
        """An indicator starting at zero (a corner lifting off at an impact) may leave to the safe
        side and come back within the first interval of a long step: halve that interval until a
        node shows it safe, so that its return is located, not the start taken for it."""
        for _ in range(MAX_HALVINGS):
            if not (nodes_s[0] == _TINY and nodes_s[1] <= 0.0):
                return
            t_half = 0.5 * (nodes_t[0] + nodes_t[1])
            if t_half - nodes_t[0] <= 1e3 * _EPS * max(1.0, abs(t_half)):
                return
            nodes_t.insert(1, t_half)
            nodes_s.insert(1, self.safe_values(t_half, dense)[j])
            self._start_band(j, nodes_t, nodes_s)


def _combine(y, h, weights, stages) -> np.ndarray:
    """y + h Σ w_j f_j over the stages with a nonzero weight (a tableau's row), summed in order."""
    total = None
    for w, stage in zip(weights, stages):
        if w:
            total = w * stage.f if total is None else total + w * stage.f
    return y + h * total


def _first_step_cap(boundaries: list) -> float:
    """The first step of a segment: at most GROWTH times the segment before (steps then grow by
    GROWTH each up to h). Impacts accumulating (a rocking block's, a bouncing ball's) come ever
    closer; steps of h would locate them to the interpolant's absolute error (~1e-9 m at
    h = 1e-2), far above their amplitudes, and the chain would end in a false Zeno."""
    return GROWTH * (boundaries[-1] - boundaries[-2]) if len(boundaries) > 1 else math.inf


@dataclass
class _Counts:
    """What a run counts of a prediction's steps (first_event), not kept."""

    steps: int = 0
    nfev: int = 0


def handles(scene) -> bool:
    """Whether the hybrid method runs this scene: its contacts and no refusal of its declaration."""
    declared = Hybrid.declares
    return (all(type(c).__name__ in declared.contacts for c in scene.contacts)
            and all(r.finds(scene) is None for r in declared.refusals))


class Hybrid(EventDriven):
    """Fixed explicit Runge–Kutta steps in each smooth mode, the reference's events between them
    (disks and points on lines)."""

    name = "hybrid"

    SAMPLES_KNOB = "a larger h, save_every or a shorter t_end"

    @staticmethod
    def samples_estimate(options, duration: float, save_every: float | None) -> float:
        """One sample a step and one per event, or one per save_every (thinned as it runs)."""
        return thinned_count(duration / options.h + options.max_events, duration, save_every) + 2

    def __init__(self, options: HybridOptions | None = None):
        self.options = options or HybridOptions()
        # False: the mode solves, steps, screen and interpolation run as their plain-Python twins
        # (a fixed-step run's prediction while its engine runs interpreted and compiles in the
        # background: stick_decisions; a cold cache then compiles nothing here)
        self.compiled = True
        self._systems = {}

    def run(self, scene, q0, v0, t_end, **clock):
        self._systems = {}  # the compiled mode solves set up in this run, by modes and what they watch
        return super().run(scene, q0, v0, t_end, **clock)  # clock: t0, resume, save_every, stop

    def _system(self, scene, modes, watched=()) -> ModeSystem:
        key = (tuple(modes), watched)
        if key not in self._systems:  # the scene's packed contacts shared by its systems in this run
            like = next(iter(self._systems.values()), None)
            self._systems[key] = ModeSystem(scene, modes, watched, like)
        system = self._systems[key]
        system.twins = None if self.compiled else _mode_system_twins()
        return system

    def _kernel(self, kernel):
        """A compiled kernel, or its plain-Python twin while `compiled` is False."""
        return kernel if self.compiled else interpreted(kernel)

    def _dynamics(self, scene, t, q, v, modes, kin=None):
        """The reference's mode decisions, rest and samples by the compiled mode solve, or
        mode_dynamics where it declines."""
        system = self._system(scene, modes)
        out = system.evaluate(t, np.concatenate([q, v]))
        return mode_dynamics(scene, t, q, v, modes, kin) if out is None else system.dynamics(out)

    def _segment(self, scene, run, modes, t_end):
        """Steps of h in `modes` from the run's state to the first event or t_end. Returns the
        event's (kind, contact), or None at t_end; leaves the run at the stop."""
        indicators = _indicators(scene, modes, 1e-9 * _force_scale(scene, run.t, run.q, run.v))
        mode = _Mode(scene, modes, indicators, self._system)
        start = _Stage(mode, run.t, np.concatenate([run.q, run.v]))
        watch = _StepWatch(mode, start)
        if not run.samples and run.unkept is None:  # the run's first state (later segments start at a sample)
            run.sample(start.t, start.y, modes, start.dynamics())
        try:
            hit, dense, end = self._watched_steps(mode, start, watch, t_end, _first_step_cap(run.boundaries), run,
                                                  lambda stage: run.sample(stage.t, stage.y, modes, stage.dynamics()))
        finally:
            run.indicator_evaluations += watch.evaluations
        if hit is None:
            run.close(float(end.t), end.y, modes, end.dynamics())
            return None
        run.close(float(hit[0]), dense(hit[0]), modes)
        return indicators[hit[1]].kind, indicators[hit[1]].contact

    def _watched_steps(self, mode: _Mode, start: _Stage, watch: _StepWatch, t_end: float, cap: float, counts,
                       on_step):
        """Steps of h (the first at most `cap`, then growing by GROWTH) from `start` until the
        watch's first event or t_end: (the event (t, indicator index) or None, the last step's
        interpolant, its end stage). on_step(end) is called at every other step's end; counts
        (a run) counts the steps and the mode solves."""
        s_start, h = watch.values(start), self.options.h
        while True:
            step = min(h, cap, t_end - start.t)
            if t_end - start.t < 1.01 * step:
                step = t_end - start.t  # no sliver of a last step
            cap *= GROWTH
            middle, end = self._step(mode, start, step, counts)
            counts.steps += 1
            dense = _hermite(start, end, self._kernel(hermite_into))
            ts = (start.t, middle.t, end.t)
            hit = watch.first_event_sampled(dense, ts, np.array([s_start, watch.values(middle),
                                                                 s_end := watch.values(end)]))
            if hit is not None or end.t >= t_end:
                return hit, dense, end
            on_step(end)
            start, s_start = end, s_end

    def first_event(self, scene, t: float, q, v, modes, t_end: float):
        """The first event of the smooth phase in `modes` from (t, q, v) before t_end, as this
        method finds it (its steps, its watch, the reference's indicators): (t_event, kind,
        contact), or None. Error-controlled Moreau–Jean decides break-aways by it
        (integrators/adaptive_breakaway.py)."""
        indicators = _indicators(scene, modes, 1e-9 * _force_scale(scene, t, q, v))
        mode = _Mode(scene, modes, indicators, self._system)
        start = _Stage(mode, t, np.concatenate([q, v]))
        hit = self._screened_steps(mode, start, _StepWatch(mode, start), t_end)
        return None if hit is None else (float(hit[0]), indicators[hit[1]].kind, indicators[hit[1]].contact)

    def _screened_steps(self, mode: _Mode, start: _Stage, watch: _StepWatch, t_end: float):
        """_watched_steps' event (t, indicator index) or None from `start` (no first-step cap), its
        steps and the watch's tests in one compiled call up to the first step the tests flag
        (watch_screen), which the watch itself looks at, with its bands as they were there: the
        same event from the same numbers. Step by step (_watched_steps) from a step the compiled
        mode solve declines, or where the mode has no compiled solve."""
        system, (c, a, b, mid) = mode.system, TABLEAUX[self.options.order]
        a_array, b_array = TABLEAU_ARRAYS[self.options.order]
        s_start = watch.values(start)
        while system is not None and system.usable and system.constant:
            tb, steps = self._step_times(start.t, t_end, BLOCK)
            if not steps:  # (a start at t_end: the step's own way)
                break
            states, outs = np.empty((len(steps), len(c) + 1, start.y.shape[0])), np.empty((len(steps), len(c) + 1,
                                                                                            system.out.shape[0]))
            screen = self._kernel(screened_steps_into)
            m = screen(system.table, system.ints, system.watched, system.offsets, system.minv, system.free, start.y,
                       np.array(steps), np.array(tb), a_array, b_array, mid, float(c[mid]), float(watch.t0), watch.sign,
                       watch.noise, watch.band_exit, s_start, DIP_FRACTION, states, outs)
            done = len(steps) if m == len(steps) else m if m >= 0 else -1 - m  # steps passed
            if done:
                start = _Stage(mode, tb[done], states[done - 1, -1], outs[done - 1, -1])
                s_start = watch.sign * start.values
            if m == len(steps) and start.t >= t_end:
                return None
            if m < 0:
                break
            if m < len(steps):
                end = _Stage(mode, tb[m + 1], states[m, -1], outs[m, -1])
                s_end = watch.sign * end.values
                watch.evaluations += 2
                dense = _hermite(start, end, self._kernel(hermite_into))
                hit = watch.first_event_sampled(dense, (tb[m], tb[m] + c[mid] * steps[m], tb[m + 1]),
                                                np.array([s_start, watch.sign * outs[m, mid, system.values], s_end]))
                if hit is not None or end.t >= t_end:
                    return hit
                start, s_start = end, s_end
        hit, _, _ = self._watched_steps(mode, start, watch, t_end, math.inf, _Counts(), lambda stage: None)
        return hit

    def _step_times(self, t: float, t_end: float, n: int):
        """Up to n steps' boundaries from t (t first) and lengths, as _watched_steps takes them
        (no first-step cap): to t_end at most, no sliver of a last step."""
        tb, steps, h = [t], [], self.options.h
        while len(steps) < n and tb[-1] < t_end:
            step = min(h, t_end - tb[-1])
            if t_end - tb[-1] < 1.01 * step:
                step = t_end - tb[-1]
            steps.append(step)
            tb.append(tb[-1] + step)
        return tb, steps

    def may_solve_compiled(self, scene, modes) -> bool:
        """Whether the compiled mode solve solves `modes` at some state (solves_compiled before a
        state is known: its contacts, no body held by more rows than its freedoms)."""
        return self._system(scene, modes).usable

    def solves_compiled(self, scene, t: float, q, v, modes) -> bool:
        """Whether `modes` at (t, q, v) are solved by the compiled mode solve (not mode_dynamics,
        ~10 times slower a step: a statically indeterminate stick, a singular A)."""
        system = self._system(scene, modes)
        return system.usable and system.evaluate(t, np.concatenate([q, v])) is not None

    def _step(self, mode: _Mode, start: _Stage, h: float, run):
        """One Runge–Kutta step of h from `start`: (its midpoint stage, its end)."""
        c, a, b, mid = TABLEAUX[self.options.order]
        run.nfev += len(c)
        stepped = mode.system.runge_kutta(start.y, h, *TABLEAU_ARRAYS[self.options.order]) if mode.system else None
        if stepped is not None:  # the whole step in one compiled call: the same sums, the same solves
            states, outs = stepped
            return (_Stage(mode, start.t + c[mid] * h, states[mid], outs[mid]),
                    _Stage(mode, start.t + h, states[-1], outs[-1]))
        stages = [start]
        for i in range(1, len(c)):
            stages.append(_Stage(mode, start.t + c[i] * h, _combine(start.y, h, a[i], stages)))
        end = _Stage(mode, start.t + h, _combine(start.y, h, b, stages))
        return stages[mid], end


Hybrid.declares = Declaration(
    options=HybridOptions, contacts=("DiskOnLine",), samples_estimate=Hybrid.samples_estimate,
    samples_knob=Hybrid.SAMPLES_KNOB, refusals=(NO_JOINTS, NO_DRIVEN))
