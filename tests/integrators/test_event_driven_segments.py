"""The event-driven reference on finite segments, against closed forms (and Moreau–Jean at a fine
step): a ball dropped beside a segment's end falls past it, one dropped on it lands; a disk
rolling off a table's end slips and leaves the edge where the closed forms say; boxes whose
contacts are found from their shapes (their corners on the table's sides, the table's ends on
their edges) fall past the end, land on the table, slide to a stop, and slide off the end — the
corner leaving the table's top and the lift of the rear corner located as events."""
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import nonsmooth_rod as nr
from nonsmooth_rod.model.collision import find_contacts
from nonsmooth_rod.model.contact_kernels import SEAM_TOL
from nonsmooth_rod.scenefile import load_scene, simulate_scene
from nonsmooth_rod.validation import InputError

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

R, M, G = 0.1, 1.0, 9.81
TABLE = nr.Segment((-1.0, 0.0), (0.0, 0.0), name="table")
SCENES = Path(__file__).resolve().parents[2] / "examples" / "scenes"
# rtol = atol = 1e-12 (the defaults): times and positions to ~1e-9 of their scale
TIME_TOL = 1e-9


def _ball_scene(law=None, k=0.5):
    body = nr.RigidBody(M, k * M * R * R)
    return nr.Scene([body], [nr.DiskOnSegment(0, (0.0, 0.0), TABLE, R, law or nr.ContactLaw.of(0.5, 0.5, 0.0),
                                              name="table")], gravity=G)


def test_a_ball_dropped_beside_the_end_falls_past_it():
    """Centre 1.5 R beyond the end: the end point stays out of reach — free fall, no force."""
    r = nr.simulate(_ball_scene(), np.array([1.5 * R, 0.5, 0.0]), np.zeros(3), 0.5, "event-driven")
    assert r.status == nr.Status.OK and not r.impacts
    assert [p.mode for p in r.phases["table"]] == ["open"] and np.all(r.trajectory.normal_force == 0.0)
    np.testing.assert_allclose(r.trajectory.q[:, 1], 0.5 - G * r.trajectory.t**2 / 2, rtol=0, atol=1e-10)


def test_a_ball_dropped_on_the_segment_lands_at_the_closed_form_time_and_rests():
    r = nr.simulate(_ball_scene(), np.array([-0.5, 0.4, 0.0]), np.zeros(3), 0.6, "event-driven")
    assert r.status == nr.Status.OK
    assert len(r.impacts) == 1 and r.impacts[0].t == pytest.approx(math.sqrt(2 * 0.3 / G), abs=TIME_TOL)
    assert [p.mode for p in r.phases["table"]] == ["open", "stick"]
    assert r.trajectory.q[-1, 1] == pytest.approx(R, abs=1e-12)
    assert r.trajectory.normal_force[-1, 0] == pytest.approx(M * G, rel=1e-9)


def test_a_disk_rolling_off_the_table_slips_and_leaves_the_edge_where_the_closed_forms_say():
    """examples/scenes/ball_off_table.toml: a disk (I = k m R², k = 1/2) rolling at v0 onto the
    table's end (the contact passes from the segment's interior to its end point) pivots on it.
    Rolling about the corner: φ̈ = g sin φ / ((1 + k) R), so the friction it needs is
    T = m g sin φ k / (1 + k), and N = m g ((3 + k) cos φ − 2) / (1 + k) − m v0²/R; it slips where
    T = μ N, and then leaves (N = 0) within k / (μ (3 + k)) rad of the rolling leaving angle
    cos φ* = (2 + (1 + k) v0²/(g R)) / (3 + k)."""
    sf = load_scene(SCENES / "ball_off_table.toml", ["simulation.method=event-driven"])
    r = simulate_scene(sf)
    assert r.status == nr.Status.OK
    assert [p.mode for p in r.phases["edge"]] == ["stick", "slip+", "open"]
    k, mu, v0 = 0.5, 100.0, 0.5
    normal = lambda phi: G * ((3 + k) * math.cos(phi) - 2) / (1 + k) - v0**2 / R  # noqa: E731 (per unit mass)
    leaving = math.acos((2 + (1 + k) * v0**2 / (G * R)) / (3 + k))
    slipping = brentq(lambda phi: G * math.sin(phi) * k / (1 + k) - mu * normal(phi), 0.0, leaving)
    tr = r.trajectory

    def angle_at(t):  # the centre's angle from the vertical through the corner, at an event's sample
        i = int(np.flatnonzero(tr.t == t)[0])
        return math.atan2(tr.q[i, 0], tr.q[i, 1])
    assert angle_at(r.phases["edge"][1].t_start) == pytest.approx(slipping, abs=1e-8)
    phi_leave = angle_at(r.phases["edge"][2].t_start)
    assert slipping < phi_leave < leaving and leaving - phi_leave < k / (mu * (3 + k))


@pytest.mark.parametrize("contact, lacks", [
    (nr.PointOnSegment(0, (0.0, -0.05), TABLE, name="corner"), r"a point \(radius 0\) on a segment: contact 'corner'"),
    (nr.SegmentEndOnEdge(0, (-0.1, -0.05), (0.1, -0.05), TABLE, "b", name="corner"),
     r"a SegmentEndOnEdge \(contact 'corner'\)")], ids=["point on a segment", "segment end on an edge"])
def test_relations_whose_normal_is_undefined_where_they_touch_are_refused_in_one_line(contact, lacks):
    """A point on a two-sided segment takes its side from the sign of a zero gap; a segment's end on
    an edge turns into a point-to-point contact at the edge's corner: both name the VertexOnEdge
    that replaces them (as found contacts are)."""
    scene = nr.Scene([nr.RigidBody(M, 0.01)], [contact], gravity=G)
    with pytest.raises(InputError, match=rf"^the event-driven integrator does not handle {lacks}.*VertexOnEdge[^\n]*$"):
        nr.simulate(scene, np.array([-0.5, 0.05, 0.0]), np.zeros(3), 0.1, "event-driven")


# --------------------------------------------------------------------------- boxes, found contacts
W, H, MU_S, MU_D = 0.4, 0.2, 0.3, 0.2  # the box of examples/scenes/box_off_table.toml
TABLE_TOP = 0.8


def _box_scene():
    box = nr.RigidBody(M, M * (W * W + H * H) / 12, name="block")
    table = nr.Segment((-2.0, TABLE_TOP), (0.0, TABLE_TOP), name="table")
    contacts = find_contacts([box], {"block": nr.Polygon.rectangle(W, H)}, {"table": table, "floor": nr.Line()},
                             nr.PairLaws(default=nr.ContactLaw.of(MU_S, MU_D)))
    return nr.Scene([box], contacts, gravity=G)


def _touched(r):
    return sorted(k for k in r.contact_names if any(p.mode != "open" for p in r.phases[k]))


@pytest.mark.parametrize("x0, lands_on, height", [(0.25, "floor", 0.0), (-1.0, "table", TABLE_TOP)],
                         ids=["beside the end", "on the table"])
def test_a_box_dropped_beside_the_tables_end_falls_past_it_one_dropped_on_it_lands(x0, lands_on, height):
    """Its left corners 5 cm beyond the table's end, the box falls past the table to the floor;
    dropped over the table, it lands on it: both at t = √(2 (y0 − H/2 − height) / g), flat (both
    bottom corners at once), and rests."""
    y0 = 1.2
    r = nr.simulate(_box_scene(), np.array([x0, y0, 0.0]), np.zeros(3), 0.6, "event-driven")
    assert r.status == nr.Status.OK, r.message
    assert _touched(r) == sorted([f"block.v0/{lands_on}", f"block.v1/{lands_on}"] if lands_on == "floor" else
                                 ["block.v0/table.side+", "block.v1/table.side+"])
    assert r.impacts[0].t == pytest.approx(math.sqrt(2 * (y0 - H / 2 - height) / G), abs=TIME_TOL)
    assert r.trajectory.q[-1, 1] == pytest.approx(height + H / 2, abs=1e-12)


def test_a_box_sliding_on_a_finite_table_stops_at_the_closed_form_distance():
    """Sliding at v0 on its two bottom corners, it decelerates at μd g: it stops after
    v0² / (2 μd g), at t = v0 / (μd g), and sticks there (μs holds it)."""
    x0, v0 = -1.5, 1.0
    r = nr.simulate(_box_scene(), np.array([x0, TABLE_TOP + H / 2, 0.0]), np.array([v0, 0.0, 0.0]), 0.8,
                    "event-driven")
    assert r.status == nr.Status.OK
    for corner in ("block.v0/table.side+", "block.v1/table.side+"):
        assert [p.mode for p in r.phases[corner]] == ["slip+", "stick"]
        assert r.phases[corner][1].t_start == pytest.approx(v0 / (MU_D * G), abs=TIME_TOL)
    assert r.trajectory.q[-1, 0] == pytest.approx(x0 + v0**2 / (2 * MU_D * G), abs=1e-9)


def _reaches(x, x0, v0):
    """When the sliding box's centre (decelerating at μd g from x0, v0) reaches x."""
    return (v0 - math.sqrt(v0**2 - 2 * MU_D * G * (x - x0))) / (MU_D * G)


def test_the_box_sliding_off_the_tables_end_example_locates_the_corner_leaving_and_the_pivot():
    """examples/scenes/box_off_table.toml by the event-driven reference. Sliding on its two bottom
    corners, decelerating at μd g, the box's front corner passes the table's end when its centre
    reaches −W/2: the corner's contact leaves its region (the foot past the end: an event), and
    the table's end under the box's bottom edge takes the load, sliding. With the bottom on the
    table's end and both contacts sliding, the moments about that point (m g x, and the
    deceleration's m μd g H/2 at the centre's height) lift the rear corner when x = −μd H/2; the box
    then pivots and slides on the edge until it leaves it and falls to the floor."""
    sf = load_scene(SCENES / "box_off_table.toml", ["simulation.method=event-driven", "simulation.t_end=0.8"])
    r = simulate_scene(sf)
    assert r.status == nr.Status.OK, r.message
    phases = {name: [(p.mode, p.t_start) for p in r.phases[name]] for name in _touched(r)}
    x0, v0 = sf.q0[0], sf.v0[0]
    front, rear, edge = phases["block.v1/table.side+"], phases["block.v0/table.side+"], phases["table.b/block.e0"]
    assert [m for m, _ in front] == ["slip+", "open"] and [m for m, _ in rear] == ["slip+", "open"]
    assert [m for m, _ in edge] == ["open", "slip+", "open"]
    # (the kernel counts a foot within SEAM_TOL × the table's length of its end as on it)
    assert front[1][1] == pytest.approx(_reaches(-W / 2 + SEAM_TOL * 2.0, x0, v0), abs=TIME_TOL)
    assert edge[1][1] == front[1][1]  # the load passes at that instant
    assert rear[1][1] == pytest.approx(_reaches(-MU_D * H / 2, x0, v0), abs=TIME_TOL)
    assert [e.kind for e in r.events if e.contact == "block.v1/table.side+"] == ["leave-feature"]
    assert r.impacts and r.impacts[0].contact.endswith("/floor") and edge[2][1] < r.impacts[0].t


def test_declared_vertex_edge_contacts_hand_the_load_from_the_corner_to_the_tables_end():
    """The same slide declared by hand (tests/integrators/test_segments.py's block, w × h = 0.2 ×
    0.1, μ = 0.3, at 2 m/s): the corners on the table's top and the table's end on the bottom edge,
    as VertexOnEdge contacts. The table's end enters its region touching, at no approach speed —
    no impact —, the right corner leaves the top when the centre reaches −w/2, the left corner
    lifts at −μ h/2, and the table's end leaves the block's edge at its corner (the pair leaves its
    region: it opens though the edge's extension would sink under it)."""
    w, h, mu, x0, v0 = 0.2, 0.1, 0.3, -0.5, 2.0
    law, box, n = nr.ContactLaw.of(mu, mu, 0.0), nr.Polygon.rectangle(w, h), TABLE.normal
    corners = [nr.VertexOnEdge(0, box.vertices[i], -1, TABLE.b, TABLE.a, cone=box.cone(i), law=law, name=name)
               for i, name in ((0, "left"), (1, "right"))]
    end = nr.VertexOnEdge(-1, TABLE.b, 0, *box.edge(0), cone=((-n[0], -n[1]), n), tie_wins=False, law=law, name="end")
    scene = nr.Scene([nr.RigidBody(M, M * (w**2 + h**2) / 12)], corners + [end], gravity=G)
    r = nr.simulate(scene, np.array([x0, h / 2, 0.0]), np.array([v0, 0.0, 0.0]), 0.6, "event-driven")
    assert r.status == nr.Status.OK, r.message
    phases = {name: [(p.mode, p.t_start) for p in ph] for name, ph in r.phases.items()}
    assert [m for m, _ in phases["left"]] == ["slip+", "open"] and [m for m, _ in phases["right"]] == ["slip+", "open"]
    assert [m for m, _ in phases["end"]] == ["open", "slip+", "open"]

    def reaches(x):
        return (v0 - math.sqrt(v0**2 - 2 * mu * G * (x - x0))) / (mu * G)
    assert phases["right"][1][1] == pytest.approx(reaches(-w / 2 + SEAM_TOL * TABLE.length), abs=TIME_TOL)
    assert phases["end"][1][1] == phases["right"][1][1]
    assert phases["left"][1][1] == pytest.approx(reaches(-mu * h / 2), abs=TIME_TOL)
    assert not r.impacts
    assert [(e.kind, e.contact) for e in r.events[1:]] == [("enter-feature", "end"), ("leave-feature", "right"),
                                                          ("liftoff", "left"), ("leave-feature", "end")]
