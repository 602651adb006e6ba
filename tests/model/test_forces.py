"""Applied forces as data: each law against its closed form, validation, and the engine using them."""
import math

import numpy as np
import pytest

from nonsmooth_rod import _jit
from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import Line, PointOnLine
from nonsmooth_rod.model.forces import ConstantForce, Damper, RampedForce, Spring, TabulatedForce
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.model.scene import Scene
from nonsmooth_rod.validation import InputError


def test_spring_to_a_world_point_pulls_along_the_line_with_its_lever_arm():
    spring = Spring(0, (0.5, 0.0), None, (3.0, 4.0), stiffness=10.0, rest_length=2.0)
    q = np.array([0.0, 0.0, math.pi / 2])  # the point (0.5, 0) of the body is at (0, 0.5)
    f = spring.generalised_force(0.0, q, np.zeros(3), 3)
    d = np.array([0.0, 0.5])
    e = np.array([3.0, 4.0]) - d
    length = np.linalg.norm(e)
    force = 10.0 * (length - 2.0) * e / length
    assert f == pytest.approx([force[0], force[1], d[0] * force[1] - d[1] * force[0]], rel=1e-13)


def test_spring_between_bodies_is_equal_and_opposite_and_damper_reads_the_stretch_rate():
    spring = Spring(0, (0.0, 0.0), 1, (0.0, 0.0), stiffness=5.0, rest_length=1.0, damping=2.0)
    q = np.array([0.0, 0.0, 0.0, 3.0, 0.0, 0.0])
    v = np.array([0.0, 0.0, 0.0, 0.5, 0.0, 0.0])  # separating at 0.5 m/s
    f = spring.generalised_force(0.0, q, v, 6)
    tension = 5.0 * 2.0 + 2.0 * 0.5
    assert f == pytest.approx([tension, 0, 0, -tension, 0, 0], rel=1e-13)
    damper = Damper(0, body_b=1, damping=2.0)
    assert damper.generalised_force(0.0, q, v, 6) == pytest.approx([1.0, 0, 0, -1.0, 0, 0], rel=1e-13)


def test_ramped_and_tabulated_forces_in_time():
    ramp = RampedForce(0, (2.0, 0.0), torque=1.0, t_start=1.0, t_full=3.0)
    q = np.zeros(3)
    assert ramp.generalised_force(0.5, q, q, 3) == pytest.approx([0, 0, 0])
    assert ramp.generalised_force(2.0, q, q, 3) == pytest.approx([1.0, 0, 0.5])
    assert ramp.generalised_force(9.0, q, q, 3) == pytest.approx([2.0, 0, 1.0])
    table = TabulatedForce(0, (0.0, 1.0, 3.0), ((0, 0), (2, 4), (2, 0)), torques=(0, 1, 1), point=(0.0, 1.0))
    assert table.generalised_force(-1.0, q, q, 3) == pytest.approx([0, 0, 0])
    assert table.generalised_force(0.5, q, q, 3) == pytest.approx([1.0, 2.0, 0.5 - 1.0])  # torque − y·fx
    assert table.generalised_force(2.0, q, q, 3) == pytest.approx([2.0, 2.0, 1.0 - 2.0])
    assert table.generalised_force(5.0, q, q, 3) == pytest.approx([2.0, 0.0, 1.0 - 2.0])


@pytest.mark.parametrize("make, field", [
    (lambda: Spring(-1, stiffness=1.0), "body_a"),
    (lambda: Spring(0, stiffness=-1.0), "stiffness"),
    (lambda: Spring(0, (1.0,), stiffness=1.0), "point_a"),
    (lambda: ConstantForce(0, (math.nan, 0.0)), "force"),
    (lambda: RampedForce(0, (1.0, 0.0), t_start=2.0, t_full=1.0), "t_full"),
    (lambda: TabulatedForce(0, (0.0, 0.0), ((0, 0), (1, 1))), "times"),
    (lambda: TabulatedForce(0, (0.0, 1.0), ((0, 0),)), "forces"),
])
def test_bad_force_fields_are_one_line_input_errors(make, field):
    with pytest.raises(InputError, match=field):
        make()


def _block(forces=(), applied_force=None):
    law = ContactLaw.of(0.5, 0.3)
    corners = [PointOnLine(0, (-0.1, -0.05), Line(), law, "left"), PointOnLine(0, (0.1, -0.05), Line(), law, "right")]
    return Scene([RigidBody(2.0, 2.0 * 0.05 / 12)], corners, forces=forces, applied_force=applied_force)


def test_pushed_block_slides_with_the_dynamic_coefficient_compiled_with_packed_forces():
    push = ConstantForce(0, (15.0, 0.0), point=(0.0, -0.05))  # at the floor line: no pitching
    q0 = np.array([0.0, 0.05, 0.0])
    run = MoreauJean(MoreauJeanOptions(h=1e-3)).run(_block([push]), q0, np.zeros(3), 0.2)
    assert run.stats["compiled"] == _jit.ENABLED and not run.stats["force_callback"]
    expected = (15.0 - 0.3 * 2.0 * 9.81) / 2.0
    assert np.diff(run.trajectory.v[:, 0]) / 1e-3 == pytest.approx(expected, rel=1e-9)
    callback = MoreauJean(MoreauJeanOptions(h=1e-3)).run(
        _block(applied_force=lambda t, q, v: push.generalised_force(t, q, v, 3)), q0, np.zeros(3), 0.2)
    assert callback.stats["compiled"] == _jit.ENABLED and callback.stats["force_callback"]
    assert np.max(np.abs(callback.trajectory.q - run.trajectory.q)) <= 1e-12


def test_scene_rejects_what_is_not_a_force():
    with pytest.raises(InputError, match="forces"):
        _block(forces=[lambda t, q, v: 0.0])


def test_torsion_spring_between_bodies_is_equal_and_opposite_and_torque_is_constant():
    from nonsmooth_rod.model.forces import Torque, TorsionSpring

    spring = TorsionSpring(0, 1, stiffness=4.0, rest_angle=0.25, damping=0.5)
    q = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.25])
    v = np.array([0.0, 0.0, 2.0, 0.0, 0.0, -1.0])
    torque = -4.0 * (1.0 - 0.25 - 0.25) - 0.5 * (2.0 + 1.0)
    assert spring.generalised_force(0.0, q, v, 6) == pytest.approx([0, 0, torque, 0, 0, -torque], rel=1e-13)
    to_world = TorsionSpring(0, None, stiffness=4.0)
    assert to_world.generalised_force(0.0, q, v, 6) == pytest.approx([0, 0, -4.0, 0, 0, 0], rel=1e-13)
    assert Torque(1, 3.0).generalised_force(7.0, q, v, 6) == pytest.approx([0, 0, 0, 0, 0, 3.0])
    with pytest.raises(InputError, match="stiffness"):
        TorsionSpring(0, None, stiffness=-1.0)
    with pytest.raises(InputError, match="body_b must differ"):
        TorsionSpring(0, 0, stiffness=1.0)


def test_disk_pinned_at_its_centre_on_a_torsion_spring_oscillates_at_its_period():
    """θ'' = −(k/I) θ − (c/I) θ': the damped oscillator's closed form, θ(t) from θ0 at rest."""
    from nonsmooth_rod.model.forces import TorsionSpring
    from nonsmooth_rod.model.joints import Pin

    inertia, k, c, theta0 = 0.02, 3.0, 0.01, 0.4
    scene = Scene([RigidBody(1.0, inertia)], forces=[TorsionSpring(0, None, stiffness=k, damping=c)],
                  joints=[Pin(0, (0.0, 0.0), None, (0.0, 0.0))])
    res = MoreauJean(MoreauJeanOptions(h=2e-4)).run(scene, [0.0, 0.0, theta0], np.zeros(3), 0.5)
    zeta = c / (2 * math.sqrt(k * inertia))
    wn = math.sqrt(k / inertia)
    wd = wn * math.sqrt(1 - zeta ** 2)
    t = res.t
    exact = theta0 * np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta * wn / wd * np.sin(wd * t))
    # the force is taken at (q_k, v_k): first order in h (measured 3.4e-3 θ0 here, 1.7e-3 at h/2)
    assert np.max(np.abs(res.q[:, 2] - exact)) < 5e-3 * theta0
    assert np.max(np.abs(res.q[:, :2])) < 1e-12  # the pin holds the centre
