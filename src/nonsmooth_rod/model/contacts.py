"""Contact relations: gap functions and their Jacobians (Siconos' "relations").

A relation maps the generalised velocity v of the scene (3 entries per body: ẋ, ẏ, θ̇ of the
centre of mass) to the local velocities of one contact,

    u_N = H_N · v,        u_T = H_T · v − (tangential velocity of the obstacle),

and gives the gap g (≥ 0 when separated) and the velocity-product terms Ḣ v that an
acceleration-level (event-driven) formulation needs: g̈ = H_N · a + Ḣ_N v.
The obstacle is a fixed straight line (horizontal or inclined), possibly moving along itself
(a conveyor belt), a fixed finite segment, or the disk of another body.

The numbers come from model/contact_kernels.py, the one implementation the compiled
Moreau–Jean loop reads too: each relation writes its geometry as a packed row (`fill_row`) and
its `kinematics` calls the kernel of its kind with that row.
"""
from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, field

import numpy as np

from ..validation import InputError, require_finite, require_index, require_nonnegative, require_point
from .contact_kernels import (C_LINE_PX, C_LINE_PY, C_NX, C_NY, C_OFF_AX, C_OFF_AY, C_OFF_BX, C_OFF_BY,
                              C_RADIUS_A, C_RADIUS_B, C_SEGMENT_LENGTH, C_SURFACE_VELOCITY, C_TX, C_TY,
                              C_EDGE_TX, C_EDGE_TY, KIND_DISK_ON_DISK, KIND_DISK_ON_LINE, KIND_DISK_ON_SEGMENT,
                              KIND_SEGMENT_END_ON_EDGE, N_CONTACT_COLUMNS, kinematics_kernel, C_CONE_1X,
                              C_CONE_1Y, C_CONE_2X, C_CONE_2Y, C_DEPTH_LIMIT, C_TIE_WINS, KIND_VERTEX_ON_EDGE,
                              KIND_FIXED_VERTEX_ON_EDGE, C_OBSTACLE_VX, C_OBSTACLE_VY,
                              C_OBSTACLE_START_VX, C_OBSTACLE_START_VY, obstacle_velocity, C_PREV_NX,
                              C_PREV_NY, C_NEXT_NX, C_NEXT_NY, C_LINEAR_GAP0, C_LINEAR_N, C_LINEAR_T,
                              KIND_LINEAR, vertex_on_edge_region)
from .motion import require_motion
from .laws import ContactLaw


@dataclass(frozen=True)
class Line:
    """A fixed straight obstacle through `point`, bodies staying on the side its normal points to.

    `angle` is the inclination of the line to +x (radians, counter-clockwise); the normal is the
    tangent turned by +90°, so angle = 0 is the floor y = point[1] with normal +y and tangent +x.
    `velocity` lets the surface move along its tangent (a belt) without moving the line;
    `motion` (model/motion.py: Harmonic, Tabulated, Prescribed) translates the line in time
    (a shaken floor), d(t) from `point`.
    """

    point: tuple[float, float] = (0.0, 0.0)
    angle: float = 0.0
    velocity: float = 0.0
    motion: object = None

    def __post_init__(self):
        require_finite("line angle", self.angle)
        require_finite("line velocity", self.velocity)
        object.__setattr__(self, "point", require_point("line point", self.point))
        require_motion("line", self.motion, (2,))

    @property
    def tangent(self) -> tuple[float, float]:
        return (math.cos(self.angle), math.sin(self.angle))

    @property
    def normal(self) -> tuple[float, float]:
        return (-math.sin(self.angle), math.cos(self.angle))


@dataclass(frozen=True)
class Segment:
    """A fixed finite straight obstacle from `a` to `b` (world frame): a table top, a step.

    Its tangent runs from a to b and its normal is the tangent turned by +90° (a → b along +x:
    normal +y); a disk touches the side it is on, or an end point when it is beyond one.
    `motion` (model/motion.py) translates it in time, d(t) from its placement.
    """

    a: tuple[float, float]
    b: tuple[float, float]
    name: str = "segment"
    motion: object = None

    def __post_init__(self):
        require_motion(f"segment {self.name!r}", self.motion, (2,))
        object.__setattr__(self, "a", require_point(f"segment {self.name!r} a", self.a))
        object.__setattr__(self, "b", require_point(f"segment {self.name!r} b", self.b))
        if self.length == 0.0:
            raise InputError(f"segment {self.name!r}: a and b coincide (a segment of length 0)")

    @property
    def length(self) -> float:
        return math.hypot(self.b[0] - self.a[0], self.b[1] - self.a[1])

    @property
    def tangent(self) -> tuple[float, float]:
        n = self.length
        return ((self.b[0] - self.a[0]) / n, (self.b[1] - self.a[1]) / n)

    @property
    def normal(self) -> tuple[float, float]:
        t = self.tangent
        return (-t[1], t[0])


def _contact_name(name) -> str:
    if not isinstance(name, str) or not name:
        raise InputError(f"a contact name must be a non-empty string, got {name!r}")
    return name


def _require_type(name: str, value, cls) -> None:
    if not isinstance(value, cls):
        raise InputError(f"{name} must be a {cls.__name__}, got {type(value).__name__}")


@dataclass
class ContactKinematics:
    """Everything a step needs from one contact at the current configuration."""

    gap: float
    H_N: np.ndarray  # row over the scene's generalised velocity
    H_T: np.ndarray
    drift_N: float  # Ḣ_N v
    drift_T: float  # Ḣ_T v
    surface_velocity: float = 0.0  # subtracted from H_T v to get the slip velocity
    normal_velocity: float = 0.0  # a driven obstacle's, subtracted from H_N v to get u_N


# Each relation's packed row, by id, beside a weak reference that tells a live relation from a
# dead one whose id was reused. Kept out of the instances so that their __dict__ stays their
# fields (type(c)(**c.__dict__) copies a relation).
_PACKED_ROWS: dict = {}
# Field assignments of any relation so far: a packed scene kept for the runs that repeat it
# (integrators/scene_plans.py) is packed again when this moved since it was packed.
_changes = 0


def relation_changes() -> int:
    """How many relation fields have been set in this process (any change of any relation)."""
    return _changes


def _forget_row(ref, key) -> None:
    entry = _PACKED_ROWS.get(key)
    if entry is not None and entry[0] is ref:
        del _PACKED_ROWS[key]


class _PackedRelation:
    """What every relation shares: its packed row (written by `fill_row`, kept until a field
    changes) and `kinematics` from the kernel of its kind."""

    _no_normal = "the contact normal is undefined"

    def __setattr__(self, name, value):
        global _changes
        object.__setattr__(self, name, value)
        _PACKED_ROWS.pop(id(self), None)  # any change of geometry re-packs
        _changes += 1

    def _packed_row(self):
        entry = _PACKED_ROWS.get(id(self))
        if entry is not None and entry[0]() is self:
            return entry[1]
        row = [0.0] * N_CONTACT_COLUMNS  # a list: the kernel's scalar reads are cheapest there
        kind, body_a, body_b = self.fill_row(row)
        key = id(self)
        ref = weakref.ref(self, lambda r, key=key: _forget_row(r, key))
        _PACKED_ROWS[key] = (ref, (kind, body_a, body_b, row))
        return kind, body_a, body_b, row

    obstacle_motion = None  # a driven obstacle's motion (model/motion.py), by the relations that have one

    def kinematics(self, q, v, n_dof: int, t: float | None = None) -> ContactKinematics:
        """The kernel of this contact's kind at (q, v): arrays, or lists (Scene.kinematics hands
        lists, converted once for all contacts: the interpreter reads Python floats fastest).
        A driven obstacle is taken at its place and velocity at time t (at rest when t is None)."""
        kind, body_a, body_b, row = self._packed_row()
        if t is not None and self.obstacle_motion is not None:
            row = list(row)
            d, w = self.obstacle_motion.at(t)
            row[C_LINE_PX], row[C_LINE_PY] = row[C_LINE_PX] + d[0], row[C_LINE_PY] + d[1]
            row[C_OBSTACLE_VX], row[C_OBSTACLE_VY] = w[0], w[1]  # (at_start reads the same: one instant)
            row[C_OBSTACLE_START_VX], row[C_OBSTACLE_START_VY] = w[0], w[1]
        q = q if isinstance(q, list) else np.asarray(q, dtype=float).tolist()
        v = v if isinstance(v, list) else np.asarray(v, dtype=float).tolist()
        hn, ht = [0.0] * 6, [0.0] * 6
        gap, drift_n, drift_t = kinematics_kernel(kind, row, body_a, body_b, q, v, hn, ht)
        if math.isnan(gap):
            raise InputError(f"{self.name}: {self._no_normal}")
        H_N, H_T = np.zeros(n_dof), np.zeros(n_dof)
        for side, body in enumerate((body_a, body_b)):
            for d in range(3 if body >= 0 else 0):  # element by element: cheaper than a slice
                H_N[3 * body + d], H_T[3 * body + d] = hn[3 * side + d], ht[3 * side + d]
        w_n, w_t = obstacle_velocity(hn[0], hn[1], ht[0], ht[1], row[C_OBSTACLE_VX], row[C_OBSTACLE_VY],
                                     row[C_SURFACE_VELOCITY])  # n, t: hn[0:2], ht[0:2] (body a's side)
        return ContactKinematics(gap, H_N, H_T, drift_n, drift_t, w_t, w_n)

    def geometry_scale(self) -> float:
        """The size of this contact's geometry (m): its points' largest coordinates, its radii and
        its segment's or edge's length, summed — the scale of its gap's round-off."""
        row = self._packed_row()[3]
        points = sum(max(abs(row[x]), abs(row[y])) for x, y in ((C_OFF_AX, C_OFF_AY), (C_OFF_BX, C_OFF_BY),
                                                                (C_LINE_PX, C_LINE_PY)))
        return points + row[C_RADIUS_A] + row[C_RADIUS_B] + row[C_SEGMENT_LENGTH]

    def region(self, q, v) -> tuple[float, float]:
        """(gap, margin): the gap whether or not this pair of features is the touching one, and
        how far inside the region where it is (≥ 0: it is; the kernel's own rule,
        `contact_kernels.vertex_on_edge_region`). A relation whose gap is finite everywhere
        (a disk on a line, a segment, a disk) is always in its region: margin +inf. Fixed
        obstacles at rest (the event-driven reference, which refuses driven ones)."""
        kind, body_a, body_b, row = self._packed_row()
        q = q if isinstance(q, list) else np.asarray(q, dtype=float).tolist()
        v = v if isinstance(v, list) else np.asarray(v, dtype=float).tolist()
        hn, ht = [0.0] * 6, [0.0] * 6
        if kind == KIND_VERTEX_ON_EDGE:
            return vertex_on_edge_region(row, body_a, body_b, q, v, hn, ht)[::3]
        if kind == KIND_FIXED_VERTEX_ON_EDGE:
            return vertex_on_edge_region(row, -1, body_a, q, v, hn, ht)[::3]
        return kinematics_kernel(kind, row, body_a, body_b, q, v, hn, ht)[0], math.inf


def _fill_disk_a(row, offset, radius) -> None:
    row[C_OFF_AX], row[C_OFF_AY] = offset
    row[C_RADIUS_A] = radius


def _check_disk_on(contact, obstacle: str, obstacle_type) -> None:
    """The fields a body's disk (or point) against a fixed obstacle shares, checked and converted."""
    contact.name = _contact_name(contact.name)
    contact.body = require_index(f"contact {contact.name!r} body", contact.body)
    contact.offset = require_point(f"contact {contact.name!r} offset", contact.offset)
    contact.radius = require_nonnegative(f"contact {contact.name!r} radius", contact.radius)
    _require_type(f"contact {contact.name!r} {obstacle}", getattr(contact, obstacle), obstacle_type)
    _require_type(f"contact {contact.name!r} law", contact.law, ContactLaw)


@dataclass
class DiskOnLine(_PackedRelation):
    """A disk (ball) of radius `radius` fixed on `body` touching a fixed Line.

    `offset` is the disk centre in the body frame, relative to the centre of mass; a radius of
    zero makes it a point (a corner). Name the contact for output ("A", "B", "corner-left", ...).
    """

    body: int
    offset: tuple[float, float]
    line: Line = field(default_factory=Line)
    radius: float = 0.0
    law: ContactLaw = field(default_factory=ContactLaw)
    name: str = "contact"

    def __post_init__(self):
        _check_disk_on(self, "line", Line)

    @property
    def bodies(self) -> tuple[int, ...]:
        return (self.body,)

    @property
    def obstacle_motion(self):
        return self.line.motion

    def fill_row(self, row) -> tuple[int, int, int]:
        """Writes the geometry into a packed row; returns (kind, body a, body b)."""
        _fill_disk_a(row, self.offset, self.radius)
        row[C_LINE_PX], row[C_LINE_PY] = self.line.point
        row[C_NX], row[C_NY] = self.line.normal
        row[C_TX], row[C_TY] = self.line.tangent
        row[C_SURFACE_VELOCITY] = self.line.velocity
        return KIND_DISK_ON_LINE, self.body, -1


def PointOnLine(body: int, offset, line: Line | None = None, law: ContactLaw | None = None, name="corner"):
    """A body-fixed point (a corner) touching a line: a disk of radius zero."""
    return DiskOnLine(body, tuple(offset), line or Line(), 0.0, law or ContactLaw(), name)


@dataclass
class DiskOnSegment(_PackedRelation):
    """A disk of radius `radius` fixed on `body` (centre `offset`, body frame) touching a fixed
    Segment: its interior (normal: the segment's normal on the disk's side) or its end point
    nearest the disk (normal: from the end point to the disk centre), whichever is nearest —
    the two meet continuously. Beyond an end by more than the radius, the contact is open.
    A radius of zero makes it a body point (a corner)."""

    body: int
    offset: tuple[float, float]
    segment: Segment
    radius: float = 0.0
    law: ContactLaw = field(default_factory=ContactLaw)
    name: str = "contact"

    _no_normal = "the disk centre is on the segment's end point, the contact normal is undefined"

    def __post_init__(self):
        _check_disk_on(self, "segment", Segment)

    @property
    def bodies(self) -> tuple[int, ...]:
        return (self.body,)

    @property
    def obstacle_motion(self):
        return self.segment.motion

    def fill_row(self, row) -> tuple[int, int, int]:
        """Writes the geometry into a packed row; returns (kind, body a, body b)."""
        _fill_disk_a(row, self.offset, self.radius)
        row[C_LINE_PX], row[C_LINE_PY] = self.segment.a
        row[C_NX], row[C_NY] = self.segment.normal
        row[C_TX], row[C_TY] = self.segment.tangent
        row[C_SEGMENT_LENGTH] = self.segment.length
        return KIND_DISK_ON_SEGMENT, self.body, -1


def PointOnSegment(body: int, offset, segment: Segment, law: ContactLaw | None = None, name="corner"):
    """A body-fixed point (a corner) touching a segment: a disk of radius zero."""
    return DiskOnSegment(body, tuple(offset), segment, 0.0, law or ContactLaw(), name)


@dataclass
class SegmentEndOnEdge(_PackedRelation):
    """An end point (`end`: "a" or "b") of a fixed Segment against the straight edge of `body`
    from `edge_start` to `edge_end` (body frame, the body on the edge's left: a counter-clockwise
    outline), e.g. a table's edge under a box's bottom. Beyond the edge's ends the edge's nearest
    end (the body's corner) touches the point; declare that corner's own contact with the
    segment beside this one."""

    body: int
    edge_start: tuple[float, float]
    edge_end: tuple[float, float]
    segment: Segment
    end: str = "b"
    law: ContactLaw = field(default_factory=ContactLaw)
    name: str = "edge"

    _no_normal = "the segment's end point is on the body's corner, the contact normal is undefined"

    def __post_init__(self):
        self.name = _contact_name(self.name)
        self.body = require_index(f"contact {self.name!r} body", self.body)
        self.edge_start = require_point(f"contact {self.name!r} edge_start", self.edge_start)
        self.edge_end = require_point(f"contact {self.name!r} edge_end", self.edge_end)
        _require_type(f"contact {self.name!r} segment", self.segment, Segment)
        _require_type(f"contact {self.name!r} law", self.law, ContactLaw)
        if self.end not in ("a", "b"):
            raise InputError(f"contact {self.name!r} end must be 'a' or 'b' (which end of the segment), "
                             f"got {self.end!r}")
        if self.edge_start == self.edge_end:
            raise InputError(f"contact {self.name!r}: edge_start and edge_end coincide (an edge of length 0)")

    @property
    def bodies(self) -> tuple[int, ...]:
        return (self.body,)

    @property
    def obstacle_motion(self):
        return self.segment.motion

    def fill_row(self, row) -> tuple[int, int, int]:
        """Writes the geometry into a packed row; returns (kind, body a, body b)."""
        _fill_disk_a(row, self.edge_start, 0.0)
        row[C_LINE_PX], row[C_LINE_PY] = self.segment.a if self.end == "a" else self.segment.b
        length = math.hypot(self.edge_end[0] - self.edge_start[0], self.edge_end[1] - self.edge_start[1])
        row[C_EDGE_TX] = (self.edge_end[0] - self.edge_start[0]) / length
        row[C_EDGE_TY] = (self.edge_end[1] - self.edge_start[1]) / length
        row[C_SEGMENT_LENGTH] = length
        return KIND_SEGMENT_END_ON_EDGE, self.body, -1


@dataclass
class DiskOnDisk(_PackedRelation):
    """Disk `offset_a`/`radius_a` of body a against disk `offset_b`/`radius_b` of body b.

    The normal points from b's disk centre to a's; the tangent is the normal turned by −90°.
    """

    body_a: int
    body_b: int
    radius_a: float
    radius_b: float
    offset_a: tuple[float, float] = (0.0, 0.0)
    offset_b: tuple[float, float] = (0.0, 0.0)
    law: ContactLaw = field(default_factory=ContactLaw)
    name: str = "disk-disk"

    _no_normal = "disk centres coincide, the contact normal is undefined"

    def __post_init__(self):
        self.name = _contact_name(self.name)
        self.body_a = require_index(f"contact {self.name!r} body_a", self.body_a)
        self.body_b = require_index(f"contact {self.name!r} body_b", self.body_b)
        self.radius_a = require_nonnegative(f"contact {self.name!r} radius_a", self.radius_a)
        self.radius_b = require_nonnegative(f"contact {self.name!r} radius_b", self.radius_b)
        self.offset_a = require_point(f"contact {self.name!r} offset_a", self.offset_a)
        self.offset_b = require_point(f"contact {self.name!r} offset_b", self.offset_b)
        _require_type(f"contact {self.name!r} law", self.law, ContactLaw)
        if self.body_a == self.body_b:
            raise InputError(f"contact {self.name!r}: a disk–disk contact joins two different bodies, "
                             f"got body_a = body_b = {self.body_a}")

    @property
    def bodies(self) -> tuple[int, ...]:
        return (self.body_a, self.body_b)

    def fill_row(self, row) -> tuple[int, int, int]:
        """Writes the geometry into a packed row; returns (kind, body a, body b)."""
        _fill_disk_a(row, self.offset_a, self.radius_a)
        row[C_OFF_BX], row[C_OFF_BY] = self.offset_b
        row[C_RADIUS_B] = self.radius_b
        return KIND_DISK_ON_DISK, self.body_a, self.body_b


def _unit(name: str, vec) -> tuple[float, float]:
    x, y = require_point(name, vec)
    norm = math.hypot(x, y)
    if not 0.999999 < norm < 1.000001:
        raise InputError(f"{name} must be a unit vector, got {quoted_point(vec)}")
    return x / norm, y / norm


def quoted_point(vec) -> str:
    return "(" + ", ".join(f"{float(x):g}" for x in vec) + ")"


@dataclass
class VertexOnEdge(_PackedRelation):
    """A vertex (or, with a radius, a disk) of `vertex_body` on the straight edge `edge_start` →
    `edge_end` of `edge_body` — each a body index, or −1 for a fixed obstacle (then its points
    are in the world frame): a box's corner on another box's top, on a table, a table's end
    under a box. The edge belongs to a counter-clockwise outline: its outward normal is its
    direction turned by −90°. The contact counts only while it is the touching pair of features:
    the vertex's foot within the edge, the edge's normal in the vertex's normal `cone` (the
    outward normals of its previous and next edges, vertex owner's frame; None for a disk) and
    a penetration under `depth_limit`; otherwise its gap is infinite (open). At a corner exactly
    on a corner the pair keeps the contact only if `tie_wins` (model/collision.py gives the
    tie to one of the two mirror pairs). `neighbours`: the outward normals of the edge's previous
    and next edges (edge owner's frame; None: the edge stands alone, a segment's side): a point
    that has crossed a neighbour too counts against the least penetrated of them only."""

    vertex_body: int
    vertex: tuple[float, float]
    edge_body: int
    edge_start: tuple[float, float]
    edge_end: tuple[float, float]
    cone: tuple | None = None
    radius: float = 0.0
    tie_wins: bool = True
    depth_limit: float = math.inf
    law: ContactLaw = field(default_factory=ContactLaw)
    name: str = "vertex-edge"
    neighbours: tuple | None = None

    def __post_init__(self):
        self.name = _contact_name(self.name)
        key = f"contact {self.name!r}"
        for attr in ("vertex_body", "edge_body"):
            value = getattr(self, attr)
            setattr(self, attr, -1 if value == -1 else require_index(f"{key} {attr}", value))
        if self.vertex_body == self.edge_body:
            raise InputError(f"{key}: vertex_body and edge_body must differ, both are {self.vertex_body}")
        for attr in ("vertex", "edge_start", "edge_end"):
            setattr(self, attr, require_point(f"{key} {attr}", getattr(self, attr)))
        if self.edge_start == self.edge_end:
            raise InputError(f"{key}: edge_start and edge_end coincide (an edge of length 0)")
        self.radius = require_nonnegative(f"{key} radius", self.radius)
        if self.radius == 0.0:
            if self.cone is None or len(self.cone) != 2:
                raise InputError(f"{key} cone: a vertex needs the outward normals of its two edges")
            self.cone = (_unit(f"{key} cone[0]", self.cone[0]), _unit(f"{key} cone[1]", self.cone[1]))
        if self.neighbours is not None:
            if len(self.neighbours) != 2:
                raise InputError(f"{key} neighbours: the outward normals of the edge's previous and next edges")
            self.neighbours = tuple(_unit(f"{key} neighbours[{k}]", n) for k, n in enumerate(self.neighbours))
        if not (isinstance(self.depth_limit, (int, float)) and self.depth_limit == math.inf):
            self.depth_limit = require_nonnegative(f"{key} depth_limit", self.depth_limit)
        _require_type(f"{key} law", self.law, ContactLaw)

    @property
    def bodies(self) -> tuple[int, ...]:
        return tuple(b for b in (self.vertex_body, self.edge_body) if b >= 0)

    def fill_row(self, row) -> tuple[int, int, int]:
        """Writes the geometry into a packed row; returns (kind, body a, body b)."""
        if self.vertex_body >= 0:
            _fill_disk_a(row, self.vertex, self.radius)
        else:
            row[C_LINE_PX], row[C_LINE_PY] = self.vertex
        row[C_OFF_BX], row[C_OFF_BY] = self.edge_start
        length = math.hypot(self.edge_end[0] - self.edge_start[0], self.edge_end[1] - self.edge_start[1])
        row[C_EDGE_TX] = (self.edge_end[0] - self.edge_start[0]) / length
        row[C_EDGE_TY] = (self.edge_end[1] - self.edge_start[1]) / length
        row[C_SEGMENT_LENGTH] = length
        if self.cone is not None:
            (row[C_CONE_1X], row[C_CONE_1Y]), (row[C_CONE_2X], row[C_CONE_2Y]) = self.cone
        row[C_TIE_WINS] = 1.0 if self.tie_wins else 0.0
        row[C_DEPTH_LIMIT] = self.depth_limit
        if self.neighbours is not None:
            (row[C_PREV_NX], row[C_PREV_NY]), (row[C_NEXT_NX], row[C_NEXT_NY]) = self.neighbours
        if self.vertex_body >= 0:
            return KIND_VERTEX_ON_EDGE, self.vertex_body, self.edge_body
        return KIND_FIXED_VERTEX_ON_EDGE, self.edge_body, -1


def check_linear_row(key: str, row) -> dict:
    """A linear relation's row {body: (x, y, θ coefficients)}, checked: body indices, 3 numbers each."""
    if row is None:
        return {}
    if not isinstance(row, dict):
        raise InputError(f"{key} must map body indices to (x, y, θ) coefficients, got {type(row).__name__}")
    out = {}
    for body, coefficients in row.items():
        body = require_index(f"{key} body", body)
        if isinstance(coefficients, (str, bytes)) or not hasattr(coefficients, "__len__") or len(coefficients) != 3:
            raise InputError(f"{key}[{body}] must be 3 numbers (the x, y, θ coefficients), got {coefficients!r}")
        out[body] = tuple(require_finite(f"{key}[{body}]", c) for c in coefficients)
    return out


@dataclass
class LinearRelation(_PackedRelation):
    """A unilateral contact whose gap is affine in the coordinates (Siconos' LagrangianLinearTIR):
    g(q) = gap0 + Σ_bodies normal[body]·(x, y, θ), with the constant tangential row `tangent`
    (u_T = tangent·v − tangent_velocity). `normal` and `tangent` map a body index to its
    (x, y, θ) coefficients; at most two bodies in all. The law is the same as every contact's
    (μs, μd, restitution). E.g. a body's point at height y on the floor: normal {0: (0, 1, 0)},
    tangent {0: (1, 0, 0)}. The published woodpecker's contacts are of this kind
    (toys/woodpecker.py, geometry="linearised")."""

    normal: dict
    gap0: float = 0.0
    tangent: dict | None = None
    law: ContactLaw = field(default_factory=ContactLaw)
    name: str = "linear"
    tangent_velocity: float = 0.0

    def __post_init__(self):
        self.name = _contact_name(self.name)
        key = f"contact {self.name!r}"
        self.normal = check_linear_row(f"{key} normal", self.normal)
        self.tangent = check_linear_row(f"{key} tangent", self.tangent)
        self.gap0 = require_finite(f"{key} gap0", self.gap0)
        self.tangent_velocity = require_finite(f"{key} tangent_velocity", self.tangent_velocity)
        _require_type(f"{key} law", self.law, ContactLaw)
        if not any(c != 0.0 for w in self.normal.values() for c in w):
            raise InputError(f"{key} normal: the normal row is zero (the gap must depend on some coordinate)")
        if len(self.bodies) > 2:
            raise InputError(f"{key}: a linear relation joins at most two bodies, got {list(self.bodies)}")
        if self.law.friction.mu_s > 0.0 and not any(c != 0.0 for w in self.tangent.values() for c in w):
            raise InputError(f"{key} tangent: a contact with friction (mu_s > 0) needs a non-zero tangent row")

    @property
    def bodies(self) -> tuple[int, ...]:
        return tuple(sorted(set(self.normal) | set(self.tangent)))

    def fill_row(self, row) -> tuple[int, int, int]:
        """Writes the rows into a packed row; returns (kind, body a, body b)."""
        bodies = self.bodies
        for side, body in enumerate(bodies):
            for d in range(3):
                row[C_LINEAR_N + 3 * side + d] = self.normal.get(body, (0.0, 0.0, 0.0))[d]
                row[C_LINEAR_T + 3 * side + d] = self.tangent.get(body, (0.0, 0.0, 0.0))[d]
        row[C_LINEAR_GAP0] = self.gap0
        row[C_SURFACE_VELOCITY] = self.tangent_velocity
        return KIND_LINEAR, bodies[0], bodies[1] if len(bodies) > 1 else -1


# Every contact relation a scene can hold, by the names users write (for error messages).
RELATION_NAMES = ("DiskOnLine", "PointOnLine", "DiskOnSegment", "PointOnSegment", "SegmentEndOnEdge", "DiskOnDisk",
                  "VertexOnEdge", "LinearRelation")
