"""A scene as arrays: what the compiled Moreau–Jean loop reads.

`pack_scene(scene)` gives a PackedScene: the mass diagonal, the weight, one row per contact
(float64 geometry and law, int64 kind and bodies) and the applied forces as tables
(model.forces.pack_forces). Each relation writes its own row (`fill_row` in model/contacts.py);
`contact_kinematics` evaluates one packed contact with the kernels of model/contact_kernels.py —
the ones the relations' `kinematics` call too — giving the gap, the normal drift Ḣ_N v and the
Jacobian rows restricted to the (at most two) bodies it touches: six entries, (ẋ, ẏ, θ̇) of
body a then of body b (zero when the obstacle is fixed) — so that a step's cost grows with its
contacts, not with contacts × degrees of freedom.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._jit import jit, jit_borrowing
from ..validation import InputError
from .contact_kernels import (C_LINE_PX, C_LINE_PY, C_MU_D, C_MU_S, C_NX, C_NY, C_OFF_AX, C_OFF_AY,  # noqa: F401
                              C_OFF_BX, C_OFF_BY, C_RADIUS_A, C_RADIUS_B, C_RESTITUTION, C_SEGMENT_LENGTH,
                              C_SURFACE_VELOCITY, C_TX, C_TY, KIND_DISK_ON_DISK, KIND_DISK_ON_LINE,
                              KIND_DISK_ON_SEGMENT, N_CONTACT_COLUMNS, kinematics_kernel, C_EDGE_TX, C_EDGE_TY,
                              KIND_FIXED_VERTEX_ON_EDGE, KIND_SEGMENT_END_ON_EDGE, KIND_VERTEX_ON_EDGE,
                              C_MOTION, C_BASE_PX, C_BASE_PY,
                              C_OBSTACLE_VX, C_OBSTACLE_VY, C_OBSTACLE_START_VX, C_OBSTACLE_START_VY)
from .forces import pack_forces
from .motion import NOW_START, NOW_START_VELOCITY, NOW_VELOCITY, pack_motions

# Int columns: kind, body a, body b (−1 for a fixed obstacle).
CI_KIND, CI_BODY_A, CI_BODY_B = range(3)


@dataclass
class PackedScene:
    minv: np.ndarray  # (n_dof,) inverse mass diagonal
    weight: np.ndarray  # (n_dof,) gravity
    contacts: np.ndarray  # (nc, N_CONTACT_COLUMNS) float64
    contact_index: np.ndarray  # (nc, 3) int64
    force_table: np.ndarray
    force_index: np.ndarray
    force_times: np.ndarray
    force_values: np.ndarray
    disks: np.ndarray  # (n_disks, 3): offset x, y and radius of every feature circle (pack_disk_pairs)
    disk_body: np.ndarray  # (n_disks,) int64; −1: a fixed circle (offset in the world frame)
    pair_keys: np.ndarray  # (n_pairs,) int64 sorted: min(disk a, disk b) · n_disks + max(...)
    pair_contact: np.ndarray  # (n_pairs,) int64: the contact of each key
    motions: list = None  # model/motion.py: every motion of a driven obstacle or body, by index
    motion_table: np.ndarray = None  # (n_motions, N_MOTION_COLUMNS), with motion_times, motion_values
    motion_times: np.ndarray = None
    motion_values: np.ndarray = None
    driven: np.ndarray = None  # (n_driven, 2) int64: body, its motion

    @property
    def n_contacts(self) -> int:
        return self.contacts.shape[0]


def pack_contacts(contacts, n_bodies: int) -> tuple[np.ndarray, np.ndarray]:
    table = np.zeros((len(contacts), N_CONTACT_COLUMNS))
    index = np.zeros((len(contacts), 3), dtype=np.int64)
    for i, c in enumerate(contacts):
        if not hasattr(c, "fill_row"):
            from .contacts import RELATION_NAMES

            raise InputError(f"contact {i} ({getattr(c, 'name', '?')}): the engine takes "
                             f"{', '.join(RELATION_NAMES)} contacts, got {type(c).__name__}")
        row = table[i]
        index[i] = c.fill_row(row)
        friction, impact = c.law.friction, c.law.impact
        row[C_MU_S], row[C_MU_D], row[C_RESTITUTION] = friction.mu_s, friction.mu_d, impact.restitution
        if max(index[i, CI_BODY_A], index[i, CI_BODY_B]) >= n_bodies:
            raise InputError(f"contact {c.name}: body index beyond the scene's {n_bodies} bodies")
    return table, index


def _feature_circles(kind, row, body_a, body_b):
    """Circles (body or −1, offset x, y, radius; body frame, world when fixed) that hold each
    side's feature of a contact, for the broad phase; None for a line (infinite: always tested).
    An edge's circle is around its middle, through its ends."""
    if kind == KIND_DISK_ON_DISK:
        return ((body_a, row[C_OFF_AX], row[C_OFF_AY], row[C_RADIUS_A]),
                (body_b, row[C_OFF_BX], row[C_OFF_BY], row[C_RADIUS_B]))
    half = 0.5 * row[C_SEGMENT_LENGTH]
    if kind == KIND_VERTEX_ON_EDGE:
        return ((body_a, row[C_OFF_AX], row[C_OFF_AY], row[C_RADIUS_A]),
                (body_b, row[C_OFF_BX] + half * row[C_EDGE_TX], row[C_OFF_BY] + half * row[C_EDGE_TY], half))
    if kind == KIND_FIXED_VERTEX_ON_EDGE:
        return ((-1, row[C_LINE_PX], row[C_LINE_PY], 0.0),
                (body_a, row[C_OFF_BX] + half * row[C_EDGE_TX], row[C_OFF_BY] + half * row[C_EDGE_TY], half))
    if kind == KIND_SEGMENT_END_ON_EDGE:
        return ((-1, row[C_LINE_PX], row[C_LINE_PY], 0.0),
                (body_a, row[C_OFF_AX] + half * row[C_EDGE_TX], row[C_OFF_AY] + half * row[C_EDGE_TY], half))
    if kind == KIND_DISK_ON_SEGMENT:
        return ((body_a, row[C_OFF_AX], row[C_OFF_AY], row[C_RADIUS_A]),
                (-1, row[C_LINE_PX] + half * row[C_TX], row[C_LINE_PY] + half * row[C_TY], half))
    return None


def pack_disk_pairs(table, index):
    """The broad phase's tables: the distinct circles holding the contacts' features (a disk; a
    vertex, radius 0; an edge or segment, around its middle — `_feature_circles`) and, sorted by
    circle pair, which contact joins them. Contacts on lines are not in them, nor one joining two
    circles of the same body (or two fixed ones): the broad phase skips such pairs unlooked."""
    disk_id, disks, bodies, keys, owners = {}, [], [], [], []
    rows, ints = table.tolist(), index.tolist()  # Python floats and ints: cheapest to read one by one
    for i, (kind, body_a, body_b) in enumerate(ints):
        circles = _feature_circles(kind, rows[i], body_a, body_b)
        if circles is None or circles[0][0] == circles[1][0]:
            continue
        ends = []
        for circle in circles:
            disk = (int(circle[0]), *(float(x) for x in circle[1:]))
            if disk not in disk_id:
                disk_id[disk] = len(disks)
                disks.append(disk[1:])
                bodies.append(disk[0])
            ends.append(disk_id[disk])
        keys.append(ends)
        owners.append(i)
    if not keys:  # contacts on lines only (most small scenes): no broad phase
        empty = np.zeros(0, dtype=np.int64)
        return np.zeros((0, 3)), empty, empty.copy(), empty.copy()
    n = len(disks)
    flat = np.array([min(a, b) * n + max(a, b) for a, b in keys], dtype=np.int64)
    order = np.argsort(flat, kind="stable")
    return (np.array(disks, dtype=float).reshape(-1, 3), np.array(bodies, dtype=np.int64), flat[order],
            np.array(owners, dtype=np.int64)[order])


def pack_drives(scene, table, index, minv):
    """The motions of the driven obstacles (their contacts' C_MOTION, C_BASE_P*) and bodies (their
    M⁻¹ rows zero: infinite mass): (motions, motion table, times, values, driven (body, motion))."""
    motions, number = [], {}

    def motion_index(motion):
        if id(motion) not in number:
            number[id(motion)] = len(motions)
            motions.append(motion)
        return number[id(motion)]

    table[:, C_MOTION] = -1.0
    for i, c in enumerate(scene.contacts):
        if getattr(c, "obstacle_motion", None) is not None:
            table[i, C_MOTION] = motion_index(c.obstacle_motion)
            table[i, C_BASE_PX], table[i, C_BASE_PY] = table[i, C_LINE_PX], table[i, C_LINE_PY]
    driven = np.array([(d.body, motion_index(d.motion)) for d in scene.driven], dtype=np.int64).reshape(-1, 2)
    for body in driven[:, 0]:
        minv[3 * body: 3 * body + 3] = 0.0
    for i, c in enumerate(scene.contacts if driven.size else ()):  # M⁻¹ = 0 only where driven
        if all(minv[3 * b] == 0.0 for b in index[i, CI_BODY_A:CI_BODY_B + 1] if b >= 0):
            raise InputError(f"contact {c.name}: every body it touches is driven, so nothing it pushes can move")
    return (motions, *pack_motions(motions), driven)


def pack_scene(scene) -> PackedScene:
    table, index = pack_contacts(scene.contacts, len(scene.bodies))
    forces = pack_forces(getattr(scene, "forces", ()))
    if forces[1].size and int(forces[1][:, 1:3].max()) >= len(scene.bodies):
        raise InputError(f"forces: a body index is beyond the scene's {len(scene.bodies)} bodies")
    minv = np.array(scene.inverse_mass_diagonal, dtype=float)
    drives = pack_drives(scene, table, index, minv)
    return PackedScene(minv, np.ascontiguousarray(scene.weight, dtype=float), table, index, *forces,
                       *pack_disk_pairs(table, index), *drives)


@jit_borrowing
def contact_kinematics(table, index, i, q, v, hn, ht):
    """(gap, Ḣ_N v) of packed contact i; fills its 6-entry Jacobian rows hn, ht. Compiled without
    reference counting, and so are the kernels compiled into it: they only read and write the
    arrays they are given, and counting the row and arrays each small kernel function takes
    was half of a vertex–edge contact's cost (a tower of 5 boxes, 52 kinematics a step)."""
    gap, drift_n, _ = kinematics_kernel(index[i, CI_KIND], table[i], index[i, CI_BODY_A], index[i, CI_BODY_B],
                                        q, v, hn, ht)
    return gap, drift_n


@jit
def drive_contacts(table, now):
    """Each driven obstacle's contact rows at this step: its place at the step's start (C_LINE_P*)
    and its velocity at the step's end and start (C_OBSTACLE_V*, C_OBSTACLE_START_V*), from the
    motions' evaluation `now`."""
    for i in range(table.shape[0]):
        m = int(table[i, C_MOTION])
        if m >= 0:
            table[i, C_LINE_PX] = table[i, C_BASE_PX] + now[m, NOW_START]
            table[i, C_LINE_PY] = table[i, C_BASE_PY] + now[m, NOW_START + 1]
            table[i, C_OBSTACLE_VX] = now[m, NOW_VELOCITY]
            table[i, C_OBSTACLE_VY] = now[m, NOW_VELOCITY + 1]
            table[i, C_OBSTACLE_START_VX] = now[m, NOW_START_VELOCITY]
            table[i, C_OBSTACLE_START_VY] = now[m, NOW_START_VELOCITY + 1]


@jit
def local_dot(h_row, index, i, x):
    """A contact's 6-entry Jacobian row times a scene vector x (n_dof)."""
    j = 3 * index[i, CI_BODY_A]
    s = h_row[0] * x[j] + h_row[1] * x[j + 1] + h_row[2] * x[j + 2]
    b = index[i, CI_BODY_B]
    if b >= 0:
        j = 3 * b
        s += h_row[3] * x[j] + h_row[4] * x[j + 1] + h_row[5] * x[j + 2]
    return s


@jit_borrowing
def row_dot(rows, index, i, x):
    """local_dot of contact i's row of `rows` (n_contacts × 6), without a view of the row: the
    per-step kernels call it for every contact (a row view costs a reference count)."""
    j = 3 * index[i, CI_BODY_A]
    s = rows[i, 0] * x[j] + rows[i, 1] * x[j + 1] + rows[i, 2] * x[j + 2]
    b = index[i, CI_BODY_B]
    if b >= 0:
        j = 3 * b
        s += rows[i, 3] * x[j] + rows[i, 4] * x[j + 1] + rows[i, 5] * x[j + 2]
    return s


__all__ = ["PackedScene", "pack_scene", "pack_contacts", "contact_kinematics", "local_dot", "row_dot",
           "KIND_DISK_ON_LINE", "KIND_DISK_ON_DISK", "KIND_DISK_ON_SEGMENT"]
