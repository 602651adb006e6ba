"""Linear relations and linear joints in scene files: `[[contacts]] kind = "linear"` and
`[[joints]] kind = "linear"`, rows per body name; every mistake one line naming the file and key;
a run made without a file describes them as the file would."""
import copy

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod.model.contacts import LinearRelation
from nonsmooth_rod.model.joints import LinearJoint
from nonsmooth_rod.scenefile import parse_scene
from nonsmooth_rod.validation import InputError

# A block on an incline of slope 1/2, written linearly: the joint holds y = x/2 (a rail), the
# contact is a wall across the rail at x = 1 (gap 1 − x − 0.1, the block's half-width 0.1).
RAIL = {
    "schema": "nonsmooth-rod/scene/1",
    "bodies": [{"name": "block", "mass": 2.0, "inertia": 0.1}],
    "contacts": [{"kind": "linear", "name": "stop", "gap0": 0.9, "normal": {"block": [-1.0, 0.0, 0.0]},
                  "law": {"restitution": 0.5}}],
    "joints": [{"kind": "linear", "name": "rail", "row": {"block": [0.5, -1.0, 0.0]}}],
    "initial": {"block": {"q": [0.0, 0.0, 0.0], "v": [1.0, 0.5, 0.0]}},
    "simulation": {"t_end": 0.3, "h": 1e-3},
    "gravity": [2.0, 0.0],
}


def test_a_linear_contact_and_joint_read_from_a_file_and_run():
    sf = parse_scene(copy.deepcopy(RAIL))
    (stop,), (rail,) = sf.scene.contacts, sf.scene.joints
    assert isinstance(stop, LinearRelation) and stop.normal == {0: (-1.0, 0.0, 0.0)} and stop.gap0 == 0.9
    assert stop.tangent == {} and stop.law.impact.restitution == 0.5
    assert isinstance(rail, LinearJoint) and rail.row == {0: (0.5, -1.0, 0.0)} and rail.constant == 0.0
    result = nr.simulate(sf.scene, sf.q0, sf.v0, 0.7, h=1e-3)
    # along the rail u = (2, 1)/√5 gravity (2, 0) pulls with 2·2/√5, so ẍ = (4/√5)(2/√5) = 1.6 m/s²
    assert np.max(np.abs(result.q[:, 1] - 0.5 * result.q[:, 0])) < 1e-14  # the joint, to round-off
    (impact,) = result.impacts
    t_hit = (-1.0 + np.sqrt(1.0 + 2 * 1.6 * 0.9)) / 1.6  # 0.9 = 1.0 t + 0.8 t²
    assert impact.t == pytest.approx(t_hit, abs=1e-3)
    k = int(np.argmax(result.v[:, 0]))  # the landing step's start: Newton's law on its velocity
    assert result.v[k + 1, 0] == pytest.approx(-0.5 * result.v[k, 0], rel=1e-12)
    assert result.v[k + 1, 1] == pytest.approx(0.5 * result.v[k + 1, 0], rel=1e-12)
    # the rail's reaction F·row cancels the weight's part across it: −(m g·n) n = (−0.8, 1.6) N,
    # n = (1, −2)/√5
    free = result.t < t_hit - 0.01
    force = result.joint_forces["rail"]["F"][free][1:] * np.array([0.5, -1.0])[:, None]
    assert force.T == pytest.approx(np.tile([-2.0 * 2 / 5, 2.0 * 4 / 5], (force.shape[1], 1)), rel=1e-9)


def test_a_run_without_a_file_describes_linear_contacts_and_joints_as_the_file_would():
    from nonsmooth_rod.result_files import scene_description

    sf = parse_scene(copy.deepcopy(RAIL))
    data = scene_description(nr.simulate(sf.scene, sf.q0, sf.v0, 0.002, h=1e-3))
    again = parse_scene(RAIL | {"contacts": data["contacts"],
                                "joints": [{"kind": "linear", "name": "rail", "row": data["joints"][0]["row"]}]})
    assert again.scene.contacts[0].__dict__ == sf.scene.contacts[0].__dict__
    assert again.scene.joints == sf.scene.joints


def _with(section: str, **changes):
    data = copy.deepcopy(RAIL)
    data[section][0].update(changes)
    return data


@pytest.mark.parametrize("data, message", [
    (_with("contacts", normal={"blok": [1.0, 0.0, 0.0]}), "contacts.stop.normal.blok: no body named 'blok'"),
    (_with("contacts", normal={"block": [1.0, 0.0]}), r"contacts.stop.normal.block: must be a list of 3 numbers"),
    (_with("contacts", normal={"block": [0.0, 0.0, 0.0]}), "contacts.stop: .*normal row is zero"),
    (_with("contacts", normal=[1.0, 0.0, 0.0]), r"contacts.stop.normal: must be a table \{ <body>"),
    (_with("contacts", tangent={"block": [0.0, 1.0, "x"]}), r"contacts.stop.tangent.block\[2\]"),
    (_with("contacts", law={"mu_s": 0.3}), "contacts.stop: .*needs a non-zero tangent row"),
    (_with("contacts", radius=0.1), "contacts.stop.radius: unknown key"),
    (_with("joints", row={"block": [0.0, 0.0, 0.0]}), "joints.rail: .*non-zero row"),
    (_with("joints", row={"nobody": [0.0, 1.0, 0.0]}), "joints.rail.row.nobody: no body named 'nobody'"),
])
def test_bad_linear_contacts_and_joints_are_one_line_naming_file_and_key(data, message):
    with pytest.raises(InputError, match=message) as err:
        parse_scene(data, "s.toml")
    assert str(err.value).startswith("s.toml: ") and "\n" not in str(err.value)
