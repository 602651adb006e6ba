"""The one contact-kinematics implementation checked against geometry and calculus: for every kind
of contact, on random states, the gap is the distance the geometry gives, H_N·v is the time
derivative of the gap, H_T·v the slip velocity of the touching material points, and the drifts
Ḣ_N v, Ḣ_T v the derivatives of H_N·v, H_T·v along q̇ = v (central finite differences,
tolerances relative to the quantities' scale). The compiled loop's packed kernel and the
relation's `kinematics` agree to round-off."""
import math

import numpy as np
import pytest

from nonsmooth_rod.model.contacts import (DiskOnDisk, DiskOnLine, DiskOnSegment, Line, Segment, SegmentEndOnEdge,
                                         VertexOnEdge)
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.model.packing import contact_kinematics, pack_contacts
from nonsmooth_rod.validation import InputError

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

EPS = 1e-6  # finite-difference step (s); the central difference errs by ~EPS² × third derivative


def _rotate(theta, p):
    c, s = math.cos(theta), math.sin(theta)
    return np.array([c * p[0] - s * p[1], s * p[0] + c * p[1]])


def _material_velocity(q, v, body, world_point):
    """Velocity of the material point of `body` at `world_point` (finite difference of its motion)."""
    j = 3 * body
    local = _rotate(-q[j + 2], world_point - q[j : j + 2])
    position = [q[j : j + 2] + s * EPS * v[j : j + 2] + _rotate(q[j + 2] + s * EPS * v[j + 2], local) for s in (1, -1)]
    return (position[0] - position[1]) / (2 * EPS)


def _centre(q, body, offset):
    return q[3 * body : 3 * body + 2] + _rotate(q[3 * body + 2], offset)


def _closest_on_segment(seg, c):
    a, b = np.array(seg.a), np.array(seg.b)
    s = np.clip(np.dot(c - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0)
    return a + s * (b - a)


def _contact_points(c, q):
    """(normal, point on body a, point on the other side or None) from plain geometry."""
    if isinstance(c, DiskOnLine):
        n = np.array(c.line.normal)
        centre = _centre(q, c.body, c.offset)
        return n, centre - c.radius * n, None
    if isinstance(c, DiskOnSegment):
        centre = _centre(q, c.body, c.offset)
        r = centre - _closest_on_segment(c.segment, centre)
        n = r / np.linalg.norm(r)
        return n, centre - c.radius * n, None
    ca, cb = _centre(q, c.body_a, c.offset_a), _centre(q, c.body_b, c.offset_b)
    n = (ca - cb) / np.linalg.norm(ca - cb)
    return n, ca - c.radius_a * n, cb + c.radius_b * n


def _geometric_gap(c, q):
    n, pa, pb = _contact_points(c, q)
    if isinstance(c, DiskOnLine):
        return float(np.dot(n, pa - np.array(c.line.point)))
    if isinstance(c, DiskOnSegment):
        return float(np.dot(n, pa - _closest_on_segment(c.segment, pa + c.radius * n)))
    return float(np.dot(n, pa - pb))


def _slip(c, q, v):
    n, pa, pb = _contact_points(c, q)
    t = np.array([n[1], -n[0]])
    body_a = c.body_a if isinstance(c, DiskOnDisk) else c.body
    rel = _material_velocity(q, v, body_a, pa)
    if pb is not None:
        rel = rel - _material_velocity(q, v, c.body_b, pb)
    return float(np.dot(t, rel))


def _random_state(rng, n_bodies, place):
    q = rng.uniform(-1, 1, 3 * n_bodies)
    v = rng.uniform(-2, 2, 3 * n_bodies)
    place(q)
    return q, v


SEG = Segment((-0.4, 0.1), (0.6, 0.5), name="table")


def _put_disk_beside_segment(where):
    """Move body 0 so that its disk (offset (0.1, −0.05)) is over the interior or beyond an end."""
    def place(q):
        a, b = np.array(SEG.a), np.array(SEG.b)
        along = {"interior": 0.3, "beyond-a": -0.25, "beyond-b": 1.3}[where] * (b - a)
        side = 1.0 if where != "interior" or q[1] > 0 else -1.0  # both sides of the interior
        centre = a + along + side * 0.3 * np.array(SEG.normal)
        q[0:2] = centre - _rotate(q[2], (0.1, -0.05))
    return place


CASES = [
    ("line", DiskOnLine(0, (0.2, -0.1), Line((0.1, -0.2), 0.3, velocity=0.7), 0.05), 1, lambda q: None),
    ("point on line", DiskOnLine(0, (-0.3, 0.1), Line((0.0, 0.0), -0.4), 0.0), 1, lambda q: None),
    ("disk on disk", DiskOnDisk(0, 1, 0.1, 0.2, (0.1, 0.05), (-0.1, 0.2)), 2, lambda q: None),
    ("segment interior", DiskOnSegment(0, (0.1, -0.05), SEG, 0.08), 1, _put_disk_beside_segment("interior")),
    ("segment end a", DiskOnSegment(0, (0.1, -0.05), SEG, 0.08), 1, _put_disk_beside_segment("beyond-a")),
    ("segment end b", DiskOnSegment(0, (0.1, -0.05), SEG, 0.0), 1, _put_disk_beside_segment("beyond-b")),
]


def _along(c, q, v, s):
    return c.kinematics(q + s * EPS * v, v, q.size)


@pytest.mark.parametrize("label, contact, n_bodies, place", CASES, ids=[c[0] for c in CASES])
def test_kinematics_are_the_derivatives_of_the_geometry(label, contact, n_bodies, place):
    rng = np.random.default_rng(22)
    for _ in range(20):
        q, v = _random_state(rng, n_bodies, place)
        k = contact.kinematics(q, v, q.size)
        plus, minus = _along(contact, q, v, 1), _along(contact, q, v, -1)
        scale = 1.0 + np.abs(v).max() ** 2  # lengths ~1 m, speeds ~2 m/s
        assert k.gap == pytest.approx(_geometric_gap(contact, q), abs=1e-12)
        assert k.H_N @ v == pytest.approx((plus.gap - minus.gap) / (2 * EPS), rel=1e-7, abs=1e-7 * scale)
        assert k.H_T @ v - k.surface_velocity == pytest.approx(
            _slip(contact, q, v) - k.surface_velocity, rel=1e-7, abs=1e-7 * scale)
        assert k.drift_N == pytest.approx((plus.H_N @ v - minus.H_N @ v) / (2 * EPS), rel=1e-6, abs=1e-6 * scale)
        assert k.drift_T == pytest.approx((plus.H_T @ v - minus.H_T @ v) / (2 * EPS), rel=1e-6, abs=1e-6 * scale)


@pytest.mark.parametrize("label, contact, n_bodies, place", CASES, ids=[c[0] for c in CASES])
def test_the_packed_kernel_of_the_loop_is_the_relations(label, contact, n_bodies, place):
    table, index = pack_contacts([contact], n_bodies)
    rng = np.random.default_rng(23)
    for _ in range(5):
        q, v = _random_state(rng, n_bodies, place)
        k = contact.kinematics(q, v, q.size)
        hn, ht = np.zeros(6), np.zeros(6)
        gap, drift = contact_kinematics(table, index, 0, q, v, hn, ht)
        rows = np.zeros((2, q.size))
        for side, body in enumerate(index[0, 1:]):
            if body >= 0:
                rows[:, 3 * body : 3 * body + 3] = hn[3 * side : 3 * side + 3], ht[3 * side : 3 * side + 3]
        np.testing.assert_allclose([gap, drift], [k.gap, k.drift_N], rtol=1e-13, atol=1e-14)
        np.testing.assert_allclose(rows, [k.H_N, k.H_T], rtol=1e-13, atol=1e-14)


def test_segment_contact_switches_feature_continuously():
    """Across the end of the segment the interior and the end point give the same gap and rows."""
    c = DiskOnSegment(0, (0.0, 0.0), Segment((0.0, 0.0), (1.0, 0.0)), 0.1)
    v = np.array([0.3, -0.2, 0.5])
    inside, outside = (c.kinematics(np.array([1.0 + s, 0.25, 0.0]), v, 3) for s in (-1e-12, 1e-12))
    assert inside.gap == pytest.approx(outside.gap, abs=1e-11)
    np.testing.assert_allclose(inside.H_N, outside.H_N, atol=1e-11)
    np.testing.assert_allclose(inside.H_T, outside.H_T, atol=1e-11)


def test_segment_contact_opens_beyond_the_end_by_more_than_the_radius():
    seg = Segment((-1.0, 0.0), (0.0, 0.0))
    c = DiskOnSegment(0, (0.0, 0.0), seg, 0.1)
    level = np.array([0.1 + 1e-6, 0.0, 0.0])  # at the segment's level, just beyond reach of its end
    assert c.kinematics(level, np.zeros(3), 3).gap > 0
    below = np.array([0.15, -0.5, 0.0])  # beyond the end and below: the end point is nearest, far away
    assert c.kinematics(below, np.zeros(3), 3).gap == pytest.approx(math.hypot(0.15, 0.5) - 0.1)


def test_bad_segments_and_undefined_normals_are_one_line_errors():
    with pytest.raises(InputError, match="segment 'step'.*length 0"):
        Segment((1.0, 2.0), (1.0, 2.0), name="step")
    with pytest.raises(InputError, match="segment 'step' b"):
        Segment((1.0, 2.0), (math.nan, 2.0), name="step")
    c = DiskOnSegment(0, (0.0, 0.0), Segment((0.0, 0.0), (1.0, 0.0)), 0.1, name="ball")
    on_end = c.kinematics(np.array([1.0, 0.0, 0.0]), np.zeros(3), 3)  # the interior's normal holds there
    assert on_end.gap == -0.1 and tuple(on_end.H_N) == (0.0, 1.0, 0.0)
    d = DiskOnDisk(0, 1, 0.1, 0.1, name="pair")
    with pytest.raises(InputError, match="pair: disk centres coincide"):
        d.kinematics(np.zeros(6), np.zeros(6), 6)
    with pytest.raises(InputError, match="contact 'ball' segment must be a Segment"):
        DiskOnSegment(0, (0.0, 0.0), Line(), 0.1, name="ball")


def test_a_changed_field_is_repacked():
    c = DiskOnLine(0, (0.0, 0.0), Line(), 0.1)
    q = np.array([0.0, 1.0, 0.0])
    assert c.kinematics(q, np.zeros(3), 3).gap == pytest.approx(0.9)
    c.radius = 0.3
    assert c.kinematics(q, np.zeros(3), 3).gap == pytest.approx(0.7)


BOX_EDGE = ((-0.1, -0.05), (0.1, -0.05))  # the bottom of a 0.2 × 0.1 box, counter-clockwise


def _put_edge_over_segment_end(where):
    """Move body 0 so that the segment's end b lies along its bottom edge, or beyond an end of it."""
    def place(q):
        fraction = {"along": 0.3, "beyond-start": -0.4, "beyond-end": 1.5}[where]
        start, end = np.array(BOX_EDGE[0]), np.array(BOX_EDGE[1])
        point_on_edge = _rotate(q[2], start + fraction * (end - start))
        outward = _rotate(q[2], (0.0, -1.0))
        q[0:2] = np.array(SEG.b) - point_on_edge - 0.02 * outward  # the end point 2 cm outside
    return place


EDGE_CASES = [(f"end on edge {w}", SegmentEndOnEdge(0, *BOX_EDGE, SEG, "b"), 1, _put_edge_over_segment_end(w))
              for w in ("along", "beyond-start", "beyond-end")]


@pytest.mark.parametrize("label, contact, n_bodies, place", EDGE_CASES, ids=[c[0] for c in EDGE_CASES])
def test_segment_end_on_an_edge_is_the_derivatives_of_its_geometry(label, contact, n_bodies, place):
    rng = np.random.default_rng(24)
    for _ in range(20):
        q, v = _random_state(rng, n_bodies, place)
        k = contact.kinematics(q, v, q.size)
        plus, minus = _along(contact, q, v, 1), _along(contact, q, v, -1)
        scale = 1.0 + np.abs(v).max() ** 2
        p = np.array(SEG.b)
        start, end = (q[0:2] + _rotate(q[2], e) for e in BOX_EDGE)
        s = np.clip(np.dot(p - start, end - start) / np.dot(end - start, end - start), 0.0, 1.0)
        assert k.gap == pytest.approx(np.linalg.norm(p - (start + s * (end - start))), abs=1e-12)  # 2 cm or the corner's
        n = k.H_N[:2]
        touching = p if label.endswith("along") else start + s * (end - start)
        t = np.array([n[1], -n[0]])
        assert k.H_T @ v == pytest.approx(np.dot(t, _material_velocity(q, v, 0, touching)), rel=1e-7, abs=1e-7 * scale)
        assert k.H_N @ v == pytest.approx((plus.gap - minus.gap) / (2 * EPS), rel=1e-7, abs=1e-7 * scale)
        assert k.drift_N == pytest.approx((plus.H_N @ v - minus.H_N @ v) / (2 * EPS), rel=1e-6, abs=1e-6 * scale)
        assert k.drift_T == pytest.approx((plus.H_T @ v - minus.H_T @ v) / (2 * EPS), rel=1e-6, abs=1e-6 * scale)
    table, index = pack_contacts([contact], n_bodies)
    hn, ht = np.zeros(6), np.zeros(6)
    gap, drift = contact_kinematics(table, index, 0, q, v, hn, ht)
    np.testing.assert_allclose([gap, drift, *hn[:3], *ht[:3]], [k.gap, k.drift_N, *k.H_N, *k.H_T], rtol=1e-13,
                               atol=1e-14)


# --- a vertex (or disk) on an edge, both sides moving or either fixed --------------------------------
EDGE = ((-0.3, 0.1), (0.5, -0.1))  # the edge's owner frame; its outward normal is τ turned by −90°
VERTEX = (0.15, -0.1)  # the vertex owner's frame
# −n of the edge in the vertex's frame: with the vertex body turned by 0.2 rad from the edge body,
# it is −n0 turned by −0.2; a cone of ±60° around it contains it


def _vertex_on_edge_case(vertex_body, edge_body, radius):
    t0 = np.subtract(EDGE[1], EDGE[0]) / np.linalg.norm(np.subtract(EDGE[1], EDGE[0]))
    minus_n0 = np.array([-t0[1], t0[0]])
    centre = _rotate(-0.2 if vertex_body >= 0 and edge_body >= 0 else 0.0, minus_n0)
    cone = (tuple(_rotate(-math.pi / 3, centre)), tuple(_rotate(math.pi / 3, centre)))
    contact = VertexOnEdge(vertex_body, VERTEX, edge_body, *EDGE, cone=None if radius else cone, radius=radius)
    n_bodies = 1 + (vertex_body >= 0 and edge_body >= 0)

    def place(q):
        theta_b = q[3 * edge_body + 2] if edge_body >= 0 else 0.0
        if vertex_body >= 0 and edge_body >= 0:
            q[3 * vertex_body + 2] = theta_b + 0.2
        if vertex_body < 0 and edge_body >= 0:
            q[2] = 0.0 if abs(q[2]) > 0.5 else q[2]  # −n within the fixed vertex's cone: turned < 60°
        origin = q[3 * edge_body: 3 * edge_body + 2] if edge_body >= 0 else np.zeros(2)
        start, end = (origin + _rotate(theta_b, e) for e in EDGE)
        tau = (end - start) / np.linalg.norm(end - start)
        point = start + 0.4 * (end - start) + (radius + 0.05 * q[0]) * np.array([tau[1], -tau[0]])
        if vertex_body >= 0:
            q[3 * vertex_body: 3 * vertex_body + 2] = point - _rotate(q[3 * vertex_body + 2], VERTEX)
        else:
            contact.vertex = tuple(point)
    return contact, n_bodies, place


def _vertex_geometry(c, q):
    """(normal, touching point of the vertex side, foot on the edge, gap) from plain geometry."""
    def frame(body):
        return (q[3 * body: 3 * body + 2], q[3 * body + 2]) if body >= 0 else (np.zeros(2), 0.0)
    (oa, tha), (ob, thb) = frame(c.vertex_body), frame(c.edge_body)
    p = oa + _rotate(tha, c.vertex) if c.vertex_body >= 0 else np.array(c.vertex)
    e0, e1 = ob + _rotate(thb, c.edge_start), ob + _rotate(thb, c.edge_end)
    tau = (e1 - e0) / np.linalg.norm(e1 - e0)
    n = np.array([tau[1], -tau[0]])
    foot = e0 + np.dot(p - e0, tau) * tau
    return n, p - c.radius * n, foot, float(np.dot(n, p - e0)) - c.radius


VERTEX_CASES = [("disk on a moving edge", 0, 1, 0.07), ("vertex on a moving edge", 1, 0, 0.0),
                ("vertex on a fixed edge", 0, -1, 0.0), ("disk on a fixed edge", 0, -1, 0.05),
                ("fixed vertex on an edge", -1, 0, 0.0)]


@pytest.mark.parametrize("label, vertex_body, edge_body, radius", VERTEX_CASES, ids=[c[0] for c in VERTEX_CASES])
def test_a_vertex_on_an_edge_is_the_derivatives_of_its_geometry(label, vertex_body, edge_body, radius):
    contact, n_bodies, place = _vertex_on_edge_case(vertex_body, edge_body, radius)
    rng = np.random.default_rng(25)
    for _ in range(20):
        q, v = _random_state(rng, n_bodies, place)
        k = contact.kinematics(q, v, q.size)
        plus, minus = _along(contact, q, v, 1), _along(contact, q, v, -1)
        scale = 1.0 + np.abs(v).max() ** 2
        n, pa, foot, gap = _vertex_geometry(contact, q)
        assert k.gap == pytest.approx(gap, abs=1e-12)
        t = np.array([n[1], -n[0]])
        rel = -_material_velocity(q, v, contact.edge_body, foot) if contact.edge_body >= 0 else 0.0
        if contact.vertex_body >= 0:
            rel = rel + _material_velocity(q, v, contact.vertex_body, pa)
        assert k.H_T @ v == pytest.approx(float(np.dot(t, rel)), rel=1e-7, abs=1e-7 * scale)
        assert k.H_N @ v == pytest.approx((plus.gap - minus.gap) / (2 * EPS), rel=1e-7, abs=1e-7 * scale)
        assert k.drift_N == pytest.approx((plus.H_N @ v - minus.H_N @ v) / (2 * EPS), rel=1e-6, abs=1e-6 * scale)
        assert k.drift_T == pytest.approx((plus.H_T @ v - minus.H_T @ v) / (2 * EPS), rel=1e-6, abs=1e-6 * scale)
        table, index = pack_contacts([contact], n_bodies)
        hn, ht = np.zeros(6), np.zeros(6)
        packed_gap, drift = contact_kinematics(table, index, 0, q, v, hn, ht)
        np.testing.assert_allclose([packed_gap, drift], [k.gap, k.drift_N], rtol=1e-13, atol=1e-14)


SQUARE = ((-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5))  # counter-clockwise; edge i runs from vertex i


def _box_pair_contacts(upper_wins_ties: bool):
    """Every vertex of a unit box (body 0, above) on every edge of another (body 1, below) and back."""
    from nonsmooth_rod.model.collision import Polygon, polygon_pair_contacts

    box = Polygon(SQUARE)
    return polygon_pair_contacts(box, 0, "upper", box, 1, "lower", ContactLaw(), tie_to_first=upper_wins_ties)


@pytest.mark.parametrize("upper_first", [True, False])
def test_flat_box_on_flat_box_of_the_same_width_touches_once_per_corner(upper_first):
    """The classic pitfall: corners exactly on corners. One contact per corner, normal +y."""
    contacts = _box_pair_contacts(upper_first)
    q = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
    touching = [(c.name, c.kinematics(q, np.zeros(6), 6)) for c in contacts]
    touching = [(name, k) for name, k in touching if k.gap <= 1e-12]
    assert len(touching) == 2, [name for name, _ in touching]
    for _, k in touching:
        assert k.gap == pytest.approx(0.0, abs=1e-15)
        np.testing.assert_allclose(k.H_N[:2], [0.0, 1.0], atol=1e-15)  # pushes the upper box up
        np.testing.assert_allclose(k.H_N[3:5], [0.0, -1.0], atol=1e-15)
    q[0] = 0.2  # shifted: the upper box's left corner on the lower's top, the lower's right corner under the upper
    touching = sorted(c.name for c in contacts if c.kinematics(q, np.zeros(6), 6).gap <= 1e-12)
    assert touching == ["lower.v2/upper.e0", "upper.v0/lower.e2"]


def test_a_vertex_whose_foot_leaves_the_edge_is_open_not_wrong():
    contacts = {c.name: c for c in _box_pair_contacts(True)}
    q = np.array([1.2, 1.0, 0.0, 0.0, 0.0, 0.0])  # the upper box entirely beside the lower, at its height
    for name in ("upper.v0/lower.e2", "upper.v0/lower.e1"):  # beyond the top; a corner beside a side
        assert contacts[name].kinematics(q, np.zeros(6), 6).gap == math.inf
    q = np.array([0.9999, 1.0, 0.0, 0.0, 0.0, 0.0])  # overlapping by 0.1 mm: on the top, not pushed sideways
    kin = {name: c.kinematics(q, np.zeros(6), 6) for name, c in contacts.items()}
    assert kin["upper.v0/lower.e2"].gap == pytest.approx(0.0, abs=1e-15)
    assert kin["upper.v0/lower.e1"].gap == math.inf  # the corner is at the side's end, the sides face away


def test_bad_vertex_on_edge_input_is_one_line():
    with pytest.raises(InputError, match="edge of length 0"):
        VertexOnEdge(0, (0.0, 0.0), 1, (1.0, 1.0), (1.0, 1.0), cone=((1.0, 0.0), (0.0, 1.0)))
    with pytest.raises(InputError, match="cone"):
        VertexOnEdge(0, (0.0, 0.0), 1, (0.0, 0.0), (1.0, 1.0))
    with pytest.raises(InputError, match="vertex_body and edge_body must differ"):
        VertexOnEdge(1, (0.0, 0.0), 1, (0.0, 0.0), (1.0, 1.0), radius=0.1)


@pytest.mark.parametrize("theta", [0.0, 0.7])
def test_a_point_that_crossed_two_edges_counts_against_the_least_penetrated(theta):
    """A ramp's end 1 cm inside a box's left side and 5 cm under its top (the box turned by θ
    with it): the side touches, 1 cm deep; the top (5 cm, within the depth limit) does not. A
    disk centred there likewise; the box's own corner, whose cone admits no side, keeps its top."""
    from nonsmooth_rod.model.collision import Polygon, find_contacts
    from nonsmooth_rod.model.body import RigidBody

    box = RigidBody(1.0, 0.02, name="box")
    end = _rotate(theta, (-0.19, 0.1))
    ramp = Segment(tuple(_rotate(theta, (-1.0, 0.4))), tuple(end), name="ramp")
    found = {c.name: c for c in find_contacts([box], {"box": Polygon.rectangle(0.4, 0.3)}, {"ramp": ramp})}
    q = np.array([0.0, 0.0, theta])
    assert found["ramp.b/box.e3"].kinematics(q, np.zeros(3), 3).gap == pytest.approx(-0.01, abs=1e-12)
    assert found["ramp.b/box.e2"].kinematics(q, np.zeros(3), 3).gap == math.inf
    square = Polygon(SQUARE)
    disk = VertexOnEdge(1, (0.0, 0.0), 0, *square.edge(2), radius=0.05, neighbours=square.neighbours(2))
    at = np.array([0.0, 0.0, 0.0, -0.49, 0.45, 0.0])  # the disk's centre 1 cm inside the left side, 5 cm under the top
    assert disk.kinematics(at, np.zeros(6), 6).gap == math.inf
    corner = VertexOnEdge(1, SQUARE[0], 0, *square.edge(2), cone=square.cone(0), neighbours=square.neighbours(2))
    at = np.array([0.0, 0.0, 0.0, 0.5, 0.98, 0.0])  # its corner 2 cm into the top, 50 cm inside the left side
    assert corner.kinematics(at, np.zeros(6), 6).gap == pytest.approx(-0.02, abs=1e-12)
    at[3] = 0.01  # its corner 1 cm inside the left side, 2 cm into the top: the side cannot push it
    assert corner.kinematics(at, np.zeros(6), 6).gap == pytest.approx(-0.02, abs=1e-12)


def test_the_region_margin_is_the_kernels_rule():
    """`region` gives the gap whether or not the pair of features counts, and a margin ≥ 0 exactly
    where the kernel counts it (a finite gap) — the event-driven reference locates entering and
    leaving the region where the margin crosses 0."""
    contacts = _box_pair_contacts(True)
    rng = np.random.default_rng(7)
    for _ in range(100):
        q = np.array([rng.uniform(-1.2, 1.2), rng.uniform(0.9, 1.1), rng.uniform(-0.4, 0.4), 0.0, 0.0, 0.0])
        v = rng.normal(size=6)
        for c in contacts:
            k = c.kinematics(q, v, 6)
            gap, margin = c.region(q, v)
            assert (margin >= 0.0) == math.isfinite(k.gap), c.name
            assert math.isfinite(gap) and (gap == k.gap or not math.isfinite(k.gap))


def test_a_corner_passing_a_segments_end_leaves_its_region_continuously():
    """A box's corner sliding flat along a table's top (found contacts) past the table's end: its
    gap stays 0 and the margin is the distance of its foot inside the end, + SEAM_TOL × length,
    changing sign where the kernel stops counting the pair (within FACE_TOL of it: flat faces sit
    on the boundary of the corner's cone, widened by FACE_TOL, which bounds the margin)."""
    from nonsmooth_rod.model.collision import Polygon, find_contacts
    from nonsmooth_rod.model.contact_kernels import FACE_TOL, SEAM_TOL

    class Body:
        name = "box"
    table = Segment((-2.0, 0.0), (0.0, 0.0), name="table")
    contacts = {c.name: c for c in find_contacts([Body()], {"box": Polygon.rectangle(0.4, 0.2)}, {"table": table})}
    corner = contacts["box.v1/table.side+"]  # the bottom right corner, at x + 0.2, on the top
    for x_corner in (-0.01, -1e-6, 1e-6, 0.01):
        q, v = [x_corner - 0.2, 0.1, 0.0], [1.0, 0.0, 0.0]
        gap, margin = corner.region(q, v)
        assert gap == pytest.approx(0.0, abs=1e-15)
        assert margin == pytest.approx(-x_corner + SEAM_TOL * table.length, abs=1e-15)
        assert math.isfinite(corner.kinematics(q, v, 3).gap) == (x_corner < 0)
    assert corner.region([-1.0, 0.1, 0.0], [0.0, 0.0, 0.0])[1] == pytest.approx(FACE_TOL, abs=1e-15)
