"""Break-aways of fixed-step Moreau–Jean confirmed by the smooth phase's prediction, not decided by
a step's overshoot (issue 28). docs/friction.md ("Break-aways at fixed steps") has the why and the
measurements.

A Moreau–Jean step holds a loaded contact with its Jacobian at the step's start: its ratio p_T/p_N
overshoots the exact T/N by ~0.22 h s⁻¹ on the rod (0.065 h of it the error of the state itself,
benchmarks/bench_grazing.py), so near a grazing peak of T/N a sticking contact breaks away where
the exact law holds it (μs = max T/N + δ, δ ≤ 1e-4 at h = 1e-3), and below it breaks away early.
No decision on the step's own state removes the state's part. Here a break-away the step makes
(a loaded contact sticking in one step, sliding in the next) is confirmed by the smooth phase: the
contacts' modes from the step where they last changed (the start of the run of steps with these
modes) are integrated as the hybrid method does (`Hybrid.first_event`, from that step's state), and

* a predicted break-away of the contact within AGREE_STEPS steps of the step's: kept, its phase
  boundary placed at the predicted time;
* predicted later: the run goes back to the step before the one that slid, holds the contact (μs
  and μd raised for it, adaptive_breakaway.HOLD_FRACTION) until the step holding the predicted
  time, and releases it there (μs lowered to μd for RELEASE_STEPS steps); the phase boundary is
  the predicted time;
* predicted earlier (the step held it past the exact break-away: on the rod, at the end of its
  roll, where the step's state lags the exact one by ~2 ms): the run goes back to that step (at
  most to the start of the chunk of steps the loop ran: a step before it is not taken back; at
  least to the mode run's second step: a stick shorter than a step is one step of it) and
  releases the contact there;
* another event predicted first (a touchdown, a lift-off, another contact's switch), or none
  before t_end: held until the step holding it (to the end) if that is more than AGREE_STEPS after
  the step's break-away, then the step's law decides; kept as it was otherwise (the exact modes
  change first).

A run of modes is acted on once (a later break-away in it is the step's own). Only break-aways
the step makes are confirmed: a contact the step holds to the end of a run past a break-away the
exact law makes is left to the step (a prediction at every change of modes would cost one per
mode run). A stick the step makes at a slip reversal that the exact law does not hold stays (the
step stops the slip within the step with |T/N| ≤ μd: no release changes it); its end is placed at
the predicted time. The prediction is as good as the state it starts from: the rod's first stick
starts from its exact initial state; a stick that starts after a slide starts from the step's
state there, with its O(h) error. Scenes the hybrid method does not run (other contacts than disks
and points on fixed lines, joints, driven things), and modes its compiled mode solve declines
(a statically indeterminate stick: two disks of a block sticking on a belt), are left to the
step's law, as before. A run resumed from an earlier one starts its first run of modes at its
first step (the earlier run's holds are not carried over).
"""
from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numpy as np

from ..solvers.problem import STATE_SLIP_MINUS, STATE_SLIP_PLUS, STATE_STICK
from ..solvers.two_coefficient import STATE_NAMES

# (adaptive_breakaway and hybrid are imported by the scenes that use them: they import the
# event-driven reference, 0.2 s, which a run of any other scene does not need)

# A step's break-away within this many steps of the predicted one is the step's own: the prediction
# starts from the step's state, whose O(h) error moves a break-away where T/N crosses μs at a
# slope by a step or so; only a decision the step's overshoot turns (a grazing peak, a crossing
# at a small slope) is moved. (Not 0: every break-away would be taken back and run again.)
AGREE_STEPS = 2
# The hybrid method's contacts (hybrid.Hybrid.declares.contacts, a test checks): a scene with any
# other is left to the step's law without importing the hybrid method (0.2 s).
PREDICTED_CONTACTS = frozenset({"DiskOnLine"})
# A released contact's μs is lowered to μd for this many steps from the one holding the predicted
# break-away: the first may stick still (the step that lets a contact go closes the gap it crept
# open with a larger N, _confirm), the next slides.
RELEASE_STEPS = 2
SLIDING = (STATE_SLIP_PLUS, STATE_SLIP_MINUS)
NOT_PREDICTED = "not predicted"  # a mode run the compiled mode solve declines: the step's law decides
MAX_PREDICTORS = 2  # predicting Hybrids a scene's plan keeps (threads running the scene at once)


class _ModeRun(NamedTuple):  # (a tuple: made at every call's first review, a frozen dataclass costs a µs more)
    """The first step of a run of steps with unchanged contact modes: its state and modes."""

    k: int
    t: float
    q: np.ndarray
    v: np.ndarray
    codes: tuple  # each contact's state code (Python ints: read one at a time)


def stick_decisions(scene, model, grid, plan=None, engine=None):
    """The run's StickDecisions, or None where the hybrid method does not run the scene's contacts
    (its other refusals, joints and driven things, are checked at the first prediction, and kept
    in the scene's plan for its later runs: integrators/scene_plans.py)."""
    kinds = frozenset(type(c).__name__ for c in scene.contacts) if plan is None else plan.kinds
    if not kinds or not kinds <= PREDICTED_CONTACTS or (plan is not None and plan.predicted is False):
        return None
    return StickDecisions(scene, model.contacts, grid, plan, engine)


class StickDecisions:
    """The holds and releases a fixed-step run's chunks of steps run in, and the review of each
    chunk's break-aways that plans them."""

    __slots__ = ("scene", "table", "grid", "plan", "engine", "smooth", "handled", "_run_start", "_start_row",
                 "held", "released", "acted", "switches", "predictions", "_ahead")

    def __init__(self, scene, table, grid, plan=None, engine=None):
        self.scene, self.table, self.grid, self.plan = scene, table, grid, plan
        self.engine = engine  # the run's Engine (moreau_jean): its predictions run compiled when its steps do
        self.smooth = None  # adaptive_breakaway: at the first prediction
        self.handled = True  # until the first prediction finds a refusal of the hybrid method
        self._run_start: _ModeRun | None = None
        self._start_row = None  # (window, row) of the run of modes' first step, read on first need (run_start)
        self.held: dict[int, tuple[int, int]] = {}  # contact → (first step held, first step not held)
        self.released: dict[int, tuple[int, int]] = {}  # contact → (first step released, first not)
        self.acted: set[int] = set()  # the first steps of the mode runs acted on
        # (contact, step) → the predicted time of a confirmed break-away whose slide may start in
        # that step: its phase boundary (moreau_jean.located_phases), not one extrapolated from the
        # step's ratios (held, or overshooting)
        self.switches: dict[tuple[int, int], float] = {}
        self.predictions = 0
        self._ahead: dict = {}  # a mode run's first step → its prediction (each contact's break-away reads it)

    def chunk(self, window, k: int, n: int):
        """(steps, context or None, whether the review may take steps back) of the chunk from step
        k of at most n steps: cut so that a chunk starts at every planned hold's and release's first
        and last step; run in its held contacts' friction raised in the packed table and its
        released ones' μs lowered to μd (restored after; None: nothing held or released); the
        review compares the modes of consecutive rows from the one before the chunk's (a run's
        first chunk of one step has no two)."""
        context = None  # (a run without holds: every call's first chunk)
        if self.held or self.released:
            bounds = [b for plan in (self.held, self.released) for span in plan.values() for b in span]
            n = min([n] + [b - k for b in bounds if b > k])
            held, released = _during(self.held, k), _during(self.released, k)
            if held or released:
                context = self.smooth.Held(self.table, held, released)
        return n, context, self.handled and (n > 1 or k > window.k_base)

    def review(self, window, k: int, k_done: int) -> int | None:
        """The step the chunk's steps k … k_done − 1 are taken back to (its records and state from
        that step on are to be run again, under the plan this review made), or None: all kept."""
        r0, r1 = k - window.k_base, k_done - window.k_base
        lo = max(r0 - 1, 0)
        if self._run_start is None and self._start_row is None:
            self._start(window, lo)
        if not self.handled or r1 - lo < 2:
            return None  # (a call's one-step chunk: no two rows to compare)
        columns = window.out.states[lo:r1]  # the contacts' columns (contacts never near: no column, open)
        differ = np.flatnonzero(columns[1:] != columns[:-1])  # (flat: an any(axis=1) costs 5 µs a chunk)
        if not differ.size:
            return None  # (most chunks: no mode changes)
        width, out = columns.shape[1], window.out
        changed = sorted({lo + 1 + f // width for f in differ.tolist()})  # rows whose codes differ from the row before
        start = None
        for r in changed:  # (few: Python on their rows costs less than numpy's calls over them)
            broke = [c for c, (was, now, p) in enumerate(zip(out.states[r - 1].tolist(), out.states[r].tolist(),
                                                            out.p_normal[r - 1].tolist()))
                     if was == STATE_STICK and p > 0.0 and now in SLIDING]  # loaded, sticking, then sliding
            if broke:
                if start is not None:  # the mode run the break-away ends started at the change before it
                    self._start(window, start)
                for i in sorted(window.owners()[broke].tolist()):  # (each contact's column: Window.columns)
                    back = self._confirm(i, window.k_base + r, k)
                    if back is not None:
                        return back
            start = r
        self._start(window, start)
        return None

    def _start(self, window, r: int) -> None:
        """Row r of the window starts a run of modes: read from the window on first need, or
        before its rows move or are run again (`keep_start`; a review that reads it does)."""
        self._start_row, self._run_start = (window, r), None

    def keep_start(self) -> None:
        """Copy the run of modes' first step out of the window: its rows are about to move."""
        if self._start_row is not None:
            window, r = self._start_row
            k = window.k_base + r
            self._run_start = _ModeRun(k, float(self.grid.time(k)), window.out.q[r].copy(), window.out.v[r].copy(),
                                       tuple(window.full(5, r).tolist()))
            self._start_row = None

    @property
    def run_start(self) -> _ModeRun | None:
        self.keep_start()
        return self._run_start

    def _confirm(self, i: int, k_break: int, k_chunk: int) -> int | None:
        """The step to go back to for contact i's break-away, the first step it slides in being
        k_break (None: kept). (The step before may be the one the law let it go in: a loaded
        contact's gap creeps open while it sticks near a break-away, and the step that lets it
        go closes the gap with a larger N, which holds it one step more.)"""
        start = self.run_start
        if start.codes[i] != STATE_STICK or start.k in self.acted or self._planned(i, k_break) or not self._predicts():
            return None
        ahead = self._prediction(start)
        if ahead is NOT_PREDICTED:
            return None
        breaks = ahead is not None and ahead[1] in self.smooth.BREAKS and ahead[2] == i
        k_exact = self.grid.last if ahead is None else self._step_holding(ahead[0])
        k_exact = max(k_exact, start.k + 1)  # a stick shorter than a step: one step of it
        if abs(k_exact - k_break) <= AGREE_STEPS or (not breaks and k_exact < k_break):
            if breaks:  # the step's own, at the exact law's time
                self.switches[(i, k_break)] = ahead[0]
            return None
        k_back = max(k_chunk, min(k_break - 1, k_exact))
        if k_exact > k_back:
            self.held[i] = (k_back, k_exact)
        if not breaks:
            self.acted.add(start.k)
            return k_back
        self._release(i, start, max(k_exact, k_chunk), ahead[0] if k_exact >= k_chunk else None)
        return k_back

    def _release(self, i: int, start: _ModeRun, k: int, t_switch: float | None) -> None:
        """Release contact i for RELEASE_STEPS from step k (its boundary at t_switch, if given:
        the first step it slides in, k … k + RELEASE_STEPS), its run of modes acted on."""
        self.acted.add(start.k)
        self.released[i] = (k, k + RELEASE_STEPS)
        if t_switch is not None:
            self.switches.update({(i, j): t_switch for j in range(k, k + RELEASE_STEPS + 1)})

    def _planned(self, i: int, k: int) -> bool:
        return bool(self.held or self.released) and (i in _during(self.held, k) or i in _during(self.released, k))

    def _predicts(self) -> bool:
        """Whether the hybrid method runs the scene (set up at the first call: 0.2 s of imports)."""
        if self.smooth is None and self.handled:
            adaptive_breakaway, handles = _smooth_phase()
            self.handled = handles(self.scene) if self.plan is None or self.plan.predicted is None else True
            if self.plan is not None:
                self.plan.predicted = self.handled
            self.smooth = adaptive_breakaway
        return self.handled

    def _prediction(self, start: _ModeRun):
        """The first event of the run's modes from its first step's state (consistent with them):
        (t, kind, contact), None (none before t_end), or NOT_PREDICTED where the compiled mode
        solve declines the modes (interpreted, a prediction of a long stick would cost more than
        the run: the belt oscillator's statically indeterminate block, 0.3 s a prediction)."""
        if start.k not in self._ahead:
            modes = [STATE_NAMES[int(c)] for c in start.codes]
            hybrid = self._predictor()
            # steps run interpreted (a cold cache: the engine compiles in the background, or
            # fast=False): so does the prediction, which then compiles nothing (the same source)
            hybrid.compiled = self.engine is None or self.engine.compiled
            self._ahead[start.k] = NOT_PREDICTED
            try:  # (a stick singular at every state, the pushed block's: declined before the projection)
                v = self.smooth.consistent_velocity(self.scene, start.q, start.v, modes) \
                    if hybrid.may_solve_compiled(self.scene, modes) else None
                if v is not None and hybrid.solves_compiled(self.scene, start.t, start.q, v, modes):
                    self.predictions += 1
                    self._ahead[start.k] = hybrid.first_event(self.scene, start.t, start.q, v, modes, self.grid.t_end)
            finally:
                # (not one holding many mode solves: a frictionless contact's margin, part of their
                # key, changes from state to state)
                if self.plan is not None and len(self.plan.predictors) < MAX_PREDICTORS and len(hybrid._systems) <= 64:
                    self.plan.predictors.append(hybrid)
        return self._ahead[start.k]

    def _predictor(self):
        """A predicting Hybrid: one an earlier prediction of the scene gave back to its plan (its
        compiled mode solves set up: a third of a prediction), or a new one. (list.pop: two
        threads running the scene never share one.)"""
        try:
            return self.plan.predictors.pop()
        except (AttributeError, IndexError):  # no plan, or none given back
            from .hybrid import Hybrid
            return Hybrid(_prediction_options())

    def _step_holding(self, t: float) -> int:
        """The step whose interval [t_k, t_k+1) holds t (at most the grid's last)."""
        return min(int(math.floor((t - self.grid.origin) / self.grid.h)), self.grid.last)


@functools.cache
def _smooth_phase():
    """(adaptive_breakaway, hybrid.handles), imported at a run's first prediction (once: an import
    statement costs a µs a run)."""
    from . import adaptive_breakaway
    from .hybrid import handles
    return adaptive_breakaway, handles


@functools.cache
def _prediction_options():
    """The predicting Hybrid's options (made once: checking them costs more than a prediction)."""
    from . import adaptive_breakaway
    from .hybrid import HybridOptions
    return HybridOptions(h=adaptive_breakaway.PREDICTION_STEP)


def _during(plan: dict, k: int) -> tuple:
    """The contacts whose span [first, end) of the plan holds step k."""
    return tuple(i for i, (first, end) in plan.items() if first <= k < end)
