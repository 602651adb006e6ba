"""Joints as data (model/joints.py): the rows are the derivatives of the constraints, the fields
are checked, and the scene refuses what cannot be a joint."""
import math

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod.model.joints import ROWS_PER_JOINT, joint_rows, joint_violation, pack_joints
from nonsmooth_rod.solvers._common import interpreted

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)


def _rows(joints, q):
    table = pack_joints(joints, len(q) // 3)
    J, C = np.zeros((ROWS_PER_JOINT * len(joints), len(q))), np.zeros(ROWS_PER_JOINT * len(joints))
    interpreted(joint_rows)(table, np.asarray(q, float), J, C)
    return J, C


JOINTS = [
    nr.Pin(0, (0.3, -0.2), None, (1.0, 2.0), name="to-world"),
    nr.Pin(0, (0.3, -0.2), 1, (-0.4, 0.1), name="between"),
    nr.Slider(0, (0.2, 0.1), None, (0.5, -1.0), axis=(2.0, 1.0), angle=0.3, name="world-slider"),
    nr.Slider(0, (0.2, 0.1), 1, (0.5, -1.0), axis=(-1.0, 3.0), angle=-0.2, name="body-slider"),
    nr.LinearJoint({1: (0.5, -1.0, 0.25), 0: (0.0, 2.0, -3.0)}, 0.7, name="linear"),
]


@pytest.mark.parametrize("joint", JOINTS, ids=lambda j: j.name)
def test_jacobian_is_the_derivative_of_the_constraint(joint):
    rng = np.random.default_rng(3)
    q = rng.normal(size=6)
    J, _ = _rows([joint], q)
    step = 1e-6
    for d in range(6):
        dq = np.zeros(6)
        dq[d] = step
        numeric = (_rows([joint], q + dq)[1] - _rows([joint], q - dq)[1]) / (2 * step)
        np.testing.assert_allclose(J[:, d], numeric, atol=1e-8)


def test_pin_constraint_is_the_world_gap_of_its_points():
    pin = nr.Pin(0, (1.0, 0.0), None, (0.0, 0.0))
    theta = 0.7
    c = joint_violation([pin], 1, [-math.cos(theta), -math.sin(theta), theta])
    np.testing.assert_allclose(c, 0.0, atol=1e-15)
    assert joint_violation([pin], 1, [0.0, 0.0, 0.0])[0] == pytest.approx(1.0)


def test_linear_joint_is_its_affine_row_and_its_second_row_is_zero():
    joint = nr.LinearJoint({1: (0.5, -1.0, 0.25), 0: (0.0, 2.0, -3.0)}, 0.7, name="linear")
    q = np.array([0.1, 0.2, 0.3, -0.4, 0.5, 0.6])
    J, C = _rows([joint], q)
    assert C[0] == pytest.approx(0.7 + 2.0 * 0.2 - 3.0 * 0.3 + 0.5 * -0.4 - 0.5 + 0.25 * 0.6, abs=1e-15)
    assert J[0].tolist() == [0.0, 2.0, -3.0, 0.5, -1.0, 0.25] and C[1] == 0.0 and not J[1].any()
    assert (joint.body_a, joint.body_b) == (0, 1)


def test_slider_axis_is_normalised_and_a_zero_axis_refused():
    assert nr.Slider(0, axis=(3.0, 4.0)).axis == pytest.approx((0.6, 0.8))
    with pytest.raises(nr.InputError, match="axis must be a non-zero direction"):
        nr.Slider(0, axis=(0.0, 0.0), name="s")


@pytest.mark.parametrize("make, match", [
    (lambda: nr.Pin(0, (0, 0), 0, (0, 0), name="p"), "body_b must differ from body_a"),
    (lambda: nr.Pin(0, (math.nan, 0), name="p"), "point_a"),
    (lambda: nr.Slider(0, axis=(math.inf, 0), name="s"), "axis"),
    (lambda: nr.Pin(-1, name="p"), "body_a"),
    (lambda: nr.LinearJoint({0: (0.0, 0.0, 0.0)}, name="lin"), "lin row: one or two bodies with a non-zero row"),
    (lambda: nr.LinearJoint({0: (1.0, 0.0)}, name="lin"), r"lin row\[0\] must be 3 numbers"),
    (lambda: nr.LinearJoint({0: (1, 0, 0), 1: (1, 0, 0), 2: (1, 0, 0)}, name="lin"), "one or two bodies"),
    (lambda: nr.LinearJoint({0: (1.0, 0.0, 0.0)}, math.inf, name="lin"), "lin constant"),
])
def test_bad_joints_are_refused_in_one_line(make, match):
    with pytest.raises(nr.InputError, match=match) as err:
        make()
    assert "\n" not in str(err.value)


def test_scene_refuses_unknown_bodies_and_duplicate_joint_names():
    body = nr.RigidBody(1.0, 1.0)
    with pytest.raises(nr.InputError, match="body_b refers to body 3"):
        nr.Scene([body], joints=[nr.Pin(0, body_b=3, name="p")])
    with pytest.raises(nr.InputError, match="two joints are named 'p'"):
        nr.Scene([body], joints=[nr.Pin(0, name="p"), nr.Pin(0, name="p")])
    with pytest.raises(nr.InputError, match="must be a Pin, a Slider or a LinearJoint"):
        nr.Scene([body], joints=["p"])
