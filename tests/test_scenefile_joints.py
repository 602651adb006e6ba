"""Joints and the forces joints need in scene files: `[[joints]]` (pin, slider), `[[forces]]`
kind torsion-spring and torque; every mistake one line naming the file and the key."""
import copy
import json
import math
from pathlib import Path

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod.scenefile import apply_override, load_scene, parse_scene
from nonsmooth_rod.validation import InputError

SCENES = Path(__file__).resolve().parents[1] / "examples" / "scenes"

TWO_BODIES = {
    "schema": "nonsmooth-rod/scene/1",
    "bodies": [{"name": "arm", "shape": "rod", "length": 1.0, "mass": 1.0},
               {"name": "cart", "mass": 2.0, "inertia": 0.1}],
    "joints": [{"kind": "pin", "name": "hinge", "body_a": "arm", "point_a": [-0.5, 0.0], "body_b": "cart",
                "point_b": [0.0, 0.0]},
               {"kind": "slider", "name": "rail", "body_a": "cart", "axis": [1.0, 0.0]}],
    "forces": [{"kind": "torsion-spring", "name": "spring", "body": "arm", "body_b": "cart", "stiffness": 2.0,
                "rest_angle_deg": 90.0, "damping": 0.1},
               {"kind": "torque", "name": "motor", "body": "arm", "torque": 0.5}],
    "initial": {"arm": {"q": [0.5, 0.0, 0.0]}, "cart": {"q": [0.0, 0.0, 0.0]}},
    "simulation": {"t_end": 0.01, "h": 1e-3},
}


def _with(path: str, value):
    data = copy.deepcopy(TWO_BODIES)
    apply_override(data, f"{path}={value}")
    return data


def test_the_example_pendulum_file_builds_its_pin_and_runs_through_the_impact():
    sf = load_scene(SCENES / "pendulum_wall.toml")
    (pin,) = sf.scene.joints
    assert isinstance(pin, nr.Pin) and (pin.body_a, pin.body_b, pin.point_a, pin.point_b) == (0, None, (-0.5, 0.0),
                                                                                              (0.0, 0.0))
    assert sf.joint_names == ["pivot"]


def test_joints_and_forces_read_by_name():
    sf = parse_scene(TWO_BODIES, "two.toml")
    hinge, rail = sf.scene.joints
    assert (hinge.body_a, hinge.body_b, hinge.point_a) == (0, 1, (-0.5, 0.0))
    assert isinstance(rail, nr.Slider) and rail.body_b is None and rail.axis == (1.0, 0.0) and rail.angle == 0.0
    spring, motor = sf.scene.forces
    assert isinstance(spring, nr.TorsionSpring) and spring.rest_angle == pytest.approx(math.pi / 2)
    assert (spring.body_a, spring.body_b, spring.stiffness, spring.damping) == (0, 1, 2.0, 0.1)
    assert motor.torque == 0.5 and motor.body == 0


def test_a_jointed_file_runs_and_writes_the_reactions_to_trajectory_csv(tmp_path):
    (tmp_path / "two.json").write_text(json.dumps(TWO_BODIES))
    res = nr.simulate_scene(load_scene(tmp_path / "two.json"))
    assert res.status == "ok"
    res.save(tmp_path / "out")
    header = (tmp_path / "out" / "trajectory.csv").read_text().splitlines()[0].split(",")
    assert {"hinge.Fx", "hinge.Fy", "rail.F", "rail.M"} <= set(header)
    loaded = nr.load(tmp_path / "out")  # read back by the scene file's joints
    np.testing.assert_array_equal(loaded.joint_forces["rail"]["F"], res.joint_forces["rail"]["F"])
    # the rail is the only external vertical force but gravity: it carries the weights and the
    # vertical momentum change of the bodies, step by step
    momentum_rate = 1.0 * res.trajectory.a[1:, 1] + 2.0 * res.trajectory.a[1:, 4]
    np.testing.assert_allclose(res.joint_forces["rail"]["F"][1:], momentum_rate + 3.0 * 9.81, rtol=1e-12)


@pytest.mark.parametrize("path, value, message", [
    ("joints.hinge.body_a", '"ghost"', "joints.hinge.body_a: no body named 'ghost'"),
    ("joints.hinge.body_b", '"arm"', "joints.hinge.body_b: joins a body to itself"),
    ("joints.rail.axis", "[0.0, 0.0]", "joints.rail.axis: must be a non-zero direction"),
    ("joints.rail.axis", "[nan, 1.0]", "joints.rail.axis[0]"),
    ("joints.hinge.point_a", "[inf, 0.0]", "joints.hinge.point_a[0]"),
    ("joints.hinge.kind", '"weld"', "joints.hinge.kind: must be one of pin, slider"),
    ("joints.hinge.axis", "[1.0, 0.0]", "joints.hinge.axis: unknown key"),
    ("joints.rail.angle_deg", "nan", "joints.rail.angle_deg"),
    ("joints.hinge.point_a", "[0.5, 0.0]", "joint 'hinge' does not hold at the initial state"),
    ("forces.spring.stiffness", "-1.0", "forces.spring.stiffness: must be non-negative"),
    ("forces.spring.body_b", '"arm"', "forces.spring.body_b: joins a body to itself"),
    ("forces.motor.torque", "inf", "forces.motor.torque"),
])
def test_bad_joints_and_forces_are_one_line_naming_file_and_key(path, value, message):
    with pytest.raises(InputError) as err:
        parse_scene(_with(path, value), "two.toml")
    text = str(err.value)
    assert "\n" not in text and text.startswith("two.toml: ") and message in text, text


def test_a_jointed_file_with_another_method_is_refused_naming_the_joint():
    data = copy.deepcopy(TWO_BODIES)
    data["simulation"] = {"t_end": 0.01, "method": "event-driven"}
    sf = parse_scene(data, "two.toml")
    with pytest.raises(InputError, match="two.toml: simulation: method 'event-driven' does not handle joints"):
        nr.simulate_scene(sf)
