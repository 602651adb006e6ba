"""What a simulation returns: trajectory samples, contact phases, events, impacts, status.

Shaped after scipy's OdeResult: one object with named fields, a `status` word and a
human `message`, whatever integrator produced it.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

import numpy as np


class ContactState(str, Enum):
    """What one contact does over a step or phase. A str-Enum: compares equal to its word."""

    OPEN = "open"
    STICK = "stick"
    SLIP_POS = "slip+"  # slip velocity > 0 along the contact tangent
    SLIP_NEG = "slip-"

    def __str__(self) -> str:
        return self.value

    def __repr__(self) -> str:  # prints like the word it stands for, e.g. in f"{status!r}"
        return repr(self.value)

    @property
    def code(self) -> int:
        """The small integer compiled code stores (0 open, 1 stick, 2 slip+, 3 slip−)."""
        return CONTACT_STATES.index(self.value)


class Status(str, Enum):
    """How a run ended. A str-Enum: `result.status == "ok"` keeps working."""

    OK = "ok"  # reached t_end
    STOPPED = "stopped"  # a stop condition ended the run
    NO_IMPACT = "no-impact"  # the awaited impact did not happen in time
    PAINLEVE = "painleve"  # the sliding problem has no or several solutions
    ZENO = "zeno"  # accumulation of impacts
    LIFTOFF = "liftoff"
    TOO_MANY_EVENTS = "too-many-events"
    TOO_MANY_STEPS = "too-many-steps"
    TIME_LIMIT = "time-limit"
    STEP_SIZE_COLLAPSE = "step-size-collapse"  # an adaptive ODE solver's step fell to round-off
    PENETRATION = "penetration"  # a penalty contact sank deeper than its model allows
    NON_FINITE = "nan"  # the state became NaN or infinite inside an ODE solver
    FAILED = "failed"  # a one-step solver failed or the state became non-finite

    def __str__(self) -> str:
        return self.value

    def __repr__(self) -> str:  # prints like the word it stands for, e.g. in f"{status!r}"
        return repr(self.value)

    @property
    def success(self) -> bool:
        return self in (Status.OK, Status.STOPPED)


# The contact-state words in code order; the rod's tables say "flight" for "open".
CONTACT_STATES = tuple(s.value for s in ContactState)
MODES = ("stick", "slip+", "slip-", "flight")
SLIP_STATES = (ContactState.SLIP_POS.value, ContactState.SLIP_NEG.value)


@dataclass
class Phase:
    """A maximal time interval in which one contact keeps one mode."""

    mode: str
    t_start: float
    t_end: float

    def __post_init__(self):
        self.mode = str(self.mode)
        self.t_start = float(self.t_start)
        self.t_end = float(self.t_end)

    @property
    def duration(self) -> float:
        return self.t_end - self.t_start

    def as_dict(self) -> dict:
        return {"mode": self.mode, "t_start": self.t_start, "t_end": self.t_end}


@dataclass
class Event:
    """A located switching event: what happened, when, at which contact."""

    t: float
    kind: str
    contact: str = ""
    detail: dict = field(default_factory=dict)

    def __post_init__(self):
        self.t = float(self.t)


@dataclass
class Impact:
    """An impact: generalised velocities just before and after, and the impulses (N·s)."""

    t: float
    contact: str
    q: np.ndarray
    v_before: np.ndarray
    v_after: np.ndarray
    normal_impulse: np.ndarray
    tangential_impulse: np.ndarray

    def __post_init__(self):
        self.t = float(self.t)


@dataclass
class Trajectory:
    """Samples of the scene's state; forces are per contact (N and T in newtons).

    For time-stepping, forces are the step's impulses divided by h, and `modes` the contact
    states found by the step ending at `t`.
    """

    t: np.ndarray
    q: np.ndarray  # (n, n_dof)
    v: np.ndarray  # (n, n_dof)
    a: np.ndarray  # (n, n_dof); NaN where undefined
    normal_force: np.ndarray  # (n, n_contacts)
    tangential_force: np.ndarray  # (n, n_contacts)
    modes: np.ndarray  # (n, n_contacts) of contact-state words


@dataclass(init=False)
class SimulationResult:
    """One run of any integrator, shaped after scipy's OdeResult.

    `status` (a `Status`) and `message` say how it ended; `t`, `q`, `v`, `normal_force`,
    `tangential_force` and `modes` are the saved samples (also in `trajectory`); `phases` maps
    each contact name to its maximal constant-state intervals; `impacts` and `events` are
    located in time; `stats` counts the work (steps, solves, whether the loop was compiled).
    `end_state` is what the run's next step would read (Moreau–Jean: contact memory, warm starts,
    the step grid; None for methods that restart from (q, v) alone) and `setup` what the run was
    made with (`nr.simulate` sets it): `restart` goes on from them.
    """

    method: str
    status: Status
    message: str
    trajectory: Trajectory
    contact_names: list[str]
    events: list[Event] = field(default_factory=list)
    impacts: list[Impact] = field(default_factory=list)
    phases: dict[str, list[Phase]] = field(default_factory=dict)  # per contact name
    steps: int = 0
    cpu_time_s: float = 0.0
    stats: dict = field(default_factory=dict)
    end_state: object = None
    setup: object = None
    # {joint name: {reaction ("Fx", "Fy" of a pin; "F", "M" of a slider): samples}} (model/joints.py)
    joint_forces: dict = field(default_factory=dict)

    def __init__(self, method: str, status: Status, message: str, trajectory: Trajectory, contact_names: list[str],
                 events: list[Event] | None = None, impacts: list[Impact] | None = None,
                 phases: dict[str, list[Phase]] | None = None, steps: int = 0, cpu_time_s: float = 0.0,
                 stats: dict | None = None, end_state: object = None, setup: object = None,
                 joint_forces: dict | None = None):
        """The fields in their order (None: an empty list or dict). `events`, `phases` and
        `end_state` written straight into their descriptors' slots: the dataclass's own __init__
        sets them through the descriptors (~0.5 µs of a short run's call)."""
        self.method, self.status = method, status if type(status) is Status else Status(status)  # (an Enum's call: ~1 µs)
        self.message, self.trajectory, self.contact_names = message, trajectory, contact_names
        self.impacts, self.steps, self.cpu_time_s = [] if impacts is None else impacts, steps, cpu_time_s
        self.stats, self.setup = {} if stats is None else stats, setup
        self.joint_forces = {} if joint_forces is None else joint_forces
        fields = self.__dict__
        fields["_events"], fields["_phases"] = [] if events is None else events, {} if phases is None else phases
        fields["_end_state"] = end_state

    @property
    def success(self) -> bool:
        return self.status.success

    @property
    def t(self) -> np.ndarray:
        return self.trajectory.t

    @property
    def q(self) -> np.ndarray:
        return self.trajectory.q

    @property
    def v(self) -> np.ndarray:
        return self.trajectory.v

    @property
    def normal_force(self) -> np.ndarray:
        return self.trajectory.normal_force

    @property
    def tangential_force(self) -> np.ndarray:
        return self.trajectory.tangential_force

    @property
    def modes(self) -> np.ndarray:
        return self.trajectory.modes

    def set_status(self, status, message: str) -> None:
        self.status = Status(status)
        self.message = message

    def defer(self, locate) -> None:
        """Leave `phases` and `events` to `locate(result)`, which sets both, run when either is
        first read or set (a study that reads the final state alone never locates phases)."""
        self.__dict__["_locate"] = locate

    def _settle(self) -> None:
        locate = self.__dict__.pop("_locate", None)
        if locate is not None:
            locate(self)

    def build_end_state(self, build) -> None:
        """Leave `end_state` to `build()`, run when it is first read (or by `settle_end_state`):
        a short run's end state is copied from arrays its scene's plan lends to the next run,
        which settles it first only if this result is still alive (integrators/scene_plans.py)."""
        self.__dict__["_build_end_state"] = build

    def end_state_pending(self) -> bool:
        return "_build_end_state" in self.__dict__

    def settle_end_state(self) -> None:
        build = self.__dict__.pop("_build_end_state", None)
        if build is not None:
            self.__dict__["_end_state"] = build()

    def __getstate__(self):  # pickled (a sweep's worker) with its phases located, not the closures
        self._settle()
        self.settle_end_state()
        return self.__dict__


class _Deferred:
    """A SimulationResult field that `defer` may leave to be computed on first use."""

    def __set_name__(self, owner, name):
        self.slot = "_" + name

    def __get__(self, result, owner=None):
        if result is None:
            return self
        result._settle()
        return result.__dict__[self.slot]

    def __set__(self, result, value):
        result._settle()
        result.__dict__[self.slot] = value


class _BuiltOnRead:
    """SimulationResult.end_state: built on first read when `build_end_state` left it to a function."""

    def __get__(self, result, owner=None):
        if result is None:
            return self
        result.settle_end_state()
        fields = result.__dict__
        return fields["_end_state"] if "_end_state" in fields else fields.get("end_state")  # (an older pickle's)

    def __set__(self, result, value):
        result.__dict__.pop("_build_end_state", None)
        result.__dict__["_end_state"] = value


for _name in ("events", "phases"):  # after @dataclass: its __init__ assigns them through these
    _field = _Deferred()
    _field.__set_name__(SimulationResult, _name)
    setattr(SimulationResult, _name, _field)
SimulationResult.end_state = _BuiltOnRead()


def phases_from_intervals(t_bounds, modes, min_duration: float = 0.0) -> list[Phase]:
    """Contiguous phases from per-interval modes: modes[i] holds on [t_bounds[i], t_bounds[i+1]].

    Phases shorter than `min_duration` (one-step blips of time-stepping at a slip reversal)
    are merged into their neighbours: into the previous phase, or the next one at the start.
    """
    t_bounds = np.asarray(t_bounds, dtype=float)
    modes = np.asarray(list(modes), dtype=object)
    if len(modes) != len(t_bounds) - 1:
        raise ValueError("need one mode per interval: len(modes) == len(t_bounds) - 1")
    # Vectorised: a time-stepping run has one interval per step, a handful of phases.
    starts = np.concatenate([[0], np.nonzero(modes[1:] != modes[:-1])[0] + 1]) if len(modes) else []
    ends = list(starts[1:]) + [len(modes)]
    phases = [Phase(modes[a], float(t_bounds[a]), float(t_bounds[b])) for a, b in zip(starts, ends)]
    return merge_short_phases(phases, min_duration)


def merge_short_phases(phases: list[Phase], min_duration: float) -> list[Phase]:
    if min_duration <= 0 or len(phases) < 2:
        return _join_equal(phases)
    out: list[Phase] = []
    for ph in phases:
        if ph.duration < min_duration and out:
            out[-1] = Phase(out[-1].mode, out[-1].t_start, ph.t_end)
        else:
            out.append(Phase(ph.mode, ph.t_start, ph.t_end))
    if len(out) > 1 and out[0].duration < min_duration:
        out[1] = Phase(out[1].mode, out[0].t_start, out[1].t_end)
        out.pop(0)
    return _join_equal(out)


def _join_equal(phases: list[Phase]) -> list[Phase]:
    out: list[Phase] = []
    for ph in phases:
        if out and out[-1].mode == ph.mode:
            out[-1] = Phase(ph.mode, out[-1].t_start, ph.t_end)
        else:
            out.append(ph)
    return out
