"""Bilateral joints as data: pins (revolute) and sliders (prismatic) between two bodies, or a body
and the world.

Each joint is two equality rows C(q) = 0:

* Pin: the world positions of point_a on body_a and point_b on body_b (or the world point
  point_b) coincide — C = r_a − r_b, so its multipliers are the world force (x, y) the joint
  applies on body_a.
* Slider: point_a stays on the line through point_b along `axis` (both in body_b's frame, or the
  world's without body_b) — C₀ = n·(r_a − r_b), n the line's normal — and body_a keeps the angle
  `angle` relative to body_b — C₁ = θ_a − θ_b − angle. Its multipliers are the force along n
  on body_a and the torque on body_a.
* LinearJoint: one linear equality between the coordinates of one or two bodies, C₀ = c + w·q
  (Siconos' LagrangianLinearTIR with an equality law; the published woodpecker's hinge,
  linearised: toys/woodpecker.py). Its second row is zero (the step's pseudo-inverse drops it);
  its multiplier is the generalised force along w.

`pack_joints` turns them into the table the compiled Moreau–Jean loop reads; `joint_rows` (one
kernel, compiled or interpreted) evaluates C(q) and the Jacobian J = ∂C/∂q — integrators/
joint_step.py eliminates the rows inside each step (docs/joints.md).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._jit import jit, jit_inline
from ..solvers._common import interpreted
from ..validation import InputError, quoted, require_finite
from .contacts import check_linear_row
from .forces import _require_point, check_two_ends

JOINT_PIN, JOINT_SLIDER, JOINT_LINEAR = 0, 1, 2
ROWS_PER_JOINT = 2
# Columns of the packed joint table (one float64 row per joint: the compiled loop's model tuple
# takes one array for every joint): geometry, then kind and bodies (small integers, exact as floats).
J_PA_X, J_PA_Y, J_PB_X, J_PB_Y, J_AXIS_X, J_AXIS_Y, J_ANGLE, J_KIND, J_BODY_A, J_BODY_B = range(10)
N_JOINT_COLUMNS = 10
# A linear joint's coefficients of (x, y, θ) of body a, then of body b, in the six geometry
# columns, and its constant c in J_ANGLE.
J_LINEAR = J_PA_X
# What each joint's multipliers are, by kind (trajectory.csv's column suffixes; a linear joint's
# second row is zero, its multiplier not reported).
REACTION_NAMES = {JOINT_PIN: ("Fx", "Fy"), JOINT_SLIDER: ("F", "M"), JOINT_LINEAR: ("F",)}


@dataclass(frozen=True)
class Pin:
    """A revolute joint: point_a of body_a (its frame) held at point_b of body_b (its frame), or at
    the world point point_b when body_b is None."""

    body_a: int
    point_a: tuple = (0.0, 0.0)
    body_b: int | None = None
    point_b: tuple = (0.0, 0.0)
    name: str = "pin"

    kind = JOINT_PIN

    def __post_init__(self):
        check_two_ends(self, "the world")


@dataclass(frozen=True)
class Slider:
    """A prismatic joint: point_a of body_a slides along the line through point_b with direction
    `axis` (body_b's frame, or the world's when body_b is None), and body_a keeps the angle
    `angle` (rad) relative to body_b (or the world)."""

    body_a: int
    point_a: tuple = (0.0, 0.0)
    body_b: int | None = None
    point_b: tuple = (0.0, 0.0)
    axis: tuple = (1.0, 0.0)
    angle: float = 0.0
    name: str = "slider"

    kind = JOINT_SLIDER

    def __post_init__(self):
        check_two_ends(self, "the world")
        ax, ay = _require_point(self.name, "axis", self.axis)
        length = math.hypot(ax, ay)
        if not length > 0.0 or not math.isfinite(length):
            raise InputError(f"{self.name} axis must be a non-zero direction, got {quoted(self.axis)}")
        object.__setattr__(self, "axis", (ax / length, ay / length))
        object.__setattr__(self, "angle", require_finite(f"{self.name} angle", self.angle))


@dataclass(frozen=True)
class LinearJoint:
    """A linear equality between coordinates: constant + Σ row[body]·(x, y, θ) = 0, `row` mapping
    one or two body indices to their (x, y, θ) coefficients. Its reaction F is the multiplier of
    that row: the generalised force F·row[body] on each body."""

    row: dict
    constant: float = 0.0
    name: str = "linear"

    kind = JOINT_LINEAR

    def __post_init__(self):
        row = check_linear_row(f"{self.name} row", self.row)
        if not 1 <= len(row) <= 2 or not any(c != 0.0 for w in row.values() for c in w):
            raise InputError(f"{self.name} row: one or two bodies with a non-zero row, got {self.row!r}")
        object.__setattr__(self, "row", row)
        object.__setattr__(self, "constant", require_finite(f"{self.name} constant", self.constant))

    @property
    def body_a(self) -> int:
        return min(self.row)

    @property
    def body_b(self) -> int | None:
        return max(self.row) if len(self.row) == 2 else None


JOINT_TYPES = (Pin, Slider, LinearJoint)


def pack_joints(joints, n_bodies: int) -> np.ndarray:
    """The joints as one (n, N_JOINT_COLUMNS) float64 table (body_b −1: the world)."""
    joints = list(joints)
    table = np.zeros((len(joints), N_JOINT_COLUMNS))
    for i, joint in enumerate(joints):
        if not isinstance(joint, JOINT_TYPES):
            raise InputError(f"joints[{i}] must be a Pin, a Slider or a LinearJoint, got {type(joint).__name__}")
        if max(joint.body_a, -1 if joint.body_b is None else joint.body_b) >= n_bodies:
            raise InputError(f"joint {joint.name!r}: body index beyond the scene's {n_bodies} bodies")
        table[i, [J_KIND, J_BODY_A, J_BODY_B]] = joint.kind, joint.body_a, -1 if joint.body_b is None else joint.body_b
        if isinstance(joint, LinearJoint):
            for side, body in enumerate(sorted(joint.row)):
                table[i, J_LINEAR + 3 * side:J_LINEAR + 3 * side + 3] = joint.row[body]
            table[i, J_ANGLE] = joint.constant
            continue
        table[i, [J_PA_X, J_PA_Y]], table[i, [J_PB_X, J_PB_Y]] = joint.point_a, joint.point_b
        if isinstance(joint, Slider):
            table[i, [J_AXIS_X, J_AXIS_Y]], table[i, J_ANGLE] = joint.axis, joint.angle
    return table


def joint_violation(joints, n_bodies: int, q) -> np.ndarray:
    """C(q) of the joints (2 rows each: a pin's x, y gap; a slider's offset from its line and angle)."""
    table = pack_joints(joints, n_bodies)
    J, C = np.zeros((ROWS_PER_JOINT * len(table), 3 * n_bodies)), np.zeros(ROWS_PER_JOINT * len(table))
    interpreted(joint_rows)(table, np.asarray(q, dtype=float), J, C)
    return C


@jit
def jointed_dofs(table, n_dof):
    """(dofs, slot): the dofs of the jointed bodies, ascending, and each dof's position among them
    (−1: not jointed)."""
    slot = np.full(n_dof, -1, dtype=np.int64)
    for i in range(table.shape[0]):
        for column in (J_BODY_A, J_BODY_B):
            body = int(table[i, column])
            if body >= 0:
                for d in range(3):
                    slot[3 * body + d] = 0
    n = 0
    for d in range(n_dof):
        if slot[d] >= 0:
            slot[d] = n
            n += 1
    dofs = np.empty(n, dtype=np.int64)
    for d in range(n_dof):
        if slot[d] >= 0:
            dofs[slot[d]] = d
    return dofs, slot


@jit
def _frame(q, body, px, py):
    """World position of body point (px, py) and its lever R(θ)p; the world point itself for body < 0."""
    if body < 0:
        return px, py, 0.0, 0.0
    j = 3 * body
    c, s = math.cos(q[j + 2]), math.sin(q[j + 2])
    dx, dy = c * px - s * py, s * px + c * py
    return q[j] + dx, q[j + 1] + dy, dx, dy


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _pin_rows(row, a, b, q, J, r):
    xa, ya, dxa, dya = _frame(q, a, row[J_PA_X], row[J_PA_Y])
    xb, yb, dxb, dyb = _frame(q, b, row[J_PB_X], row[J_PB_Y])
    ja = 3 * a
    J[r, ja], J[r, ja + 2] = 1.0, -dya
    J[r + 1, ja + 1], J[r + 1, ja + 2] = 1.0, dxa
    if b >= 0:
        jb = 3 * b
        J[r, jb], J[r, jb + 2] = -1.0, dyb
        J[r + 1, jb + 1], J[r + 1, jb + 2] = -1.0, -dxb
    return xa - xb, ya - yb


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _slider_rows(row, a, b, q, J, r):
    xa, ya, dxa, dya = _frame(q, a, row[J_PA_X], row[J_PA_Y])
    xb, yb, dxb, dyb = _frame(q, b, row[J_PB_X], row[J_PB_Y])
    theta_b = q[3 * b + 2] if b >= 0 else 0.0
    c, s = math.cos(theta_b), math.sin(theta_b)
    ux, uy = c * row[J_AXIS_X] - s * row[J_AXIS_Y], s * row[J_AXIS_X] + c * row[J_AXIS_Y]  # the axis, world
    nx, ny = -uy, ux
    ex, ey = xa - xb, ya - yb
    ja = 3 * a
    J[r, ja], J[r, ja + 1], J[r, ja + 2] = nx, ny, nx * -dya + ny * dxa
    J[r + 1, ja + 2] = 1.0
    if b >= 0:
        jb = 3 * b
        # ∂n/∂θ_b = −u: the line turns with body_b; its anchor point moves with it
        J[r, jb], J[r, jb + 1], J[r, jb + 2] = -nx, -ny, -(ux * ex + uy * ey) - (nx * -dyb + ny * dxb)
        J[r + 1, jb + 2] = -1.0
    return nx * ex + ny * ey, q[ja + 2] - theta_b - row[J_ANGLE]


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def check_linear_rows(row, a, b, q, J, r):
    """c + w·q and its constant row; the joint's second row stays zero."""
    c = row[J_ANGLE]
    for side in range(2):
        body = a if side == 0 else b
        if body >= 0:
            for d in range(3):
                J[r, 3 * body + d] = row[J_LINEAR + 3 * side + d]
                c += row[J_LINEAR + 3 * side + d] * q[3 * body + d]
    return c, 0.0


@jit
def joint_rows(table, q, J, C):
    """C(q) (2 rows per joint) and its Jacobian J = ∂C/∂q (dense: rows × n_dof, overwritten)."""
    J[:, :] = 0.0
    for i in range(table.shape[0]):
        r = ROWS_PER_JOINT * i
        row = table[i]
        a, b = int(row[J_BODY_A]), int(row[J_BODY_B])
        kind = int(row[J_KIND])
        if kind == JOINT_PIN:
            c0, c1 = _pin_rows(row, a, b, q, J, r)
        elif kind == JOINT_LINEAR:
            c0, c1 = check_linear_rows(row, a, b, q, J, r)
        else:
            c0, c1 = _slider_rows(row, a, b, q, J, r)
        C[r], C[r + 1] = c0, c1


__all__ = ["Pin", "Slider", "LinearJoint", "JOINT_LINEAR",
           "JOINT_TYPES", "pack_joints", "jointed_dofs", "joint_violation", "joint_rows",
           "JOINT_PIN", "JOINT_SLIDER", "REACTION_NAMES", "ROWS_PER_JOINT"]
