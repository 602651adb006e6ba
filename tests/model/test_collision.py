"""Shapes that collide (model/collision.py): contacts found from the bodies' shapes, checked
against closed forms — a box on an incline that holds, slides or tips; two stacked boxes pulled;
a tower that holds without creep; a ball beside or on a segment's end; a block sliding off a
table, pivoting on its edge — and the input rules (convex polygons, laws by pair, filters)."""
import math

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod.model.collision import find_contacts

G = 9.81
H = 1e-3


def _box(name, mass, w, h):
    return nr.RigidBody(mass, mass * (w * w + h * h) / 12.0, name=name)


def _run(bodies, contacts, q0, v0, steps, forces=()):
    result = nr.simulate(nr.Scene(bodies, contacts, forces=list(forces)), np.asarray(q0, float),
                         np.asarray(v0, float), steps * H, "moreau-jean", h=H)
    assert result.status == "ok", result.message
    return result


def _touched(result):
    return sorted(k for k in result.contact_names if any(p.mode != "open" for p in result.phases[k]))


def _incline(alpha, mu_s, mu_d, width, height, steps):
    box = _box("box", 1.0, width, height)
    ramp = nr.Line((0.0, 0.0), alpha)
    contacts = find_contacts([box], {"box": nr.Polygon.rectangle(width, height)}, {"ramp": ramp},
                             nr.PairLaws(default=nr.ContactLaw.of(mu_s, mu_d)))
    assert [c.name for c in contacts] == ["box.v0/ramp", "box.v1/ramp", "box.v2/ramp", "box.v3/ramp"]
    q0 = [*(np.array(ramp.normal) * height / 2), alpha]  # resting flat, its bottom on the ramp
    return _run([box], contacts, q0, [0.0, 0.0, 0.0], steps), ramp


def test_a_box_holds_on_an_incline_below_both_slip_and_tip():
    """tan α = 0.31 < μs = 0.5 and < b/h = 1: nothing moves, to round-off."""
    result, _ = _incline(0.3, 0.5, 0.4, 1.0, 1.0, 1000)
    assert np.abs(result.trajectory.q - result.trajectory.q[0]).max() < 1e-10


def test_a_box_slides_down_an_incline_at_g_sin_minus_mu_d_cos():
    alpha, mu_d = 0.3, 0.15
    result, ramp = _incline(alpha, 0.2, mu_d, 1.0, 0.5, 300)
    t, v = result.trajectory.t[-1], result.trajectory.v[-1]
    speed_down = -float(np.dot(v[:2], ramp.tangent))
    assert speed_down == pytest.approx(G * (math.sin(alpha) - mu_d * math.cos(alpha)) * t, rel=1e-9)
    assert abs(v[2]) < 1e-12  # no turn: it slides flat
    assert _touched(result) == ["box.v0/ramp", "box.v1/ramp"]


def test_a_narrow_box_tips_about_its_lower_corner_without_slipping():
    """b/h = 0.4 < tan α = 0.55 < μs = 0.8: it turns about its downhill corner, which stays put."""
    alpha, w, h = 0.5, 0.4, 1.0
    result, _ = _incline(alpha, 0.8, 0.6, w, h, 300)
    q = result.trajectory.q
    corner = q[:, :2] + np.array([[math.cos(th) * -w / 2 - math.sin(th) * -h / 2,
                                   math.sin(th) * -w / 2 + math.cos(th) * -h / 2] for th in q[:, 2]])
    travel = np.abs(q[:, :2] - q[0, :2]).max()  # ~4 cm; the corner moves by what the step's turn leaves, O(h²)
    assert np.abs(corner - corner[0]).max() < 1e-3 * travel
    assert q[-1, 2] - q[0, 2] > 0.05  # turning downhill (counter-clockwise)
    assert [p.mode for p in result.phases["box.v0/ramp"]] == ["stick"]
    assert _touched(result) == ["box.v0/ramp"]


def _stacked(force, m1=2.0, m2=1.0, mu_s=0.4, mu_d=0.3, steps=150):
    w, h = 1.0, 0.5  # the same width: corners exactly on corners
    lower, upper = _box("lower", m1, w, h), _box("upper", m2, w, h)
    laws = nr.PairLaws([("lower", "upper", nr.ContactLaw.of(mu_s, mu_d))])  # the floor: the default, frictionless
    shape = nr.Polygon.rectangle(w, h)
    contacts = find_contacts([lower, upper], {"lower": shape, "upper": shape}, {"floor": nr.Line()}, laws)
    result = _run([lower, upper], contacts, [0.0, h / 2, 0.0, 0.0, 1.5 * h, 0.0], np.zeros(6), steps,
                  [nr.ConstantForce(0, (force, 0.0))])
    return result, result.trajectory.v[-1] / result.trajectory.t[-1]


def test_stacked_boxes_move_together_below_the_static_limit():
    m1, m2, mu_s = 2.0, 1.0, 0.4
    force = 0.9 * mu_s * G * (m1 + m2)
    result, acc = _stacked(force)
    assert acc[0] == pytest.approx(force / (m1 + m2), rel=1e-10)
    assert acc[3] == pytest.approx(force / (m1 + m2), rel=1e-10)
    assert np.abs(result.trajectory.q[:, [1, 2, 4, 5]] - result.trajectory.q[0, [1, 2, 4, 5]]).max() < 1e-12
    # one contact per touching corner: the pair of coincident corners gives one, not two
    assert len([k for k in _touched(result) if "floor" not in k]) == 2


def test_stacked_boxes_slip_above_the_static_limit():
    m1, m2, mu_s, mu_d = 2.0, 1.0, 0.4, 0.3
    force = 1.1 * mu_s * G * (m1 + m2)
    _, acc = _stacked(force)
    assert acc[3] == pytest.approx(mu_d * G, rel=1e-10)
    assert acc[0] == pytest.approx((force - mu_d * m2 * G) / m1, rel=1e-10)


def test_a_tower_of_five_boxes_holds_without_creep():
    w, h, n = 0.4, 0.3, 5
    bodies = [_box(f"box{k}", 1.0, w, h) for k in range(n)]
    shape = nr.Polygon.rectangle(w, h)
    contacts = find_contacts(bodies, {b.name: shape for b in bodies}, {"floor": nr.Line()},
                             nr.PairLaws(default=nr.ContactLaw.of(0.5, 0.4)))
    q0 = np.zeros(3 * n)
    q0[1::3] = h / 2 + h * np.arange(n)
    result = _run(bodies, contacts, q0, np.zeros(3 * n), 200)
    assert np.abs(result.trajectory.q - q0).max() < 1e-10
    # corners on corners: the upper box's bottom corners on the top of the box below (the later
    # body's vertices keep the tie), each box's two, left to right as a hand-written scene lists them
    touched = _touched(result)
    expected = [f"box0.v{i}/floor" for i in (0, 1)] + [f"box{k}.v{i}/box{k - 1}.e2" for k in range(1, n) for i in (0, 1)]
    assert sorted(touched) == sorted(expected)
    assert [name for name in result.contact_names if name in expected] == expected


@pytest.mark.parametrize("x0, lands", [(-0.5, True), (0.12, False)])
def test_a_ball_lands_on_a_segment_or_falls_past_its_end(x0, lands):
    r = 0.1
    ball = nr.RigidBody(1.0, 0.5 * r * r / 2, name="ball")
    table = nr.Segment((-1.0, 0.0), (0.0, 0.0), name="table")
    contacts = find_contacts([ball], {"ball": nr.Disk(r)}, {"table": table})
    result = _run([ball], contacts, [x0, 0.5, 0.0], [0.0, 0.0, 0.0], 600)
    y, vy = result.trajectory.q[-1, 1], result.trajectory.v[-1, 1]
    if lands:
        impact_speed = math.sqrt(2 * G * 0.4)
        assert r - H * impact_speed < y <= r and vy == pytest.approx(0.0, abs=1e-12)  # within a step's travel
    else:
        t = result.trajectory.t[-1]
        assert y == pytest.approx(0.5 - G * t * t / 2, rel=1e-9)  # free fall past the end


def test_a_block_slides_over_a_table_end_pivots_on_its_edge_and_falls():
    """Phases: the front corner slides off (the table's end takes over under the block's bottom),
    the back corner lifts when the block starts to pivot, then the block leaves the edge. While
    both touch and slide, the pivot starts when the moment of friction about the centre of mass
    (μd m g h/2) is no longer balanced: the centre of mass at μd h/2 before the edge."""
    w, h, mu_d, x0, v0 = 0.4, 0.2, 0.2, -0.25, 1.2
    block = _box("block", 1.0, w, h)
    table = nr.Segment((-2.0, 0.0), (0.0, 0.0), name="table")
    contacts = find_contacts([block], {"block": nr.Polygon.rectangle(w, h)}, {"table": table},
                             nr.PairLaws(default=nr.ContactLaw.of(0.3, mu_d)))
    result = _run([block], contacts, [x0, h / 2, 0.0], [v0, 0.0, 0.0], 700)
    modes = {k: [p.mode for p in result.phases[k]] for k in _touched(result)}
    assert modes == {"block.v0/table.side+": ["slip+", "open"], "block.v1/table.side+": ["slip+", "open"],
                     "table.b/block.e0": ["open", "slip+", "open"]}
    front_off, pivot = (result.phases[k][0].t_end for k in ("block.v1/table.side+", "block.v0/table.side+"))
    assert result.phases["table.b/block.e0"][1].t_start == pytest.approx(front_off, abs=2 * H)  # the hand-over
    a = mu_d * G  # both slide: x = x0 + v0 t − a t²/2

    def reaching(x):
        return (v0 - math.sqrt(v0 * v0 - 2 * a * (x - x0))) / a
    assert front_off == pytest.approx(reaching(-w / 2), abs=2 * H)  # the front corner over the end
    t_pivot = reaching(-mu_d * h / 2)
    assert pivot == pytest.approx(t_pivot, abs=3 * H)
    assert result.trajectory.q[-1, 1] < -h  # fallen below the table top


def test_declared_contacts_take_the_place_of_the_found_ones():
    box = _box("box", 1.0, 1.0, 1.0)
    floor = nr.Line()
    declared = [nr.PointOnLine(0, (0.5, -0.5), floor, nr.ContactLaw.of(0.9), name="right")]
    found = find_contacts([box], {"box": nr.Polygon.rectangle(1.0, 1.0)}, {"floor": floor}, declared=declared)
    assert [c.name for c in found] == ["box.v0/floor", "box.v2/floor", "box.v3/floor"]


def test_laws_by_pair_most_specific_first():
    law_a, law_b, law_c = (nr.ContactLaw.of(mu) for mu in (0.1, 0.2, 0.3))
    laws = nr.PairLaws([("*", "*", law_a), ("box", "*", law_b), ("floor", "box", law_c)])
    assert laws.law("box", "floor") is law_c and laws.law("box", "wall") is law_b
    assert laws.law("ball", "wall") is law_a
    assert nr.PairLaws().law("a", "b") == nr.ContactLaw()
    box = _box("box", 1.0, 1.0, 1.0)
    with pytest.raises(nr.InputError, match=r"laws\[0\].between: 'bx' names no body"):
        find_contacts([box], {"box": nr.Polygon.rectangle(1, 1)}, {"floor": nr.Line()},
                      nr.PairLaws([("bx", "*", law_a)]))


def test_filters_leave_pairs_out():
    bodies = [_box(n, 1.0, 1.0, 1.0) for n in ("a", "b", "c")]
    shapes = {b.name: nr.Polygon.rectangle(1, 1) for b in bodies}
    pairs = {tuple(sorted({c.name.split("/")[0].split(".")[0], c.name.split("/")[1].split(".")[0]}))
             for c in find_contacts(bodies, shapes, {"floor": nr.Line()}, never=[("a", "*")], groups={"b": 1, "c": 1})}
    assert pairs == {("b", "floor"), ("c", "floor")}


@pytest.mark.parametrize("vertices, message", [
    ([(0, 0), (1, 0), (0.2, 0.2), (0, 1)], "not convex"),
    ([(0, 0), (0, 1), (1, 1), (1, 0)], "clockwise"),
    ([(0, 0), (1, 0), (2, 0)], "area 0"),
    ([(0, 0), (1, 0), (1, 0), (0, 1)], "repeat"),
    ([(0, 0), (1, 0)], "at least 3"),
])
def test_bad_polygons_are_one_line_errors(vertices, message):
    with pytest.raises(nr.InputError, match=f"box vertices: .*{message}"):
        nr.Polygon(vertices, name="box")


def test_polyline_is_named_segments():
    chain = nr.Polyline([(0, 0), (1, 0), (2, 1)], name="ground")
    assert list(chain) == ["ground.0", "ground.1"] and chain["ground.1"].b == (2.0, 1.0)
    with pytest.raises(nr.InputError, match="segment 'ground.0'.*length 0"):
        nr.Polyline([(0, 0), (0, 0)], name="ground")


def test_the_event_driven_reference_runs_polygons_on_lines_and_on_segments():
    """A box pushed along a floor stops after v0²/(2 μ g): its found corner contacts are points
    on a line, which the event-driven method locates; on a table segment (vertex–edge contacts)
    it stops at the same place."""
    box = _box("box", 1.0, 0.4, 0.2)
    shape = {"box": nr.Polygon.rectangle(0.4, 0.2)}
    contacts = find_contacts([box], shape, {"floor": nr.Line()}, nr.PairLaws(default=nr.ContactLaw.of(0.5)))
    result = nr.simulate(nr.Scene([box], contacts), np.array([0.0, 0.1, 0.0]), np.array([0.5, 0.0, 0.0]), 0.3,
                         "event-driven")
    assert result.trajectory.q[-1, 0] == pytest.approx(0.5 ** 2 / (2 * 0.5 * G), rel=1e-8)
    on_table = find_contacts([box], shape, {"table": nr.Segment((-1.0, 0.0), (1.0, 0.0))},
                             nr.PairLaws(default=nr.ContactLaw.of(0.5)))
    result = nr.simulate(nr.Scene([box], on_table), np.array([0.0, 0.1, 0.0]), np.array([0.5, 0.0, 0.0]), 0.3,
                         "event-driven")
    assert result.trajectory.q[-1, 0] == pytest.approx(0.5 ** 2 / (2 * 0.5 * G), rel=1e-8)


def test_boxes_and_a_ball_dropped_in_a_heap_do_not_pass_through_each_other():
    """Three tilted boxes and a ball dropped onto a floor, a ramp and each other for 3 s: faces
    rock on faces and corners slide off edges, and no shape ever sinks into another by more than
    an impact's step of travel (h × 3 m/s)."""
    rng = np.random.default_rng(1)
    bodies = [_box(f"b{k}", 1.0, 0.4, 0.3) for k in range(3)] + [nr.RigidBody(1.0, 0.5 * 0.12 ** 2 / 2, name="b3")]
    shapes = {f"b{k}": nr.Polygon.rectangle(0.4, 0.3) for k in range(3)} | {"b3": nr.Disk(0.12)}
    obstacles = {"floor": nr.Line(), "ramp": nr.Segment((-1.5, 0.6), (-0.3, 0.1), name="ramp")}
    contacts = find_contacts(bodies, shapes, obstacles, nr.PairLaws(default=nr.ContactLaw.of(0.4, 0.3)))
    q0 = np.array([[rng.uniform(-0.3, 0.3), 0.3 + 0.5 * k, rng.uniform(-0.5, 0.5)] for k in range(4)]).ravel()
    q0[9:12] = [-1.0, 1.2, 0.0]
    result = _run(bodies, contacts, q0, np.zeros(12), 3000)
    scene = nr.Scene(bodies, contacts)
    deepest = min(k.gap for i in range(0, len(result.trajectory.t), 10)
                  for k in scene.kinematics(result.trajectory.q[i], result.trajectory.v[i]))
    assert deepest > -3e-3


def test_a_box_dropped_on_a_box_runs_as_with_its_touching_contacts_declared():
    """Found contacts (40 candidates, most left out by the broad phase or rejected by the kernel
    before their rows) against the 4 that touch declared by hand: a box dropped 2 cm onto a box
    on the floor, 5 cm off its axis — the same impacts, phases and run to round-off."""
    w, h = 0.4, 0.3
    bodies = [_box(f"box{k}", 1.0, w, h) for k in range(2)]
    box, floor, law = nr.Polygon.rectangle(w, h), nr.Line(), nr.ContactLaw.of(0.5, 0.4)
    found = find_contacts(bodies, {b.name: box for b in bodies}, {"floor": floor}, nr.PairLaws(default=law))
    declared = [nr.PointOnLine(0, box.vertices[i], floor, law, name=f"box0.v{i}/floor") for i in (0, 1)]
    declared += [nr.VertexOnEdge(1, box.vertices[0], 0, *box.edge(2), cone=box.cone(0), law=law,
                                 name="box1.v0/box0.e2"),
                 nr.VertexOnEdge(0, box.vertices[2], 1, *box.edge(0), cone=box.cone(2), law=law,
                                 name="box0.v2/box1.e0")]
    q0 = [0.0, h / 2, 0.0, 0.05, 1.5 * h + 0.02, 0.0]
    runs = [_run(bodies, contacts, q0, [0.0] * 6, 200) for contacts in (found, declared)]
    assert len(runs[0].contact_names) == 40
    q = runs[1].trajectory.q
    assert np.abs(runs[0].trajectory.q - q).max() <= 1e-12
    assert sorted((i.t, i.contact) for i in runs[0].impacts) == sorted((i.t, i.contact) for i in runs[1].impacts)
    assert {i.contact for i in runs[1].impacts} >= {"box1.v0/box0.e2", "box0.v2/box1.e0"}
    assert _touched(runs[0]) == sorted(runs[1].contact_names)
    for name in runs[1].contact_names:
        phases = [[(p.mode, p.t_start) for p in run.phases[name]] for run in runs]
        assert phases[0] == phases[1]
