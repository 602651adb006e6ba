"""Shapes that collide: a body's shape is its collision geometry, and its contacts are found.

Shapes (body frame): `Polygon` (a convex counter-clockwise vertex list; `Polygon.rectangle`)
and `Disk` (a radius at an offset: the rod-with-balls body is two disks). Fixed obstacles are
model.contacts' `Line` (infinite) and `Segment`; `Polyline` is a chain of segments.

`find_contacts(bodies, shapes, obstacles, ...)` lists, for every pair of collidable shapes, the
candidate contacts between their features (the narrow phase is each candidate's kernel, run
every step the broad phase keeps it — moreau_jean_loop.broad_phase, lines_in_reach: a candidate
whose features do not touch has an infinite or positive gap and stays open;
model/contact_kernels.py):

    polygon – polygon   every vertex of each on every edge of the other (VertexOnEdge)
    polygon – line      every vertex on the line (a DiskOnLine of radius 0)
    polygon – segment   every vertex on both sides of the segment; both ends of the segment on
                        every edge of the polygon (VertexOnEdge)
    disk – line / segment / disk     DiskOnLine / DiskOnSegment / DiskOnDisk
    disk – polygon      the disk on every edge (VertexOnEdge with a radius) and on every vertex
                        (DiskOnDisk with radius 0)

A contact is named by its two features, `<feature of a>/<feature of b>`: a body or obstacle's
name, then `.vK` (vertex K), `.eK` (edge K, from vertex K to K + 1), `.sK` (shape K of a body
with several), `.a`, `.b` (a segment's ends), `.side+`, `.side-` (a segment's side its normal
points to, or the other) — e.g. `box1.v2/box2.e0`, `ball/table`, `table.b/box.e0`.
The names are stable: a contact keeps its name (and its column in the outputs) while the same
features touch. At a corner exactly on a corner the two mirror pairs (vertex of a on edge of
b, vertex of b on edge of a) give the same touch: between two bodies, the pair whose vertex
belongs to the body listed later keeps it (a box on the box below it, a tower listed from the
floor up: its bottom corners on the top below, as a hand-written scene declares them — the
same contacts in the same order, so the same Lemke pivots); between a body and an obstacle, the
body's vertex.

Each candidate is one contact of the scene (a column of trajectory.csv, ~25 floats of memory
per kept sample): a box–box pair is 32 candidates, a box on a line 4. Filter pairs that cannot
meet (`never`, `groups`) to keep a large scene's outputs small.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..validation import InputError, require_point, require_positive
from .contacts import DiskOnDisk, DiskOnLine, DiskOnSegment, Line, Segment, SegmentEndOnEdge, VertexOnEdge
from .laws import ContactLaw

# Vertices closer than this (relative to the polygon's size) are repeated; an area below this
# fraction of size² is degenerate; a turn below it (a sine) is a straight angle, not convex.
POLYGON_TOL = 1e-9
# A penetration deeper than this fraction of the thinner shape's width is not the pair touching.
DEPTH_FRACTION = 0.5


@dataclass(frozen=True)
class Polygon:
    """A convex polygon in a body's frame: vertices counter-clockwise, relative to the body's
    centre of mass. Edge k runs from vertex k to vertex k + 1."""

    vertices: tuple
    name: str = "polygon"

    def __post_init__(self):
        key = f"{self.name} vertices"
        try:
            points = tuple(require_point(f"{key}[{k}]", p) for k, p in enumerate(self.vertices))
        except TypeError:
            raise InputError(f"{key} must be a list of [x, y] points, got {self.vertices!r}") from None
        object.__setattr__(self, "vertices", points)
        _check_convex(key, np.array(points, dtype=float).reshape(-1, 2))

    @classmethod
    def rectangle(cls, width: float, height: float, name: str = "rectangle") -> "Polygon":
        """A width × height rectangle centred on the body's centre of mass, sides along its axes."""
        w = require_positive(f"{name} width", width) / 2
        h = require_positive(f"{name} height", height) / 2
        return cls(((-w, -h), (w, -h), (w, h), (-w, h)), name)

    def edge(self, k: int):
        return self.vertices[k], self.vertices[(k + 1) % len(self.vertices)]

    def normal(self, k: int) -> tuple[float, float]:
        """Outward unit normal of edge k (its direction turned by −90°)."""
        (ax, ay), (bx, by) = self.edge(k)
        length = math.hypot(bx - ax, by - ay)
        return (by - ay) / length, -(bx - ax) / length

    def cone(self, k: int):
        """The normal cone of vertex k: the outward normals of its previous and next edges."""
        return self.normal((k - 1) % len(self.vertices)), self.normal(k)

    def neighbours(self, k: int):
        """The outward normals of the edges before and after edge k."""
        n = len(self.vertices)
        return self.normal((k - 1) % n), self.normal((k + 1) % n)

    @property
    def width(self) -> float:
        """The smallest extent across an edge (its thinnest direction)."""
        pts = np.array(self.vertices)
        return min(float(np.max((pts - pts[k]) @ -np.array(self.normal(k)))) for k in range(len(pts)))

    @property
    def reach(self) -> float:
        """Distance of the farthest vertex from the body's centre of mass."""
        return max(math.hypot(x, y) for x, y in self.vertices)


def _check_convex(key: str, pts: np.ndarray) -> None:
    """One line naming the key: fewer than 3 vertices, repeated ones, area 0, clockwise or non-convex."""
    n = len(pts)
    if n < 3:
        raise InputError(f"{key}: a polygon needs at least 3 vertices, got {n}")
    size = float(np.max(np.abs(pts - pts.mean(axis=0)))) or 1.0
    edges = np.roll(pts, -1, axis=0) - pts
    lengths = np.hypot(edges[:, 0], edges[:, 1])
    if lengths.min() <= POLYGON_TOL * size:
        k = int(np.argmin(lengths))
        raise InputError(f"{key}: vertices {k} and {(k + 1) % n} repeat the same point")
    area = 0.5 * float(np.sum(pts[:, 0] * np.roll(pts[:, 1], -1) - np.roll(pts[:, 0], -1) * pts[:, 1]))
    if abs(area) <= POLYGON_TOL * size * size:
        raise InputError(f"{key}: the polygon has area 0 (its vertices are on one line)")
    if area < 0:
        raise InputError(f"{key}: the vertices run clockwise; list them counter-clockwise")
    unit = edges / lengths[:, None]
    turns = unit[:, 0] * np.roll(unit[:, 1], -1) - unit[:, 1] * np.roll(unit[:, 0], -1)
    if turns.min() <= POLYGON_TOL:
        raise InputError(f"{key}: the polygon is not convex (or has a straight angle) at vertex "
                         f"{(int(np.argmin(turns)) + 1) % n}; split a concave body into convex shapes")


@dataclass(frozen=True)
class Disk:
    """A disk of `radius` centred at `offset` in a body's frame."""

    radius: float
    offset: tuple = (0.0, 0.0)

    def __post_init__(self):
        require_positive("disk radius", self.radius)
        object.__setattr__(self, "offset", require_point("disk offset", self.offset))

    @property
    def reach(self) -> float:
        return math.hypot(*self.offset) + self.radius


def Polyline(points, name: str = "polyline") -> dict:
    """A chain of fixed segments through `points` (world frame), named `name.0`, `name.1`, ..."""
    pts = [require_point(f"polyline {name!r} point {k}", p) for k, p in enumerate(points)]
    if len(pts) < 2:
        raise InputError(f"polyline {name!r} needs at least 2 points, got {len(pts)}")
    return {f"{name}.{k}": Segment(a, b, name=f"{name}.{k}") for k, (a, b) in enumerate(zip(pts, pts[1:]))}


class PairLaws:
    """The contact law of a pair of shapes: entries (name a, name b, law), "*" matching any name;
    an entry naming both wins over one naming one, which wins over ("*", "*"); `default`
    otherwise."""

    def __init__(self, entries=(), default: ContactLaw | None = None):
        self.default = default or ContactLaw()
        self.entries = []
        for k, entry in enumerate(entries):
            if len(entry) != 3 or not isinstance(entry[2], ContactLaw):
                raise InputError(f"laws[{k}] must be (name a, name b, ContactLaw), got {entry!r}")
            self.entries.append((str(entry[0]), str(entry[1]), entry[2]))

    def check_names(self, names, key: str = "laws") -> None:
        for k, (a, b, _) in enumerate(self.entries):
            for name in (a, b):
                if name != "*" and name not in names:
                    raise InputError(f"{key}[{k}].between: {name!r} names no body, line or segment")

    def law(self, a: str, b: str) -> ContactLaw:
        best, rank = self.default, -1
        for x, y, law in self.entries:
            for p, q in ((x, y), (y, x)):
                if p in ("*", a) and q in ("*", b):
                    specific = (p != "*") + (q != "*")
                    if specific > rank:
                        best, rank = law, specific
        return best


def _shape_name(body_name: str, k: int, n_shapes: int) -> str:
    return body_name if n_shapes == 1 else f"{body_name}.s{k}"


def polygon_pair_contacts(poly_a, body_a, name_a, poly_b, body_b, name_b, law, tie_to_first=True):
    """Every vertex of polygon a (of body_a) on every edge of polygon b (of body_b) and back; at a
    corner exactly on a corner, the first polygon's vertices keep the tie when tie_to_first."""
    depth = DEPTH_FRACTION * min(poly_a.width, poly_b.width)
    found = []
    for (pv, bv, nv, pe, be, ne, wins, order) in (
            (poly_a, body_a, name_a, poly_b, body_b, name_b, tie_to_first, -1),
            (poly_b, body_b, name_b, poly_a, body_a, name_a, not tie_to_first, 1)):
        # Edge by edge, each edge's vertices of the other polygon: a's from the last, b's from the
        # first. Two faces that touch then give their corners in one direction whichever polygon's
        # corners they are (a CCW outline runs the other way on the facing side): a body listed
        # above the one below it (a tower from the floor up) gives them left to right, as a
        # hand-written scene lists them — Lemke's pivots follow the order (a tower of 5 boxes:
        # 18.7 a step left to right, 25.9 right to left).
        for k in range(len(pe.vertices)):
            for i in range(len(pv.vertices))[::order]:
                vertex = pv.vertices[i]
                found.append(VertexOnEdge(bv, vertex, be, *pe.edge(k), cone=pv.cone(i), tie_wins=wins,
                                          depth_limit=depth, law=law, name=f"{nv}.v{i}/{ne}.e{k}",
                                          neighbours=pe.neighbours(k)))
    return found


def _segment_as_polygon_parts(seg: Segment):
    """A segment as a flat two-sided polygon: its sides (edges with outward normals ±n) and ends
    (vertices with half-plane cones)."""
    n = seg.normal
    minus = (-n[0], -n[1])
    sides = {"side+": (seg.b, seg.a), "side-": (seg.a, seg.b)}
    ends = {"a": (seg.a, (n, minus)), "b": (seg.b, (minus, n))}
    return sides, ends


def _polygon_segment(poly, body, name, seg, seg_name, law):
    if getattr(seg, "motion", None) is not None:  # its vertex–edge rows are fixed geometry
        raise InputError(f"segment {seg_name!r} moves (motion) and a polygon ({name}) collides with it: found "
                         "polygon–segment contacts do not follow a driven segment yet; use a driven line, or "
                         "collide = false and declare point-on-segment contacts")
    depth = DEPTH_FRACTION * poly.width
    sides, ends = _segment_as_polygon_parts(seg)
    found = []
    for i, vertex in enumerate(poly.vertices):
        for side, (start, end) in sides.items():
            found.append((("seg", body, _r(vertex), 0.0, _r(seg.a), _r(seg.b)),
                          VertexOnEdge(body, vertex, -1, start, end, cone=poly.cone(i), tie_wins=True,
                                       depth_limit=depth, law=law, name=f"{name}.v{i}/{seg_name}.{side}")))
    for end_name, (point, cone) in ends.items():
        for k in range(len(poly.vertices)):
            edge = poly.edge(k)
            found.append((("ve", -1, _r(point), body, _r(edge[0]), _r(edge[1]), 0.0),
                          VertexOnEdge(-1, point, body, *edge, cone=cone, tie_wins=False, depth_limit=depth,
                                       law=law, name=f"{seg_name}.{end_name}/{name}.e{k}",
                                       neighbours=poly.neighbours(k))))
    return found


def _disk_polygon(disk, body, name, poly, pbody, pname, law):
    """A disk on every edge of a polygon (while its centre's foot is on the edge) and on every
    vertex (a disk of radius 0): the nearest feature touches."""
    depth = DEPTH_FRACTION * min(poly.width, disk.radius)
    found = [VertexOnEdge(body, disk.offset, pbody, *poly.edge(k), radius=disk.radius, depth_limit=depth, law=law,
                          name=f"{name}/{pname}.e{k}", neighbours=poly.neighbours(k))
             for k in range(len(poly.vertices))]
    if pbody >= 0:
        found += [DiskOnDisk(body, pbody, disk.radius, 0.0, disk.offset, vertex, law, f"{name}/{pname}.v{i}")
                  for i, vertex in enumerate(poly.vertices)]
    return found


def _pair(a, b, law):
    """The candidate contacts between two colliders (name, body or −1, shape or obstacle), a
    listed before b; as (features key, relation)."""
    (na, ba, sa), (nb, bb, sb) = a, b
    if ba < 0:  # an obstacle first: only obstacle–obstacle pairs, which never collide
        return []
    if isinstance(sa, Polygon):
        if isinstance(sb, Polygon):
            # corners on corners: the later body's (a box on the one below it, listed before it)
            return _keyed(polygon_pair_contacts(sa, ba, na, sb, bb, nb, law, tie_to_first=False))
        if isinstance(sb, Disk):
            return _keyed(_disk_polygon(sb, bb, nb, sa, ba, na, law))
        if isinstance(sb, Line):
            return _keyed([DiskOnLine(ba, v, sb, 0.0, law, f"{na}.v{i}/{nb}") for i, v in enumerate(sa.vertices)])
        return _polygon_segment(sa, ba, na, sb, nb, law)
    if isinstance(sb, Polygon):
        return _keyed(_disk_polygon(sa, ba, na, sb, bb, nb, law))
    if isinstance(sb, Disk):
        return _keyed([DiskOnDisk(ba, bb, sa.radius, sb.radius, sa.offset, sb.offset, law, f"{na}/{nb}")])
    if isinstance(sb, Line):
        return _keyed([DiskOnLine(ba, sa.offset, sb, sa.radius, law, f"{na}/{nb}")])
    return _keyed([DiskOnSegment(ba, sa.offset, sb, sa.radius, law, f"{na}/{nb}")])


def _keyed(contacts):
    return [(_declared_key(c), c) for c in contacts]


def _colliders(bodies, shapes, obstacles):
    """(collider name, body index or −1, shape or obstacle, owner name) of every shape, bodies
    first (in the scene's order), then the obstacles."""
    names = [b.name for b in bodies]
    found = []
    for owner, body_shapes in shapes.items():
        if owner not in names:
            raise InputError(f"shapes: {owner!r} names no body (bodies: {', '.join(names)})")
        parts = list(body_shapes) if isinstance(body_shapes, (list, tuple)) else [body_shapes]
        for k, shape in enumerate(parts):
            if not isinstance(shape, (Polygon, Disk)):
                raise InputError(f"shapes[{owner!r}]: a body's shape is a Polygon or a Disk, "
                                 f"got {type(shape).__name__}")
            found.append((_shape_name(owner, k, len(parts)), names.index(owner), shape, owner))
    found.sort(key=lambda c: c[1])
    for owner, obstacle in obstacles.items():
        if not isinstance(obstacle, (Line, Segment)):
            raise InputError(f"obstacles[{owner!r}]: an obstacle is a Line or a Segment, got {type(obstacle).__name__}")
        found.append((owner, -1, obstacle, owner))
    return found


def _filtered(a, b, never, groups) -> bool:
    """True when the pair must not collide: the same body, two obstacles, a `never` pair, or
    one shared group."""
    if a[1] == b[1] or a[1] < 0 and b[1] < 0:
        return True
    for x, y in never:
        if x in ("*", a[3]) and y in ("*", b[3]) or y in ("*", a[3]) and x in ("*", b[3]):
            return True
    ga, gb = groups.get(a[3]), groups.get(b[3])
    return ga is not None and ga == gb


def find_contacts(bodies, shapes: dict, obstacles: dict | None = None, laws: PairLaws | None = None,
                  never=(), groups: dict | None = None, declared=()) -> list:
    """The candidate contacts of every pair of collidable shapes (module docstring).

    `shapes`: body name → a Polygon or Disk, or a list of them (a body left out does not collide);
    `obstacles`: name → Line or Segment; `laws`: the law of each pair by the names of its bodies
    or obstacles; `never`: pairs of names ("*": any) that never collide; `groups`: name → group,
    shapes of one group never collide with each other; `declared`: hand-declared contacts, each
    taking the place of the candidate between the same features (never two contacts for one touch).
    """
    obstacles, groups, laws = dict(obstacles or {}), dict(groups or {}), laws or PairLaws()
    colliders = _colliders(bodies, shapes, obstacles)
    known = {b.name for b in bodies} | set(obstacles)
    laws.check_names(known)
    for k, pair in enumerate(never):
        if len(pair) != 2 or any(x != "*" and x not in known for x in pair):
            raise InputError(f"never[{k}]: {pair!r} must be two names of bodies, lines or segments (or \"*\")")
    taken = {_declared_key(c) for c in declared} - {None}
    found = []
    for i, a in enumerate(colliders):
        for b in colliders[i + 1:]:
            if _filtered(a, b, never, groups):
                continue
            for key, contact in _pair(a[:3], b[:3], laws.law(a[3], b[3])):
                if key not in taken:
                    found.append(contact)
    # By the later body of each pair (stable): body k's contacts with the bodies before it and the
    # obstacles come together, in the order a hand-written scene lists them (each body on what
    # holds it) — the active contacts' order is the solver's (Lemke's pivots follow it).
    found.sort(key=lambda c: max(c.bodies))
    return found


def _r(x):
    """A number or point rounded for comparing the features of two contacts."""
    return tuple(round(float(v), 12) for v in x) if isinstance(x, tuple) else round(float(x), 12)


def _declared_key(c):
    """The features a contact relation joins, as automatic candidates key them."""
    if isinstance(c, DiskOnLine):
        return ("line", c.body, _r(c.offset), _r(c.radius), c.line)
    if isinstance(c, DiskOnSegment):
        return ("seg", c.body, _r(c.offset), _r(c.radius), _r(c.segment.a), _r(c.segment.b))
    if isinstance(c, DiskOnDisk):
        return ("disks", frozenset({(c.body_a, _r(c.offset_a), _r(c.radius_a)),
                                    (c.body_b, _r(c.offset_b), _r(c.radius_b))}))
    if isinstance(c, SegmentEndOnEdge):
        end = c.segment.a if c.end == "a" else c.segment.b
        return ("ve", -1, _r(end), c.body, _r(c.edge_start), _r(c.edge_end), 0.0)
    if isinstance(c, VertexOnEdge):
        return ("ve", c.vertex_body, _r(c.vertex), c.edge_body, _r(c.edge_start), _r(c.edge_end), _r(c.radius))
    return None


def deepest_overlap(bodies, shapes: dict, q, lines=()) -> float:
    """The deepest overlap (m) of any two bodies' polygons, or of a polygon's vertex behind one of
    `lines`, at the configurations q (one row per sample): separating axes over every pair of
    polygons, whatever contacts a scene lists or filters out — a check of a run's physics (no box
    through another or the floor) independent of the contact kernels. 0 when nothing overlaps."""
    polygons = [(k, shapes[b.name]) for k, b in enumerate(bodies) if isinstance(shapes.get(b.name), Polygon)]
    q = np.atleast_2d(np.asarray(q, dtype=float))
    deepest = 0.0
    for row in q:
        world = [_world(p.vertices, row[3 * k: 3 * k + 3]) for k, p in polygons]
        axes = [_edge_normals(w) for w in world]
        for line in lines:
            n, point = np.array(line.normal), np.array(line.point)
            deepest = max(deepest, max(float(np.max((point - w) @ n)) for w in world))
        for a in range(len(world)):
            for b in range(a + 1, len(world)):
                both = np.vstack([axes[a], axes[b]])
                pa, pb = world[a] @ both.T, world[b] @ both.T
                overlap = np.minimum(pa.max(axis=0), pb.max(axis=0)) - np.maximum(pa.min(axis=0), pb.min(axis=0))
                deepest = max(deepest, float(overlap.min()))
    return deepest


def _world(vertices, pose) -> np.ndarray:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    v = np.array(vertices)
    return np.column_stack([pose[0] + c * v[:, 0] - s * v[:, 1], pose[1] + s * v[:, 0] + c * v[:, 1]])


def _edge_normals(world: np.ndarray) -> np.ndarray:
    edges = np.roll(world, -1, axis=0) - world
    return np.column_stack([edges[:, 1], -edges[:, 0]]) / np.hypot(edges[:, 0], edges[:, 1])[:, None]
