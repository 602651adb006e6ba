"""A scene as arrays: what the compiled Moreau–Jean loop reads.

`pack_scene(scene)` gives a PackedScene: the mass diagonal, the weight, one row per contact
(float64 geometry and law, int64 kind and bodies) and the applied forces as tables
(model.forces.pack_forces). `contact_kinematics` evaluates one packed contact — gap, normal
drift Ḣ_N v and its Jacobian rows restricted to the (at most two) bodies it touches:
six entries, (ẋ, ẏ, θ̇) of body a then of body b (zero when the obstacle is a line) — so that a
step's cost grows with its contacts, not with contacts × degrees of freedom.

The formulas are those of model/contacts.py (DiskOnLine, DiskOnDisk); tests hold the two to
each other.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._jit import jit
from ..validation import InputError
from .contacts import DiskOnDisk, DiskOnLine
from .forces import pack_forces

KIND_DISK_ON_LINE, KIND_DISK_ON_DISK = 0, 1
# Float columns of the contact table.
(C_OFF_AX, C_OFF_AY, C_RADIUS_A, C_OFF_BX, C_OFF_BY, C_RADIUS_B, C_LINE_PX, C_LINE_PY, C_NX, C_NY, C_TX,
 C_TY, C_SURFACE_VELOCITY, C_MU_S, C_MU_D, C_RESTITUTION) = range(16)
N_CONTACT_COLUMNS = 16
# Int columns: kind, body a, body b (−1 for a line).
CI_KIND, CI_BODY_A, CI_BODY_B = range(3)


@dataclass
class PackedScene:
    minv: np.ndarray  # (n_dof,) inverse mass diagonal
    weight: np.ndarray  # (n_dof,) gravity
    contacts: np.ndarray  # (nc, 16) float64
    contact_index: np.ndarray  # (nc, 3) int64
    force_table: np.ndarray
    force_index: np.ndarray
    force_times: np.ndarray
    force_values: np.ndarray
    disks: np.ndarray  # (n_disks, 3): body-frame offset x, y and radius of every disk in a disk–disk contact
    disk_body: np.ndarray  # (n_disks,) int64
    pair_keys: np.ndarray  # (n_pairs,) int64 sorted: min(disk a, disk b) · n_disks + max(...)
    pair_contact: np.ndarray  # (n_pairs,) int64: the contact of each key

    @property
    def n_contacts(self) -> int:
        return self.contacts.shape[0]


def pack_contacts(contacts, n_bodies: int) -> tuple[np.ndarray, np.ndarray]:
    table = np.zeros((len(contacts), N_CONTACT_COLUMNS))
    index = np.zeros((len(contacts), 3), dtype=np.int64)
    for i, c in enumerate(contacts):
        row = table[i]
        friction, impact = c.law.friction, c.law.impact
        row[C_MU_S], row[C_MU_D], row[C_RESTITUTION] = friction.mu_s, friction.mu_d, impact.restitution
        if isinstance(c, DiskOnLine):
            index[i] = (KIND_DISK_ON_LINE, c.body, -1)
            row[C_OFF_AX], row[C_OFF_AY] = c.offset
            row[C_RADIUS_A] = c.radius
            row[C_LINE_PX], row[C_LINE_PY] = c.line.point
            row[C_NX], row[C_NY] = c.line.normal
            row[C_TX], row[C_TY] = c.line.tangent
            row[C_SURFACE_VELOCITY] = c.line.velocity
        elif isinstance(c, DiskOnDisk):
            index[i] = (KIND_DISK_ON_DISK, c.body_a, c.body_b)
            row[C_OFF_AX], row[C_OFF_AY] = c.offset_a
            row[C_OFF_BX], row[C_OFF_BY] = c.offset_b
            row[C_RADIUS_A], row[C_RADIUS_B] = c.radius_a, c.radius_b
        else:
            raise InputError(f"contact {i} ({getattr(c, 'name', '?')}): the engine takes DiskOnLine, "
                             f"PointOnLine and DiskOnDisk contacts, got {type(c).__name__}")
        if max(index[i, CI_BODY_A], index[i, CI_BODY_B]) >= n_bodies:
            raise InputError(f"contact {c.name}: body index beyond the scene's {n_bodies} bodies")
    return table, index


def pack_disk_pairs(table, index):
    """The broad phase's tables: the distinct disks of the disk–disk contacts and, sorted by
    disk pair, which contact joins them."""
    disk_id, disks, bodies, keys, owners = {}, [], [], [], []
    for i in np.flatnonzero(index[:, CI_KIND] == KIND_DISK_ON_DISK):
        ends = []
        for body, columns in ((index[i, CI_BODY_A], (C_OFF_AX, C_OFF_AY, C_RADIUS_A)),
                              (index[i, CI_BODY_B], (C_OFF_BX, C_OFF_BY, C_RADIUS_B))):
            disk = (int(body), *(float(table[i, c]) for c in columns))
            if disk not in disk_id:
                disk_id[disk] = len(disks)
                disks.append(disk[1:])
                bodies.append(disk[0])
            ends.append(disk_id[disk])
        keys.append(ends)
        owners.append(i)
    n = len(disks)
    flat = np.array([min(a, b) * n + max(a, b) for a, b in keys], dtype=np.int64)
    order = np.argsort(flat, kind="stable")
    return (np.array(disks, dtype=float).reshape(-1, 3), np.array(bodies, dtype=np.int64), flat[order],
            np.array(owners, dtype=np.int64)[order])


def pack_scene(scene) -> PackedScene:
    table, index = pack_contacts(scene.contacts, len(scene.bodies))
    forces = pack_forces(getattr(scene, "forces", ()))
    if forces[1].size and int(forces[1][:, 1:3].max()) >= len(scene.bodies):
        raise InputError(f"forces: a body index is beyond the scene's {len(scene.bodies)} bodies")
    return PackedScene(np.ascontiguousarray(scene.inverse_mass_diagonal, dtype=float),
                       np.ascontiguousarray(scene.weight, dtype=float), table, index, *forces,
                       *pack_disk_pairs(table, index))


@jit
def _disk_on_line(row, body, q, v, hn, ht):
    j = 3 * body
    c, s = math.cos(q[j + 2]), math.sin(q[j + 2])
    ox, oy = row[C_OFF_AX], row[C_OFF_AY]
    dx, dy = c * ox - s * oy, s * ox + c * oy
    nx, ny, tx, ty, r = row[C_NX], row[C_NY], row[C_TX], row[C_TY], row[C_RADIUS_A]
    rho_x, rho_y = dx - r * nx, dy - r * ny
    gap = nx * (q[j] + dx - row[C_LINE_PX]) + ny * (q[j + 1] + dy - row[C_LINE_PY]) - r
    hn[0], hn[1], hn[2] = nx, ny, rho_x * ny - rho_y * nx
    ht[0], ht[1], ht[2] = tx, ty, rho_x * ty - rho_y * tx
    for d in range(3, 6):
        hn[d] = 0.0
        ht[d] = 0.0
    om = v[j + 2]
    return gap, -om * om * (dx * nx + dy * ny)


@jit
def _disk_on_disk(row, body_a, body_b, q, v, hn, ht):
    ia, ib = 3 * body_a, 3 * body_b
    ca, sa = math.cos(q[ia + 2]), math.sin(q[ia + 2])
    cb, sb = math.cos(q[ib + 2]), math.sin(q[ib + 2])
    dax = ca * row[C_OFF_AX] - sa * row[C_OFF_AY]
    day = sa * row[C_OFF_AX] + ca * row[C_OFF_AY]
    dbx = cb * row[C_OFF_BX] - sb * row[C_OFF_BY]
    dby = sb * row[C_OFF_BX] + cb * row[C_OFF_BY]
    ex, ey = q[ia] + dax - q[ib] - dbx, q[ia + 1] + day - q[ib + 1] - dby
    dist = math.sqrt(ex * ex + ey * ey)
    if dist == 0.0:  # coincident centres: no normal; the caller reports it
        return math.nan, math.nan
    nx, ny = ex / dist, ey / dist
    tx, ty = ny, -nx
    ra, rb = row[C_RADIUS_A], row[C_RADIUS_B]
    rax, ray = dax - ra * nx, day - ra * ny
    rbx, rby = dbx + rb * nx, dby + rb * ny
    hn[0], hn[1], hn[2] = nx, ny, rax * ny - ray * nx
    hn[3], hn[4], hn[5] = -nx, -ny, -(rbx * ny - rby * nx)
    ht[0], ht[1], ht[2] = tx, ty, rax * ty - ray * tx
    ht[3], ht[4], ht[5] = -tx, -ty, -(rbx * ty - rby * tx)
    om_a, om_b = v[ia + 2], v[ib + 2]
    wx = v[ia] - om_a * day - v[ib] + om_b * dby
    wy = v[ia + 1] + om_a * dax - v[ib + 1] - om_b * dbx
    w_n = wx * nx + wy * ny
    drift = (-om_a * om_a * (dax * nx + day * ny) + om_b * om_b * (dbx * nx + dby * ny)
             + (wx * wx + wy * wy - w_n * w_n) / dist)
    return dist - ra - rb, drift


@jit
def contact_kinematics(table, index, i, q, v, hn, ht):
    """(gap, Ḣ_N v) of packed contact i; fills its 6-entry Jacobian rows hn, ht."""
    if index[i, CI_KIND] == KIND_DISK_ON_LINE:
        return _disk_on_line(table[i], index[i, CI_BODY_A], q, v, hn, ht)
    return _disk_on_disk(table[i], index[i, CI_BODY_A], index[i, CI_BODY_B], q, v, hn, ht)


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


__all__ = ["PackedScene", "pack_scene", "pack_contacts", "contact_kinematics", "local_dot",
           "KIND_DISK_ON_LINE", "KIND_DISK_ON_DISK"]
