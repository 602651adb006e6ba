"""Gravity as a vector: any direction and magnitude, 0 included."""
import math

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod import toys
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import DiskOnLine, Line
from nonsmooth_rod.model.scene import Scene
from nonsmooth_rod.validation import InputError

G = 9.81


def _rotation(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def _in_incline_frame(q, angle):
    """Body states (x, y, θ) seen from a frame turned by `angle`: the incline's frame."""
    xy = q[:, :2] @ _rotation(angle)  # rows: Rᵀ x
    return np.c_[xy, q[:, 2] - angle]


@pytest.mark.parametrize("method, options", [("moreau-jean", dict(h=1e-3)),
                                             ("event-driven", dict(rtol=1e-10, atol=1e-10, output_dt=1e-2))])
def test_a_block_on_a_floor_under_turned_gravity_moves_as_on_the_incline(method, options):
    """The block on an incline of 25° under g downward, and on a flat floor under gravity turned
    by −25°: the same motion (in the incline's frame), and the closed form g (sin α − μd cos α)."""
    incline = toys.BlockOnIncline(angle=math.radians(25.0), mu_s=0.3, mu_d=0.2)
    alpha = incline.angle
    gravity = tuple(_rotation(-alpha) @ np.array([0.0, -G]))
    flat = Scene(incline.scene().bodies, [DiskOnLine(c.body, c.offset, Line(), 0.0, c.law, c.name)
                                          for c in incline.scene().contacts], gravity=gravity)
    q0, v0 = incline.initial_state()
    on_incline = nr.simulate(incline.scene(), q0, v0, 0.5, method, **options)
    q0f = _in_incline_frame(q0[None, :], alpha)[0]
    on_floor = nr.simulate(flat, q0f, np.zeros(3), 0.5, method, **options)
    assert np.max(np.abs(_in_incline_frame(on_incline.trajectory.q, alpha) - on_floor.trajectory.q)) < 1e-9
    t, x = on_floor.trajectory.t, on_floor.trajectory.q[:, 0]
    assert np.max(np.abs(x - 0.5 * incline.sliding_down_acceleration * t ** 2)) < 1e-9


def test_zero_gravity_is_free_flight_at_constant_velocity():
    ball = Scene([RigidBody(1.0, 1e-3)], [DiskOnLine(0, (0.0, 0.0), Line(), 0.05, name="floor")], gravity=(0.0, 0.0))
    q0, v0 = np.array([0.0, 1.0, 0.0]), np.array([0.3, 0.2, 1.5])
    result = nr.simulate(ball, q0, v0, 1.0, h=1e-3)
    tr = result.trajectory
    assert np.max(np.abs(tr.q - (q0 + np.outer(tr.t, v0)))) < 1e-12 and np.all(tr.v == v0)
    assert ball.energy(tr.q[-1], tr.v[-1]) == pytest.approx(ball.energy(q0, v0), rel=1e-15)


def test_the_potential_energy_is_minus_m_g_dot_x():
    scene = Scene([RigidBody(2.0, 1.0)], gravity=(3.0, -4.0))
    assert scene.potential_energy(np.array([1.0, 2.0, 0.5])) == pytest.approx(-2.0 * (3.0 * 1.0 - 4.0 * 2.0))
    assert Scene([RigidBody(2.0, 1.0)], gravity=G).potential_energy(np.array([1.0, 2.0, 0.0])) == 2.0 * G * 2.0
    assert list(scene.weight) == [6.0, -8.0, 0.0]


@pytest.mark.parametrize("gravity, message", [(-1.0, "g must be non-negative"), ((1.0, math.nan), "gravity y"),
                                              ((1.0, 2.0, 3.0), "gravity must be two numbers"),
                                              ("down", "g must be a number")])
def test_bad_gravity_is_one_line(gravity, message):
    with pytest.raises(InputError, match=message) as err:
        Scene([RigidBody(1.0, 1.0)], gravity=gravity)
    assert "\n" not in str(err.value)
