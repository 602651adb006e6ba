"""Scene files: what they build (checked against the toys' own scenes and closed-form inertias),
overrides by name, and one-line errors naming the file and the key for every malformed input."""
import copy
import json
import math
from pathlib import Path

import numpy as np
import pytest

from nonsmooth_rod import toys
from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.scene_forces import build_force
from nonsmooth_rod.scenefile import apply_override, load_scene, parse_scene
from nonsmooth_rod.validation import InputError

SCENES = Path(__file__).resolve().parents[1] / "examples" / "scenes"

BALL = {
    "schema": "nonsmooth-rod/scene/1",
    "bodies": [{"name": "ball", "shape": "ball", "radius": 0.05, "mass": 1.0}],
    "lines": [{"name": "ground", "angle_deg": 0.0}],
    "contacts": [{"kind": "disk-on-line", "name": "floor", "body": "ball", "radius": 0.05, "line": "ground",
                  "law": {"mu_s": 0.3, "mu_d": 0.2, "restitution": 0.5}}],
    "initial": {"ball": {"q": [0.0, 1.05, 0.0]}},
    "simulation": {"t_end": 0.1, "h": 1e-3},
}


def _with(path: str, value):
    data = copy.deepcopy(BALL)
    apply_override(data, f"{path}={value}")
    return data


def test_ball_file_builds_the_toy_scene():
    sf = load_scene(SCENES / "bouncing_ball.toml")
    toy = toys.BouncingBall()
    body, = sf.scene.bodies
    assert body.mass == toy.mass and body.inertia == pytest.approx(0.4 * toy.mass * toy.radius**2, rel=1e-13)
    q0, v0 = toy.initial_state()
    np.testing.assert_array_equal(sf.q0, q0)
    np.testing.assert_array_equal(sf.v0, v0)
    c, = sf.scene.contacts
    assert (c.radius, c.law.impact.restitution, c.line.angle) == (toy.radius, toy.restitution, 0.0)
    assert sf.contact_names == ["floor"] and sf.body_names == ["ball"] and sf.method == "moreau-jean"


def test_paper_rod_file_matches_rod_problem():
    sf = load_scene(SCENES / "paper_rod.toml")
    p = RodProblem.paper()
    body, = sf.scene.bodies
    assert body.mass == pytest.approx(p.mass, rel=1e-13) and body.inertia == pytest.approx(p.inertia, rel=1e-13)
    q0, _ = p.initial_state()
    np.testing.assert_allclose(sf.q0, q0, rtol=1e-13)
    assert [c.offset for c in sf.scene.contacts] == [(-p.xi, 0.0), (p.length - p.xi, 0.0)]
    assert sf.stop == ["B"]


@pytest.mark.parametrize("shape, dims, inertia", [
    ("disk", {"radius": 0.2}, 2.0 * 0.2**2 / 2),
    ("ball", {"radius": 0.2}, 0.4 * 2.0 * 0.2**2),
    ("rectangle", {"width": 0.3, "height": 0.1}, 2.0 * (0.09 + 0.01) / 12),
    ("rod", {"length": 1.5}, 2.0 * 1.5**2 / 12),
])
def test_shapes_give_the_textbook_inertia(shape, dims, inertia):
    data = copy.deepcopy(BALL)
    data["bodies"][0] = {"name": "ball", "shape": shape, "mass": 2.0, **dims}
    data["contacts"] = []
    sf = parse_scene(data)
    assert sf.scene.bodies[0].inertia == pytest.approx(inertia, rel=1e-13)
    assert sf.shapes["ball"] == {"shape": shape, **dims}


def test_density_gives_the_mass_of_a_steel_ball():
    data = copy.deepcopy(BALL)
    data["bodies"][0] = {"name": "ball", "shape": "ball", "radius": 0.02, "density": 7800.0}
    assert parse_scene(data).scene.bodies[0].mass == pytest.approx(7800 * 4 / 3 * math.pi * 0.02**3, rel=1e-13)


def test_json_and_toml_read_the_same(tmp_path):
    sf = load_scene(SCENES / "ladder.toml")
    path = tmp_path / "ladder.json"
    path.write_text(json.dumps(sf.data))
    again = load_scene(path)
    np.testing.assert_array_equal(again.q0, sf.q0)
    assert again.scene.contacts == sf.scene.contacts


def test_overrides_reach_entries_by_name():
    sf = load_scene(SCENES / "ladder.toml", ["contacts.foot.law.mu_s=0.2", "contacts.foot.law.mu_d=0.1",
                                             "simulation.moreau-jean.h=5e-4", "initial.ladder.v=[0.1, 0, 0]"])
    foot = sf.scene.contacts[0]
    assert (foot.law.friction.mu_s, foot.law.friction.mu_d) == (0.2, 0.1)
    assert sf.options["h"] == 5e-4 and sf.v0[0] == 0.1
    assert sf.data["contacts"][0]["law"]["mu_s"] == 0.2  # the summary records what ran


def test_spring_force_pulls_towards_its_anchor_with_k_times_stretch():
    spring = build_force("spring", body_a=0, point_a=(0.0, -0.1), point_b=(0.0, 0.0), stiffness=100.0,
                         rest_length=0.0, damping=2.0, name="s")
    q = np.array([0.3, 0.1, 0.0])  # the attachment point sits at (0.3, 0): stretched 0.3 m along x
    v = np.array([0.5, 0.0, 0.0])
    f = spring.generalised_force(0.0, q, v, 3)
    tension = 100.0 * 0.3 + 2.0 * 0.5  # k stretch + c d(stretch)/dt
    # force (-tension, 0) at the lever (0, -0.1): torque (0)(0) - (-0.1)(-tension) = -0.1 tension
    np.testing.assert_allclose(f, [-tension, 0.0, -0.1 * tension], rtol=0, atol=500 * np.finfo(float).eps * tension)


def test_ramped_force_scales_linearly_between_its_times():
    ramp = build_force("ramped", body=0, force=(10.0, 0.0), t_start=1.0, t_full=3.0, name="r")
    assert [ramp.generalised_force(t, np.zeros(3), np.zeros(3), 3)[0] for t in (0.0, 2.0, 5.0)] == [0.0, 5.0, 10.0]


BAD = [
    ("bodies.ball.mass", "-1", "bodies.ball.mass: must be positive"),
    ("bodies.ball.mass", "nan", "bodies.ball.mass: must be finite"),
    ("bodies.ball.mass", '"heavy"', "bodies.ball.mass: must be a number"),
    ("bodies.ball.colour", '"red"', "bodies.ball.colour: unknown key"),
    ("bodies.ball.shape", '"cube"', "bodies.ball.shape: must be one of"),
    ("bodies.ball.width", "0.1", "bodies.ball.width: not a dimension of a ball: it takes radius, density"),
    ("bodies.ball.density", "7800", "bodies.ball.density: give mass or density, not both"),
    ("contacts.floor.body", '"bal"', "contacts.floor.body: no body named 'bal' (have: ball)"),
    ("contacts.floor.line", '"wall"', "contacts.floor.line: no line named 'wall'"),
    ("contacts.floor.kind", '"disk-on-cube"', "contacts.floor.kind: must be one of"),
    ("contacts.floor.law.mu_d", "0.5", "contacts.floor.law.mu_d: 0.5 exceeds mu_s = 0.3"),
    ("contacts.floor.law.restitution", "1.5", "contacts.floor.law.restitution: must lie in [0, 1]"),
    ("contacts.floor.law.mu", "0.5", "contacts.floor.law.mu: unknown key"),
    ("contacts.floor.offset", "[0, 0, 0]", "contacts.floor.offset: must be a list of 2 numbers"),
    ("lines.ground.angle", "30", "lines.ground.angle: angles of lines are given in degrees"),
    ("initial.ball.q", "[0, 0.01, 0]", "contact 'floor' starts overlapping by 0.04 m"),
    ("initial.ball.q", "[0, 1]", "initial.ball.q: must be a list of 3 numbers"),
    ("initial.box.q", "[0, 1, 0]", "initial.box: unknown key"),
    ("simulation.method", '"rk4"', "simulation.method: must be one of moreau-jean"),
    ("simulation.t_end", "0", "simulation.t_end: must be positive"),
    ("simulation.h", "-1e-3", "simulation: h (step size) must be positive"),
    ("simulation.rtol", "1e-6", "simulation.rtol: unknown key"),
    ("simulation.solver", '"magic"', "simulation: unknown solver 'magic'"),
    ("simulation.stop", '"flor"', "simulation.stop: no contact named 'flor'"),
    ("simulation.stop", '["floor", "floor"]', "simulation.stop: one contact at a time"),
    ("simulation.moreau-jean.h", "1e-4", "simulation.h: given twice: also as simulation.moreau-jean.h"),
    ("simulation.event-driven.h", "1e-4", "simulation.event-driven.h: unknown key"),
    # another method's table is checked by value too: --set simulation.method=… would run it
    ("simulation.event-driven.rtol", "-1", "simulation.event-driven: rtol must lie in"),
    ("simulation.event-driven.rtol", "nan", "simulation.event-driven.rtol: must be finite"),
    ("simulation.hybrid.h", "0", "simulation.hybrid: h (step size) must lie in"),
    ("schema", '"nonsmooth-rod/scene/9"', "schema: must be 'nonsmooth-rod/scene/1'"),
    ("gravity", "inf", "gravity: must be finite"),
    ("title", "1979-05-27", "title: must be a number, string, list or table, got datetime.date"),
    ("simulation.moreau-jean.solver_options", "{ when = 07:32:00 }",
     "simulation.moreau-jean.solver_options.when: must be a number, string, list or table"),
]


@pytest.mark.parametrize("path, value, message", BAD, ids=[f"{p}={v}" for p, v, _ in BAD])
def test_bad_values_are_one_line_naming_file_and_key(path, value, message):
    with pytest.raises(InputError) as err:
        parse_scene(_with(path, value), source="my.toml")
    text = str(err.value)
    assert text.startswith("my.toml: ") and message in text and "\n" not in text


@pytest.mark.parametrize("edit, message", [
    (lambda d: d["bodies"].append({"name": "ball", "mass": 1, "inertia": 1}), "bodies.ball: duplicate name"),
    (lambda d: d["bodies"][0].pop("name"), "bodies[0].name: missing"),
    (lambda d: d["bodies"][0].update(name="a.b"), "bodies[0].name: must be letters"),
    (lambda d: d.pop("initial"), "initial: missing"),
    (lambda d: d.pop("simulation"), "simulation: missing"),
    (lambda d: d["initial"].pop("ball"), "initial.ball: missing"),
    (lambda d: d.update(bodies=[]), "bodies: a scene needs at least one"),
    (lambda d: d.update(extra=1), "extra: unknown key"),
    (lambda d: d["contacts"].append({"kind": "disk-on-disk", "name": "dd", "body_a": "ball", "body_b": "ball",
                                     "radius_a": 0.1, "radius_b": 0.1}), "contacts.dd.body_b: a disk-on-disk"),
    (lambda d: d.update(forces=[{"kind": "ramped", "name": "p", "body": "ball", "force": [1, 0],
                                 "t_start": 1.0, "t_full": 1.0}]), "forces.p.t_full: must exceed t_start"),
    (lambda d: d.update(forces=[{"kind": "tabulated", "name": "tab", "body": "ball", "times": [0, 1],
                                 "forces": [[1, 0]]}]), "forces.tab.forces: must be a list of 2"),
    (lambda d: d.update(forces=[{"kind": "spring", "name": "s", "body": "ghost", "stiffness": 1}]),
     "forces.s.body: no body named 'ghost'"),
    (lambda d: d.update(forces=[{"kind": "spring", "name": "s", "body": "ball", "body_b": "ball", "stiffness": 1}]),
     "forces.s.body_b: joins a body to itself"),
    (lambda d: d["contacts"][0].pop("line"), "contacts.floor.line: missing: name a line (have: ground)"),
])
def test_bad_structure_is_one_line(edit, message):
    data = copy.deepcopy(BALL)
    edit(data)
    with pytest.raises(InputError) as err:
        parse_scene(data, source="my.toml")
    assert message in str(err.value) and "\n" not in str(err.value) and str(err.value).startswith("my.toml")


def test_unreadable_and_malformed_files(tmp_path):
    with pytest.raises(InputError, match="cannot read the scene file"):
        load_scene(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("schema = \n")
    with pytest.raises(InputError, match=r"bad\.toml: not valid TOML: .*line 1"):
        load_scene(bad)
    bad_json = tmp_path / "bad.json"
    bad_json.write_text("{")
    with pytest.raises(InputError, match="not valid JSON"):
        load_scene(bad_json)


@pytest.mark.parametrize("assignment, message", [
    ("contacts.flor.law.mu_s=0.3", "no entry named 'flor'"),
    ("contacts.floor.law.mu_s", "expected PATH=VALUE"),
    ("contacts..mu_s=1", "empty key"),
])
def test_bad_overrides(assignment, message):
    with pytest.raises(InputError, match=message):
        apply_override(copy.deepcopy(BALL), assignment)


def test_driver_refusals_name_the_file():
    from nonsmooth_rod.scenefile import simulate_scene

    sf = parse_scene(_with("simulation.t_end", "1e12"), source="my.toml")
    with pytest.raises(InputError, match=r"^my\.toml: simulation: the run would keep 1e\+15 samples .*larger h"):
        simulate_scene(sf)
    data = copy.deepcopy(BALL)
    data["bodies"].append({"name": "other", "shape": "ball", "radius": 0.05, "mass": 1.0})
    data["initial"]["other"] = {"q": [1.0, 1.05, 0.0]}
    data["contacts"].append({"kind": "disk-on-disk", "name": "balls", "body_a": "other", "body_b": "ball",
                             "radius_a": 0.05, "radius_b": 0.05})
    data["simulation"] = {"method": "event-driven", "t_end": 0.1}
    with pytest.raises(InputError, match=r"^my\.toml: simulation: method 'event-driven' does not handle DiskOnDisk"):
        simulate_scene(parse_scene(data, source="my.toml"))


HOSTILE = ["x", -1.0, 0, math.nan, math.inf, [], {}, True, None, 1e308, -1e308, 1e-308, [1.0], [1.0, 2.0],
           [[1, 2]], {"a": 1}]


def _leaves(node, path=()):
    """Every key path of a scene's content (the lists themselves and their items)."""
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _leaves(v, path + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _leaves(v, path + (i,))
    if path:
        yield path


# Shipped scenes of many repeated bodies, cut to their first two for the hostile values (every
# key of a body is the same key in each; parsing the whole row thousands of times takes minutes).
CUT_TO_TWO = {"dominoes"}


def _first_two_bodies(data):
    keep = [b["name"] for b in data["bodies"][:2]]
    for body in data["bodies"][:2]:
        if "collides_with" in body:
            body["collides_with"] = [x for x in body["collides_with"] if x in keep or x not in
                                     {b["name"] for b in data["bodies"]}]
    data["bodies"] = data["bodies"][:2]
    data["initial"] = {k: v for k, v in data["initial"].items() if k in keep}
    return data


@pytest.mark.parametrize("name", sorted(p.stem for p in SCENES.glob("*.toml")))
def test_hostile_values_anywhere_are_refused_in_one_line_or_give_a_finite_scene(name):
    """Every key of every shipped scene set to each hostile value (JSON null included): the
    result is a one-line InputError or a scene with finite masses and state, never a raw error
    or a numpy overflow warning (6288 cases in all, about 2 s)."""
    import warnings

    from nonsmooth_rod.scenefile import read_data

    data, _ = read_data(SCENES / f"{name}.toml")
    if name in CUT_TO_TWO:
        data = _first_two_bodies(data)
    for path in list(_leaves(data)):
        for value in HOSTILE:
            changed = copy.deepcopy(data)
            node = changed
            for k in path[:-1]:
                node = node[k]
            node[path[-1]] = value
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                try:
                    sf = parse_scene(changed, source="f.toml")
                except InputError as err:
                    assert "\n" not in str(err) and str(err).startswith("f.toml: "), (path, value)
                    continue
            assert np.all(np.isfinite(sf.scene.mass_diagonal)) and np.all(np.isfinite(sf.q0)), (path, value)


def _pushed_block_with(force: dict, **law):
    from nonsmooth_rod.scenefile import read_data

    data, _ = read_data(SCENES / "pushed_block.toml")
    data["forces"] = [{"name": "push", "body": "block", "point": [0.0, -0.025], **force}]
    for contact in data["contacts"]:
        contact["law"].update(law)
    data["simulation"]["t_end"] = 0.3
    return parse_scene(data)


@pytest.mark.parametrize("force, position", [
    # F = 10 N/s · t as a table: sticks until 0.4905 s > t_end, so the block stays put
    ({"kind": "tabulated", "times": [0.0, 10.0], "forces": [[0.0, 0.0], [100.0, 0.0]]}, lambda t: 0 * t),
    # 6 N > mu_s m g = 4.905 N from the start: slides at (F - mu_d m g)/m
    ({"kind": "constant", "force": [6.0, 0.0]}, lambda t: 0.5 * (6.0 - 0.3 * 9.81) * t**2),
])
def test_forces_of_each_kind_give_the_closed_form_motion(force, position):
    from nonsmooth_rod.scenefile import simulate_scene

    result = simulate_scene(_pushed_block_with(force))
    np.testing.assert_allclose(result.trajectory.q[:, 0], position(result.t), atol=1e-12)  # 1e-19 (table), 4e-16 m (constant) measured


def test_a_damper_to_the_wall_slows_a_sliding_block_exponentially():
    from nonsmooth_rod.scenefile import simulate_scene

    sf = _pushed_block_with({"kind": "damper", "point_b": [-100.0, -0.0], "damping": 2.0}, mu_s=0.0, mu_d=0.0)
    sf.v0[0] = 1.0
    result = simulate_scene(sf)
    # a long horizontal damper: ẍ = −(c/m) ẋ, ẋ = e^{−2t}. Moreau–Jean takes applied forces at the
    # step's start velocity, first order: (1 − 2h)^k vs e^{−2kh}, relative 2 h t = 6e-4 at t = 0.3 s
    np.testing.assert_allclose(result.trajectory.v[:, 0], np.exp(-2.0 * result.t), rtol=1e-3)
    assert result.trajectory.v[-1, 0] < np.exp(-2.0 * result.t[-1])  # and on the damped side


def test_the_docs_python_example_runs(monkeypatch):
    import re

    doc = SCENES.parents[1] / "docs" / "scene-format.md"
    code, = re.findall(r"```python\n(.*?)```", doc.read_text(encoding="utf-8"), flags=re.DOTALL)
    monkeypatch.chdir(SCENES.parents[1])
    namespace = {}
    exec(compile(code, str(doc), "exec"), namespace)  # noqa: S102 (the doc's own example)
    result = namespace["result"]
    assert result.success and [p.mode for p in result.phases["foot"]] == ["slip+"]  # mu_s = 0.2 < cot 60° / 2


@pytest.mark.parametrize("edit, message", [
    (lambda d: d["segments"][0].update(b=[-1.0, 0.0]), "segments.table.b: equals a = [-1.0, 0.0]: a segment of length 0"),
    (lambda d: d["segments"][0].pop("b"), "segments.table.b: missing"),
    (lambda d: d["segments"][0].update(point=[0, 0]), "segments.table.point: unknown key"),
    (lambda d: d["contacts"][0].update(segment="tabel"), "contacts.edge.segment: no segment named 'tabel' (have: table)"),
    (lambda d: d["contacts"][0].update(kind="point-on-segment"), "contacts.edge.radius: unknown key"),
    (lambda d: d["contacts"][0].update(line="table"), "contacts.edge.line: unknown key"),
    (lambda d: d["initial"]["disk"].update(q=[-0.5, 0.05, 0.0]), "contact 'edge' starts overlapping by 0.05 m"),
])
def test_segments_and_their_contacts_read_from_a_file_and_refuse_mistakes_in_one_line(edit, message):
    from nonsmooth_rod.model.contacts import DiskOnSegment

    sf = load_scene(SCENES / "ball_off_table.toml")
    (contact,) = sf.scene.contacts
    assert isinstance(contact, DiskOnSegment) and contact.radius == 0.1 and list(sf.segments) == ["table"]
    assert (contact.segment.a, contact.segment.b, contact.segment.normal) == ((-1.0, 0.0), (0.0, 0.0), (-0.0, 1.0))
    data = copy.deepcopy(sf.data)
    edit(data)
    with pytest.raises(InputError) as err:
        parse_scene(data, source="my.toml")
    assert message in str(err.value) and "\n" not in str(err.value) and str(err.value).startswith("my.toml")


def test_a_segment_end_on_a_box_edge_reads_from_a_file_and_refuses_a_zero_edge():
    from nonsmooth_rod.model.contacts import SegmentEndOnEdge

    data = {"schema": "nonsmooth-rod/scene/1", "bodies": [{"name": "box", "shape": "rectangle", "width": 0.2,
                                                           "height": 0.1, "mass": 1.0}],
            "segments": [{"name": "table", "a": [-1.0, 0.0], "b": [0.0, 0.0]}],
            "contacts": [{"kind": "segment-end-on-edge", "name": "edge", "body": "box", "segment": "table",
                          "edge_start": [-0.1, -0.05], "edge_end": [0.1, -0.05], "law": {"mu_s": 0.3}}],
            "initial": {"box": {"q": [-0.05, 0.05, 0.0]}}, "simulation": {"t_end": 0.1}}
    (edge,) = parse_scene(copy.deepcopy(data), source="box.toml").scene.contacts
    assert isinstance(edge, SegmentEndOnEdge) and edge.end == "b" and edge.edge_end == (0.1, -0.05)
    assert edge.kinematics(np.array([-0.05, 0.05, 0.0]), np.zeros(3), 3).gap == 0.0  # the end under the bottom
    data["contacts"][0]["edge_end"] = [-0.1, -0.05]
    with pytest.raises(InputError, match=r"^box.toml: contacts.edge.edge_end: equals edge_start = \[-0.1, -0.05\]"):
        parse_scene(data, source="box.toml")
    data["contacts"][0].update(edge_end=[0.1, -0.05], end="c")
    with pytest.raises(InputError, match=r"^box.toml: contacts.edge.end: must be one of"):
        parse_scene(data, source="box.toml")


def test_save_every_in_a_scene_file_thins_the_kept_samples_and_keeps_the_events():
    from nonsmooth_rod.scenefile import load_scene, simulate_scene

    every = simulate_scene(load_scene(SCENES / "bouncing_ball.toml"))
    thinned = simulate_scene(load_scene(SCENES / "bouncing_ball.toml", ["simulation.save_every=0.1"]))
    assert len(every.t) > 900 and len(thinned.t) == 11  # t_end = 1 s, one sample per 0.1 s
    assert thinned.t[-1] == every.t[-1] == 1.0
    assert [i.t for i in thinned.impacts] == [i.t for i in every.impacts]  # located in the run, not sampled
    assert len(thinned.restart(t_end=1.5).t) == 6  # a restart keeps the file's save_every (1.0 … 1.5 s)
    with pytest.raises(InputError, match="simulation.save_every"):
        load_scene(SCENES / "bouncing_ball.toml", ["simulation.save_every=-1"])
