"""Scene files whose shapes collide (scene_collisions.py): polygon bodies, found contacts, `collide`,
`group`, `[[laws]]` by pair, overlaps at the start — every mistake one line naming its key."""
import math

import numpy as np
import pytest

from nonsmooth_rod.scenefile import parse_scene
from nonsmooth_rod.validation import InputError

TRIANGLE = [[-0.1, -0.1 / 3], [0.1, -0.1 / 3], [0.0, 0.2 / 3]]  # centroid at the origin


def _scene(bodies, initial, **extra):
    data = {"schema": "nonsmooth-rod/scene/1", "bodies": bodies, "lines": [{"name": "floor"}],
            "initial": {name: {"q": q} for name, q in initial.items()}, "simulation": {"t_end": 0.01, "h": 1e-3}}
    data.update(extra)
    return parse_scene(data, "s.toml")


def test_a_polygon_body_collides_with_the_floor_and_a_box():
    sf = _scene([{"name": "tri", "shape": "polygon", "vertices": TRIANGLE, "mass": 1.0},
                 {"name": "box", "shape": "rectangle", "width": 0.4, "height": 0.2, "mass": 2.0}],
                {"tri": [0.0, 0.1 / 3 + 0.2, 0.0], "box": [0.0, 0.1, 0.0]})
    names = sf.contact_names
    assert "tri.v0/floor" in names and "box.v3/floor" in names and "tri.v1/box.e2" in names
    assert "box.v0/tri.e1" in names and len(names) == 3 + 4 + 2 * 3 * 4
    # J of the triangle about its centroid: m (a² + b² + c²)/36 for sides a, b, c
    sides = [math.dist(TRIANGLE[i], TRIANGLE[(i + 1) % 3]) for i in range(3)]
    assert sf.scene.bodies[0].inertia == pytest.approx(sum(s * s for s in sides) / 36, rel=1e-12)


def test_laws_by_pair_and_collide_false():
    sf = _scene([{"name": "a", "shape": "disk", "radius": 0.1, "mass": 1.0},
                 {"name": "b", "shape": "ball", "radius": 0.1, "mass": 1.0},
                 {"name": "ghost", "shape": "disk", "radius": 0.1, "mass": 1.0, "collide": False}],
                {"a": [0.0, 0.1, 0.0], "b": [0.2, 0.1, 0.0], "ghost": [0.1, 0.1, 0.0]},
                laws=[{"between": ["*", "floor"], "mu_s": 0.5, "mu_d": 0.4},
                      {"between": ["b", "floor"], "mu_s": 0.9}, {"between": ["a", "b"], "restitution": 0.5}])
    laws = {c.name: c.law for c in sf.scene.contacts}
    assert sorted(laws) == ["a/b", "a/floor", "b/floor"]
    assert laws["a/floor"].friction.mu_d == 0.4 and laws["b/floor"].friction.mu_s == 0.9
    assert laws["a/b"].impact.restitution == 0.5 and laws["a/b"].friction.mu_s == 0.0


def test_collides_with_lists_what_a_body_meets():
    disks = [{"name": n, "shape": "disk", "radius": 0.1, "mass": 1.0} for n in "abc"]
    disks[0]["collides_with"] = ["b", "floor"]
    sf = _scene(disks, {"a": [0.0, 0.1, 0.0], "b": [0.2, 0.1, 0.0], "c": [0.4, 0.1, 0.0]})
    assert sorted(sf.contact_names) == ["a/b", "a/floor", "b/c", "b/floor", "c/floor"]  # no a/c
    disks[0]["collides_with"] = ["b"]
    sf = _scene(disks, {"a": [0.0, 0.1, 0.0], "b": [0.2, 0.1, 0.0], "c": [0.4, 0.1, 0.0]})
    assert "a/floor" not in sf.contact_names
    for bad, message in ((["d"], "'d' names no body"), ("b", "must be a list")):
        disks[0]["collides_with"] = bad
        with pytest.raises(InputError, match=f"^s.toml: bodies.a.collides_with: .*{message}"):
            _scene(disks, {"a": [0.0, 0.1, 0.0], "b": [0.2, 0.1, 0.0], "c": [0.4, 0.1, 0.0]})


def test_declared_contacts_keep_their_pair():
    sf = _scene([{"name": "box", "shape": "rectangle", "width": 0.4, "height": 0.2, "mass": 1.0}],
                {"box": [0.0, 0.1, 0.0]},
                contacts=[{"kind": "point-on-line", "name": "left", "body": "box", "offset": [-0.2, -0.1],
                           "line": "floor"}])
    assert sf.contact_names == ["left"]  # a pair with a declared contact is not searched


@pytest.mark.parametrize("body, key, message", [
    ({"vertices": [[0, 0], [0, 1], [1, 0]]}, "bodies.p.vertices", "clockwise"),
    ({"vertices": [[-1, -1], [1, -1], [0, -0.9], [0, 1]]}, "bodies.p.vertices", "not convex"),
    ({"vertices": [[0, 0], [1, 0], [2, 0]]}, "bodies.p.vertices", "area 0"),
    ({"vertices": [[0, 0], [1, 0], [0, 1]]}, "bodies.p.vertices", "centroid"),
    ({"vertices": [[0, 0], [1]]}, "bodies.p.vertices", "list of"),
    ({"vertices": TRIANGLE, "collide": "yes"}, "bodies.p.collide", "true or false"),
])
def test_bad_polygons_are_one_line_errors(body, key, message):
    with pytest.raises(InputError, match=f"^s.toml: {key}: .*{message}") as err:
        _scene([{"name": "p", "shape": "polygon", "mass": 1.0, **body}], {"p": [0.0, 1.0, 0.0]})
    assert "\n" not in str(err.value)


def test_a_law_naming_nothing_and_overlapping_shapes_are_one_line_errors():
    ball = [{"name": "b", "shape": "disk", "radius": 0.1, "mass": 1.0}]
    with pytest.raises(InputError, match=r"^s.toml: laws\[0\].between: 'flor' names no body, line or segment$"):
        _scene(ball, {"b": [0.0, 0.1, 0.0]}, laws=[{"between": ["b", "flor"], "mu_s": 0.2}])
    with pytest.raises(InputError, match=r"^s.toml: initial: contact 'b/floor' starts overlapping by 0.05 m"):
        _scene(ball, {"b": [0.0, 0.05, 0.0]})
    with pytest.raises(InputError, match=r"^s.toml: segments.t.b: .*length 0"):
        _scene(ball, {"b": [0.0, 0.1, 0.0]}, segments=[{"name": "t", "a": [0, 1], "b": [0, 1]}])


def test_the_example_block_slides_off_the_table():
    from pathlib import Path

    from nonsmooth_rod.scenefile import load_scene, simulate_scene

    sf = load_scene(Path(__file__).resolve().parents[1] / "examples" / "scenes" / "box_off_table.toml",
                    ["simulation.t_end=0.6"])
    result = simulate_scene(sf)
    touched = sorted(k for k in result.contact_names if any(p.mode != "open" for p in result.phases[k]))
    assert touched == ["block.v0/table.side+", "block.v1/table.side+", "table.b/block.e0"]
    assert result.trajectory.q[-1, 1] < 0.8 and np.isfinite(result.trajectory.q).all()


def test_a_rod_with_balls_collides_by_its_two_balls():
    rod = {"name": "rod", "shape": "rod-with-balls", "ball_radius": 0.025, "rod_diameter": 0.01, "length": 0.3,
           "density": 7800.0}
    sf = _scene([rod], {"rod": [0.0, 0.025, 0.0]})
    assert sf.contact_names == ["rod.s0/floor", "rod.s1/floor"]
    assert [c.offset for c in sf.scene.contacts] == [(-0.15, 0.0), (0.15, 0.0)]
