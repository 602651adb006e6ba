"""Prescribed motions: driven obstacles (lines, segments) and driven bodies.

A motion is a displacement d(t) = (dx, dy, dθ) from the thing's initial placement, and its
velocity ḋ(t):

    Harmonic(amplitude, frequency_hz, phase)   d = amplitude · sin(2π f t + φ)
    Tabulated(times, positions, interpolation)  d through the rows: "linear" (ḋ the row's slope) or
                                                "spline" (a not-a-knot cubic spline, ḋ its derivative);
                                                held at the first/last row (ḋ = 0) outside the times
    Prescribed(function)                        function(t) -> (d, ḋ), Python (the step-wise loop)

A line or segment takes a translation (two components: it does not turn); a body takes two or
three (x, y, θ). The compiled Moreau–Jean loop evaluates the harmonic and tabulated motions with
`motion_kernel` from a packed table (like model/forces.py's tables); the Python classes' `at`
reads the same kernel, so the two cannot disagree. A table of either interpolation is packed as a
piecewise cubic (its linear, quadratic and cubic coefficients beside each row's position; a linear
table's higher ones zero), so one kernel evaluates both.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._jit import jit, jitable
from ..validation import InputError, quoted, require_finite, require_index, require_nonnegative

MOTION_HARMONIC, MOTION_TABLE, MOTION_CALLABLE = 0, 1, 2
# Float columns of a packed motion: kind, amplitude (x, y, θ), ω = 2π f, phase φ (rad), the first
# row and the number of rows of its table in the packed times/values.
MO_KIND, MO_AX, MO_AY, MO_ATH, MO_OMEGA, MO_PHASE, MO_START, MO_COUNT = range(8)
N_MOTION_COLUMNS = 8
# Columns of the per-step evaluation `now`: d and ḋ at the step's start, d and ḋ at its end.
NOW_START, NOW_START_VELOCITY, NOW_END, NOW_VELOCITY = 0, 3, 6, 9
N_NOW_COLUMNS = 12
# Columns of the packed table values: row i's position (x, y, θ), then the coefficients of the
# cubic d(t) = d_i + c₁ s + c₂ s² + c₃ s³ (s = t − t_i, three columns each) on [t_i, t_{i+1}].
VALUE_POSITION, VALUE_LINEAR, VALUE_QUADRATIC, VALUE_CUBIC = 0, 3, 6, 9
N_VALUE_COLUMNS = 12
INTERPOLATIONS = ("linear", "spline")
SPLINE_BOUNDARY = "not-a-knot"  # scipy.interpolate.CubicSpline's bc_type: exact for a cubic
MIN_SPLINE_ROWS = 4  # a not-a-knot spline needs 4 rows to be a true cubic (scipy: 2 a line, 3 a parabola)


def _components(name: str, values, allowed) -> tuple[float, ...]:
    try:
        items = list(values)
    except TypeError:
        raise InputError(f"{name} must be a list of numbers, got {quoted(values)}") from None
    if len(items) not in allowed:
        raise InputError(f"{name} must have {' or '.join(map(str, allowed))} numbers (x, y, θ), got {len(items)}")
    return tuple(require_finite(f"{name}[{i}]", x) for i, x in enumerate(items))


@dataclass(frozen=True)
class Harmonic:
    """d(t) = amplitude · sin(2π frequency_hz t + phase), phase in radians."""

    amplitude: tuple
    frequency_hz: float
    phase: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "amplitude", _components("motion amplitude", self.amplitude, (2, 3)))
        require_nonnegative("motion frequency_hz", self.frequency_hz)
        require_finite("motion phase", self.phase)
        omega = 2.0 * math.pi * self.frequency_hz
        if not all(math.isfinite(a * omega * omega) for a in self.amplitude) or not math.isfinite(omega * omega):
            raise InputError(f"motion amplitude × (2π frequency_hz)² overflows: {quoted(self.amplitude)} at "
                             f"{self.frequency_hz:g} Hz (the motion's acceleration is not finite)")

    @property
    def n_components(self) -> int:
        return len(self.amplitude)

    def pack(self, row, times: list, values: list) -> None:
        a = self.amplitude + (0.0,) * (3 - len(self.amplitude))
        row[MO_KIND], (row[MO_AX], row[MO_AY], row[MO_ATH]) = MOTION_HARMONIC, a
        row[MO_OMEGA], row[MO_PHASE] = 2.0 * math.pi * self.frequency_hz, self.phase

    def at(self, t: float):
        return _packed_at(self, t)


@dataclass(frozen=True)
class Tabulated:
    """d(t) through (times[i], positions[i]), positions rows of 2 or 3 numbers: linear between the
    rows, or a cubic spline (interpolation="spline": scipy's CubicSpline per coordinate, not-a-knot
    ends, at least 4 rows); held at the first row before times[0] and the last after times[-1]."""

    times: tuple
    positions: tuple
    interpolation: str = "linear"
    coefficients: np.ndarray = field(init=False, repr=False, compare=False)  # (rows, N_VALUE_COLUMNS)

    def __post_init__(self):
        if self.interpolation not in INTERPOLATIONS:
            raise InputError(f"motion interpolation must be one of {', '.join(INTERPOLATIONS)}, "
                             f"got {quoted(self.interpolation)}")
        try:
            times = list(self.times)
        except TypeError:
            raise InputError(f"motion times must be a list of numbers, got {quoted(self.times)}") from None
        if not times:
            raise InputError("motion times must list at least one time")
        times = _components("motion times", times, (len(times),))
        if any(b <= a for a, b in zip(times, times[1:])):
            raise InputError("motion times must increase strictly")
        try:
            rows = [list(r) for r in self.positions]
        except TypeError:
            raise InputError(f"motion positions must be a list of [x, y] or [x, y, θ] rows, got "
                             f"{quoted(self.positions)}") from None
        if len(rows) != len(times):
            raise InputError(f"motion positions must have one row per time ({len(times)}), got {len(rows)}")
        width = len(rows[0])
        positions = tuple(_components(f"motion positions[{i}]", r, (width,) if i else (2, 3))
                          for i, r in enumerate(rows))
        if self.interpolation == "spline" and len(times) < MIN_SPLINE_ROWS:
            raise InputError(f"a spline motion table needs at least {MIN_SPLINE_ROWS} rows ({SPLINE_BOUNDARY} "
                             f"cubic), got {len(times)}")
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "positions", positions)
        object.__setattr__(self, "coefficients", _piecewise_cubic(times, positions, self.interpolation))

    @property
    def n_components(self) -> int:
        return len(self.positions[0])

    def pack(self, row, times: list, values: list) -> None:
        row[MO_KIND], row[MO_START], row[MO_COUNT] = MOTION_TABLE, len(times), len(self.times)
        times.extend(self.times)
        values.extend(self.coefficients)

    def at(self, t: float):
        return _packed_at(self, t)


def _piecewise_cubic(times, positions, interpolation: str) -> np.ndarray:
    """The packed values of a table (rows, N_VALUE_COLUMNS): each row's position and the
    coefficients of the cubic from it to the next row (the last row's zero: the table is held)."""
    values = np.zeros((len(times), N_VALUE_COLUMNS))
    y = np.array([tuple(p) + (0.0,) * (3 - len(p)) for p in positions])
    values[:, VALUE_POSITION:VALUE_POSITION + 3] = y
    if len(times) < 2:
        return values
    with np.errstate(all="ignore"):  # an overflow is refused below
        if interpolation == "linear":
            values[:-1, VALUE_LINEAR:VALUE_LINEAR + 3] = np.diff(y, axis=0) / np.diff(times)[:, None]
        else:
            from scipy.interpolate import CubicSpline  # here: a spline motion is rare, the import ~0.2 s

            c = CubicSpline(times, y, bc_type=SPLINE_BOUNDARY).c  # (4, rows − 1, 3): s³, s², s, 1
            for column, power in ((VALUE_CUBIC, 0), (VALUE_QUADRATIC, 1), (VALUE_LINEAR, 2)):
                values[:-1, column:column + 3] = c[power]
    if not np.all(np.isfinite(values)):
        raise InputError(f"motion positions change too fast between their times: the table's {interpolation} "
                         f"slopes overflow")
    return values


@dataclass(frozen=True)
class Prescribed:
    """A Python motion: function(t) -> (d, ḋ), each 2 or 3 numbers (`n_components` of them).
    A scene with one runs Moreau–Jean's step-wise loop (as a Python applied force does)."""

    function: object
    n_components: int = 2

    def __post_init__(self):
        if not callable(self.function):
            raise InputError(f"a Prescribed motion needs a callable t -> (displacement, velocity), "
                             f"got {quoted(self.function)}")
        if self.n_components not in (2, 3):
            raise InputError(f"Prescribed n_components must be 2 or 3, got {quoted(self.n_components)}")

    def pack(self, row, times: list, values: list) -> None:
        row[MO_KIND] = MOTION_CALLABLE

    def at(self, t: float):
        try:
            d, w = self.function(t)
            d = np.asarray(d, dtype=float)
            w = np.asarray(w, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"a Prescribed motion's function must return (displacement, velocity) at "
                             f"t = {t:g} s") from None
        n = self.n_components
        if d.shape != (n,) or w.shape != (n,) or not (np.all(np.isfinite(d)) and np.all(np.isfinite(w))):
            raise InputError(f"a Prescribed motion's function must return {n} finite numbers for the "
                             f"displacement and for the velocity, got {quoted(d.tolist())}, {quoted(w.tolist())} "
                             f"at t = {t:g} s")
        return np.r_[d, np.zeros(3 - n)], np.r_[w, np.zeros(3 - n)]


MOTION_TYPES = (Harmonic, Tabulated, Prescribed)


def require_motion(name: str, motion, components=(2, 3)):
    """A motion (or None) that moves `name`, with an allowed number of components."""
    if motion is None:
        return None
    if not isinstance(motion, MOTION_TYPES):
        raise InputError(f"{name} motion must be a Harmonic, Tabulated or Prescribed, got {type(motion).__name__}")
    if motion.n_components not in components:
        raise InputError(f"{name} motion: a line or segment translates (2 components: x, y), "
                         f"got {motion.n_components}")
    return motion


@dataclass(frozen=True)
class DrivenBody:
    """A body whose placement follows `motion` from its placement at the run's start: infinite
    mass for the contacts it takes part in (its forces and the contacts' impulses do not move it)."""

    body: int
    motion: object

    def __post_init__(self):
        object.__setattr__(self, "body", require_index("driven body", self.body))
        require_motion(f"driven body {self.body}", self.motion)


def pack_motions(motions) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(table (n, N_MOTION_COLUMNS), times, values (rows, 3)) of a list of motions."""
    table = np.zeros((len(motions), N_MOTION_COLUMNS))
    times: list = []
    values: list = []
    for i, motion in enumerate(motions):
        motion.pack(table[i], times, values)
    return table, np.array(times, dtype=float), np.array(values, dtype=float).reshape(-1, N_VALUE_COLUMNS)


def _packed_at(motion, t: float):
    table, times, values = pack_motions([motion])
    out = np.zeros(6)
    motion_kernel(float(t), table[0], times, values, out, 0)
    return out[:3], out[3:]


@jitable
def motion_kernel(t, row, times, values, out, o):
    """d(t) into out[o:o+3] and ḋ(t) into out[o+3:o+6] for a harmonic or tabulated motion (a table
    is a piecewise cubic: its row's position plus c₁ s + c₂ s² + c₃ s³, ḋ = c₁ + 2 c₂ s + 3 c₃ s²)."""
    if row[MO_KIND] == MOTION_HARMONIC:
        arg = row[MO_OMEGA] * t + row[MO_PHASE]
        s, c = math.sin(arg), row[MO_OMEGA] * math.cos(arg)
        for d in range(3):
            out[o + d] = row[MO_AX + d] * s
            out[o + 3 + d] = row[MO_AX + d] * c
        return
    start, n = int(row[MO_START]), int(row[MO_COUNT])
    j = start + np.searchsorted(times[start:start + n], t, side="right") - 1  # the row at or before t
    inside = start <= j < start + n - 1
    j = min(max(j, start), start + n - 1)
    s = t - times[j] if inside else 0.0  # held outside the times: the row's position, ḋ = 0
    for d in range(3):
        c1, c2, c3 = values[j, VALUE_LINEAR + d], values[j, VALUE_QUADRATIC + d], values[j, VALUE_CUBIC + d]
        out[o + d] = values[j, VALUE_POSITION + d] + ((c3 * s + c2) * s + c1) * s
        out[o + 3 + d] = ((3.0 * c3 * s + 2.0 * c2) * s + c1) if inside else 0.0


@jit
def evaluate_motions(t_start, t_end, table, times, values, now):
    """Each compiled motion's (d, ḋ) at t_start and at t_end into its row of `now`; the Python
    (Prescribed) rows are left as the step-wise loop wrote them."""
    for m in range(table.shape[0]):
        if table[m, MO_KIND] == MOTION_CALLABLE:
            continue
        motion_kernel(t_start, table[m], times, values, now[m], NOW_START)
        motion_kernel(t_end, table[m], times, values, now[m], NOW_END)


def evaluate_python_motions(motions, t_start: float, t_end: float, now) -> None:
    """The Prescribed motions' rows of `now` (the step-wise loop, before each step)."""
    for m, motion in enumerate(motions):
        if isinstance(motion, Prescribed):
            now[m, NOW_START:NOW_START + 3], now[m, NOW_START_VELOCITY:NOW_START_VELOCITY + 3] = motion.at(t_start)
            now[m, NOW_END:NOW_END + 3], now[m, NOW_VELOCITY:NOW_VELOCITY + 3] = motion.at(t_end)


__all__ = ["Harmonic", "Tabulated", "Prescribed", "DrivenBody", "MOTION_TYPES", "require_motion", "pack_motions",
           "motion_kernel", "evaluate_motions", "evaluate_python_motions"]
