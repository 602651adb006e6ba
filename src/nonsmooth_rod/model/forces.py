"""Applied forces as data: springs, dampers, torsion springs, constant, ramped and tabulated forces.

Each force is a small frozen dataclass that validates its fields, and `generalised_force(t, q, v,
n_dof)` gives its contribution to the scene's generalised force (forces on the centres of mass,
torques) for Python callers. The compiled Moreau–Jean loop never sees these objects: `pack_forces`
turns a sequence of them into float64/int64 tables, and `accumulate_forces` (one kernel, compiled
or interpreted) evaluates the tables. `generalised_force` itself calls that kernel, so there is
one implementation of every force law.

Points are body-frame offsets from the body's centre of mass; bodies are indices into
scene.bodies; forces are world-frame vectors.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._jit import jit, jit_inline
from ..solvers._common import interpreted
from ..validation import InputError, quoted, require_finite, require_nonnegative

# Force kinds of the packed table.
FORCE_SPRING, FORCE_CONSTANT, FORCE_RAMPED, FORCE_TABULATED = 0, 1, 2, 3
FORCE_TORSION = 4
# Float columns of the packed force table.
(F_PA_X, F_PA_Y, F_PB_X, F_PB_Y, F_STIFFNESS, F_REST_LENGTH, F_DAMPING, F_FX, F_FY, F_TORQUE,
 F_T_START, F_T_FULL) = range(12)
N_FORCE_COLUMNS = 12
# Int columns: kind, body a, body b (−1: the world), first row and row count in the time table.
FI_KIND, FI_BODY_A, FI_BODY_B, FI_TABLE_START, FI_TABLE_ROWS = range(5)
N_FORCE_INDEX_COLUMNS = 5


def _require_body(owner: str, field_name: str, body) -> int:
    if isinstance(body, bool) or not isinstance(body, (int, np.integer)) or body < 0:
        raise InputError(f"{owner} {field_name} must be a non-negative body index, got {quoted(body)}")
    return int(body)


def _require_point(owner: str, field_name: str, point) -> tuple[float, float]:
    try:
        x, y = point
    except (TypeError, ValueError):
        raise InputError(f"{owner} {field_name} must be a pair (x, y), got {quoted(point)}") from None
    return (require_finite(f"{owner} {field_name}", x), require_finite(f"{owner} {field_name}", y))


def check_two_ends(item, world: str) -> None:
    """body_a, point_a and body_b (None: the world), point_b of a spring, damper or joint, checked;
    the points stored as float pairs. `world`: what body_b = None means, for the message."""
    _require_body(item.name, "body_a", item.body_a)
    if item.body_b is not None:
        _require_body(item.name, "body_b", item.body_b)
        if item.body_b == item.body_a:
            raise InputError(f"{item.name}: body_b must differ from body_a (or be None for {world})")
    object.__setattr__(item, "point_a", _require_point(item.name, "point_a", item.point_a))
    object.__setattr__(item, "point_b", _require_point(item.name, "point_b", item.point_b))


class _Force:
    """What every force shares: the Python evaluation through the packed kernel."""

    def generalised_force(self, t: float, q, v, n_dof: int) -> np.ndarray:
        """This force's generalised force (n_dof entries) at time t and state (q, v)."""
        table, index, times, values = pack_forces([self])
        if int(index[0, FI_BODY_A]) * 3 + 3 > n_dof or int(index[0, FI_BODY_B]) * 3 + 3 > n_dof:
            raise InputError(f"{self.name}: body index beyond the scene's {n_dof // 3} bodies")
        f = np.zeros(n_dof)
        interpreted(accumulate_forces)(float(t), np.asarray(q, dtype=float), np.asarray(v, dtype=float),
                                        table, index, times, values, f)
        return f


@dataclass(frozen=True)
class Spring(_Force):
    """A linear spring-damper between two body points, or a body point and a fixed world point.

    Magnitude k (ℓ − ℓ0) + c dℓ/dt along the line joining the points, pulling them together when
    stretched. body_b None: point_b is the fixed world point.
    """

    body_a: int
    point_a: tuple = (0.0, 0.0)
    body_b: int | None = None
    point_b: tuple = (0.0, 0.0)
    stiffness: float = 0.0
    rest_length: float = 0.0
    damping: float = 0.0
    name: str = "spring"

    def __post_init__(self):
        check_two_ends(self, "a world point")
        require_nonnegative(f"{self.name} stiffness", self.stiffness)
        require_nonnegative(f"{self.name} rest_length", self.rest_length)
        require_nonnegative(f"{self.name} damping", self.damping)


def Damper(body_a: int, point_a=(0.0, 0.0), body_b: int | None = None, point_b=(0.0, 0.0),
           damping: float = 0.0, name: str = "damper") -> Spring:
    """A linear damper between two points: a Spring of stiffness 0."""
    return Spring(body_a, point_a, body_b, point_b, stiffness=0.0, rest_length=0.0, damping=damping, name=name)


def _check_force_at_point(force) -> None:
    """The fields a constant and a ramped force share: body, force (fx, fy), point, torque."""
    _require_body(force.name, "body", force.body)
    object.__setattr__(force, "force", _require_point(force.name, "force", force.force))
    object.__setattr__(force, "point", _require_point(force.name, "point", force.point))
    require_finite(f"{force.name} torque", force.torque)


@dataclass(frozen=True)
class ConstantForce(_Force):
    """A constant world-frame force (and torque) at a body point."""

    body: int
    force: tuple = (0.0, 0.0)
    torque: float = 0.0
    point: tuple = (0.0, 0.0)
    name: str = "force"

    def __post_init__(self):
        _check_force_at_point(self)


@dataclass(frozen=True)
class RampedForce(_Force):
    """A ConstantForce scaled by clip((t − t_start)/(t_full − t_start), 0, 1)."""

    body: int
    force: tuple = (0.0, 0.0)
    torque: float = 0.0
    point: tuple = (0.0, 0.0)
    t_start: float = 0.0
    t_full: float = 1.0
    name: str = "ramp"

    def __post_init__(self):
        _check_force_at_point(self)
        require_finite(f"{self.name} t_start", self.t_start)
        require_finite(f"{self.name} t_full", self.t_full)
        if not self.t_full > self.t_start:
            raise InputError(f"{self.name} t_full must exceed t_start = {quoted(self.t_start)}, got {quoted(self.t_full)}")


@dataclass(frozen=True)
class TabulatedForce(_Force):
    """World-frame force (and torque) interpolated linearly in t from a table; held constant
    outside [times[0], times[-1]]."""

    body: int
    times: tuple = ()
    forces: tuple = ()
    torques: tuple | None = None
    point: tuple = (0.0, 0.0)
    name: str = "table"

    def __post_init__(self):
        _require_body(self.name, "body", self.body)
        object.__setattr__(self, "point", _require_point(self.name, "point", self.point))
        times = np.asarray(self.times, dtype=float).ravel()
        if times.size == 0 or not np.all(np.isfinite(times)):
            raise InputError(f"{self.name} times must be a non-empty sequence of finite numbers, got {quoted(self.times)}")
        if np.any(np.diff(times) <= 0.0):
            raise InputError(f"{self.name} times must be strictly increasing, got {quoted(self.times)}")
        forces = np.asarray(self.forces, dtype=float)
        if forces.shape != (times.size, 2) or not np.all(np.isfinite(forces)):
            raise InputError(f"{self.name} forces must be {times.size} finite (fx, fy) rows, got {quoted(self.forces)}")
        torques = np.zeros(times.size) if self.torques is None else np.asarray(self.torques, dtype=float).ravel()
        if torques.shape != (times.size,) or not np.all(np.isfinite(torques)):
            raise InputError(f"{self.name} torques must be {times.size} finite numbers, got {quoted(self.torques)}")
        object.__setattr__(self, "times", tuple(times.tolist()))
        object.__setattr__(self, "forces", tuple(map(tuple, forces.tolist())))
        object.__setattr__(self, "torques", tuple(torques.tolist()))


@dataclass(frozen=True)
class TorsionSpring(_Force):
    """A torsional spring-damper between two bodies, or a body and the world (body_b None).

    Torque −k (θ_a − θ_b − rest_angle) − c (ω_a − ω_b) on body_a, the opposite on body_b (θ_b, ω_b
    zero for the world). rest_angle in radians."""

    body_a: int
    body_b: int | None = None
    stiffness: float = 0.0
    rest_angle: float = 0.0
    damping: float = 0.0
    name: str = "torsion-spring"

    def __post_init__(self):
        _require_body(self.name, "body_a", self.body_a)
        if self.body_b is not None:
            _require_body(self.name, "body_b", self.body_b)
            if self.body_b == self.body_a:
                raise InputError(f"{self.name}: body_b must differ from body_a (or be None for the world)")
        require_nonnegative(f"{self.name} stiffness", self.stiffness)
        require_finite(f"{self.name} rest_angle", self.rest_angle)
        require_nonnegative(f"{self.name} damping", self.damping)


def Torque(body: int, torque: float = 0.0, name: str = "torque") -> ConstantForce:
    """A constant torque on a body: a ConstantForce without force."""
    return ConstantForce(body, (0.0, 0.0), torque, (0.0, 0.0), name=name)


FORCE_TYPES = (Spring, ConstantForce, RampedForce, TabulatedForce, TorsionSpring)


def pack_forces(forces) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(table (n, 12) float64, index (n, 5) int64, times (m,), values (m, 3)) of the forces."""
    forces = list(forces)
    table = np.zeros((len(forces), N_FORCE_COLUMNS))
    index = np.zeros((len(forces), N_FORCE_INDEX_COLUMNS), dtype=np.int64)
    times, values = [], []
    for i, force in enumerate(forces):
        row, ix = table[i], index[i]
        ix[FI_BODY_B] = -1
        if isinstance(force, Spring):
            ix[FI_KIND], ix[FI_BODY_A] = FORCE_SPRING, force.body_a
            ix[FI_BODY_B] = -1 if force.body_b is None else force.body_b
            row[[F_PA_X, F_PA_Y]], row[[F_PB_X, F_PB_Y]] = force.point_a, force.point_b
            row[[F_STIFFNESS, F_REST_LENGTH, F_DAMPING]] = force.stiffness, force.rest_length, force.damping
        elif isinstance(force, (ConstantForce, RampedForce)):
            ix[FI_KIND] = FORCE_CONSTANT if isinstance(force, ConstantForce) else FORCE_RAMPED
            ix[FI_BODY_A] = force.body
            row[[F_PA_X, F_PA_Y]] = force.point
            row[[F_FX, F_FY]], row[F_TORQUE] = force.force, force.torque
            if isinstance(force, RampedForce):
                row[F_T_START], row[F_T_FULL] = force.t_start, force.t_full
        elif isinstance(force, TorsionSpring):
            ix[FI_KIND], ix[FI_BODY_A] = FORCE_TORSION, force.body_a
            ix[FI_BODY_B] = -1 if force.body_b is None else force.body_b
            row[[F_STIFFNESS, F_REST_LENGTH, F_DAMPING]] = force.stiffness, force.rest_angle, force.damping
        elif isinstance(force, TabulatedForce):
            ix[FI_KIND], ix[FI_BODY_A] = FORCE_TABULATED, force.body
            row[[F_PA_X, F_PA_Y]] = force.point
            ix[FI_TABLE_START], ix[FI_TABLE_ROWS] = len(times), len(force.times)
            times.extend(force.times)
            values.extend((fx, fy, tz) for (fx, fy), tz in zip(force.forces, force.torques))
        else:
            raise InputError(f"forces[{i}] must be a Spring, Damper, ConstantForce, RampedForce, "
                             f"TabulatedForce or TorsionSpring, got {type(force).__name__}")
    return (table, index, np.array(times, dtype=float).reshape(-1),
            np.array(values, dtype=float).reshape(-1, 3))


@jit
def _apply_at_point(f, body, px, py, theta, fx, fy, torque):
    """Add a world force (fx, fy) at body-frame point (px, py) and a torque to f."""
    c, s = math.cos(theta), math.sin(theta)
    dx, dy = c * px - s * py, s * px + c * py
    j = 3 * body
    f[j] += fx
    f[j + 1] += fy
    f[j + 2] += torque + dx * fy - dy * fx


@jit
def _point_state(q, v, body, px, py):
    """World position and velocity of a body point; body < 0 means the fixed world point (px, py)."""
    if body < 0:
        return px, py, 0.0, 0.0
    j = 3 * body
    c, s = math.cos(q[j + 2]), math.sin(q[j + 2])
    dx, dy = c * px - s * py, s * px + c * py
    om = v[j + 2]
    return q[j] + dx, q[j + 1] + dy, v[j] - om * dy, v[j + 1] + om * dx


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _spring(q, v, row, body_a, body_b, f):
    xa, ya, vxa, vya = _point_state(q, v, body_a, row[F_PA_X], row[F_PA_Y])
    xb, yb, vxb, vyb = _point_state(q, v, body_b, row[F_PB_X], row[F_PB_Y])
    ex, ey = xa - xb, ya - yb
    length = math.sqrt(ex * ex + ey * ey)
    if length == 0.0:  # coincident points: no direction, and a zero-length spring pulls nothing
        return
    ex /= length
    ey /= length
    rate = ex * (vxa - vxb) + ey * (vya - vyb)
    tension = row[F_STIFFNESS] * (length - row[F_REST_LENGTH]) + row[F_DAMPING] * rate
    _apply_at_point(f, body_a, row[F_PA_X], row[F_PA_Y], q[3 * body_a + 2], -tension * ex, -tension * ey, 0.0)
    if body_b >= 0:
        _apply_at_point(f, body_b, row[F_PB_X], row[F_PB_Y], q[3 * body_b + 2], tension * ex, tension * ey, 0.0)


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _torsion(q, v, row, body_a, body_b, f):
    """−k (θ_a − θ_b − θ_rest) − c (ω_a − ω_b) on body_a, its opposite on body_b (unless the world)."""
    ja = 3 * body_a + 2
    angle, rate = q[ja] - row[F_REST_LENGTH], v[ja]  # F_REST_LENGTH holds the rest angle
    if body_b >= 0:
        angle -= q[3 * body_b + 2]
        rate -= v[3 * body_b + 2]
    torque = -row[F_STIFFNESS] * angle - row[F_DAMPING] * rate
    f[ja] += torque
    if body_b >= 0:
        f[3 * body_b + 2] -= torque


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _tabulated(t, times, values, start, rows):
    """Linear interpolation of the rows [start, start + rows) of (times, values) at t."""
    last = start + rows - 1
    if t <= times[start]:
        return values[start, 0], values[start, 1], values[start, 2]
    if t >= times[last]:
        return values[last, 0], values[last, 1], values[last, 2]
    lo, hi = start, last
    while hi - lo > 1:  # bisection: times[lo] ≤ t < times[hi]
        mid = (lo + hi) // 2
        if times[mid] <= t:
            lo = mid
        else:
            hi = mid
    w = (t - times[lo]) / (times[hi] - times[lo])
    return ((1.0 - w) * values[lo, 0] + w * values[hi, 0], (1.0 - w) * values[lo, 1] + w * values[hi, 1],
            (1.0 - w) * values[lo, 2] + w * values[hi, 2])


@jit
def accumulate_forces(t, q, v, table, index, times, values, f):
    """Add every packed force's generalised force at (t, q, v) to f."""
    for i in range(table.shape[0]):
        kind = index[i, FI_KIND]
        body = index[i, FI_BODY_A]
        row = table[i]
        if kind == FORCE_SPRING:
            _spring(q, v, row, body, index[i, FI_BODY_B], f)
            continue
        if kind == FORCE_TORSION:
            _torsion(q, v, row, body, index[i, FI_BODY_B], f)
            continue
        scale = 1.0
        fx, fy, torque = row[F_FX], row[F_FY], row[F_TORQUE]
        if kind == FORCE_RAMPED:
            scale = min(1.0, max(0.0, (t - row[F_T_START]) / (row[F_T_FULL] - row[F_T_START])))
        elif kind == FORCE_TABULATED:
            fx, fy, torque = _tabulated(t, times, values, index[i, FI_TABLE_START], index[i, FI_TABLE_ROWS])
        _apply_at_point(f, body, row[F_PA_X], row[F_PA_Y], q[3 * body + 2], scale * fx, scale * fy,
                        scale * torque)


__all__ = ["Spring", "Damper", "ConstantForce", "RampedForce", "TabulatedForce", "TorsionSpring", "Torque",
           "FORCE_TYPES",
           "pack_forces", "accumulate_forces"]
