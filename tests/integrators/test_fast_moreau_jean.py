"""The compiled Moreau–Jean loop and the same source interpreted agree to round-off."""
import math

import numpy as np
import pytest

from nonsmooth_rod import _jit
from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import DiskOnDisk, Line, DiskOnLine
from nonsmooth_rod.model.forces import Spring
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.model.scene import Scene
from nonsmooth_rod.rod.problem import RodProblem

from test_moreau_jean import _block_on_incline

pytestmark = pytest.mark.skipif(not _jit.ENABLED, reason="numba not installed or disabled")
ULPS = 400  # numpy/numba versions change FMA use and summation order


def _both(scene, q0, v0, t_end, **options):
    fast = MoreauJean(MoreauJeanOptions(fast=True, **options)).run(scene, q0, v0, t_end)
    slow = MoreauJean(MoreauJeanOptions(fast=False, **options)).run(scene, q0, v0, t_end)
    assert fast.stats["compiled"] and not slow.stats["compiled"]
    return fast, slow


def _close(a, b, scale):
    return np.max(np.abs(np.asarray(a) - np.asarray(b)), initial=0.0) <= ULPS * np.finfo(float).eps * scale


def _assert_same(fast, slow):
    assert fast.status == slow.status and fast.steps == slow.steps
    tf, ts = fast.trajectory, slow.trajectory
    assert _close(tf.q, ts.q, np.max(np.abs(ts.q)))
    assert _close(tf.v, ts.v, np.max(np.abs(ts.v)))
    force_scale = max(np.max(np.abs(ts.normal_force)), 1e-300)
    assert _close(tf.normal_force, ts.normal_force, force_scale)
    assert (tf.modes == ts.modes).all()
    assert [i.contact for i in fast.impacts] == [i.contact for i in slow.impacts]
    for a, b in zip(fast.impacts, slow.impacts):
        assert _close(a.t, b.t, b.t)


@pytest.mark.parametrize("case", [1, 2, 3])
def test_rod_cases_through_the_impact(case):
    p = RodProblem.paper(case, restitution=0.2)
    q0, v0 = p.initial_state()
    _assert_same(*_both(p.scene(), q0, v0, 0.6, h=5e-4))


def test_block_with_two_corners_stopping_on_an_incline():
    scene, q0, t_dir, _ = _block_on_incline(math.radians(25.0), 0.5, 0.3)
    _assert_same(*_both(scene, q0, np.r_[t_dir, 0.0], 0.4, h=1.3e-3))


def test_two_balls_on_a_floor_with_a_spring_and_a_disk_contact():
    law = ContactLaw.of(0.3, 0.2, 0.5)
    balls = [RigidBody(1.0, 0.004, "a"), RigidBody(1.0, 0.004, "b")]
    floor = Line((0.0, 0.0), 0.0)
    contacts = [DiskOnLine(0, (0.0, 0.0), floor, 0.1, law, "a-floor"),
                DiskOnLine(1, (0.0, 0.0), floor, 0.1, law, "b-floor"),
                DiskOnDisk(1, 0, 0.1, 0.1, law=law, name="a-b")]
    spring = Spring(0, (0.0, 0.05), None, (-1.0, 0.3), stiffness=50.0, rest_length=0.5, damping=0.2)
    scene = Scene(balls, contacts, forces=[spring])
    q0, v0 = np.array([0.0, 0.1, 0.0, 0.3, 0.15, 0.0]), np.array([1.0, 0.0, 0.0, -3.0, 0.0, 2.0])
    fast, slow = _both(scene, q0, v0, 0.5, h=1e-3)
    assert [i.contact for i in fast.impacts][:2] == ["a-b", "b-floor"]  # every contact kind acts
    _assert_same(fast, slow)


@pytest.mark.parametrize("toy", ["BouncingBall", "BlockOnIncline", "PushedBlock", "DiskOnIncline", "BeltOscillator",
                                 "RockingBlock", "PainleveRod", "BallRow"])
def test_every_toy_runs_compiled(toy):
    from nonsmooth_rod import toys

    run = toys.run(getattr(toys, toy)(), "moreau-jean", 0.02)
    assert run.status == "ok" and run.stats["compiled"]
    assert not run.stats["force_callback"]  # every toy's forces are data: the run is one compiled call


def test_a_python_force_callback_is_called_back_and_matches_the_same_force_as_data():
    from nonsmooth_rod import toys

    block = toys.PushedBlock()
    as_data = block.scene()
    b = block.height / 2

    def push(t, q, v):  # the same push (fx, 0) at the body point (0, −b): lever (b sin θ, −b cos θ)
        fx = block.push(t)
        return np.array([fx, 0.0, b * math.cos(q[2]) * fx])

    as_callback = Scene(as_data.bodies, as_data.contacts, gravity=as_data.gravity, applied_force=push)
    q0, v0 = block.initial_state()
    options = MoreauJeanOptions(h=1e-3)
    data = MoreauJean(options).run(as_data, q0, v0, 0.7)
    called = MoreauJean(options).run(as_callback, q0, v0, 0.7)
    assert called.stats["force_callback"] and called.stats["compiled"] and not data.stats["force_callback"]
    assert toys.first_slip_time(called) == toys.first_slip_time(data)
    _assert_same(data, called)


@pytest.mark.parametrize("solver", ["lemke", "pgs", "enum", "osqp"])
def test_the_rod_runs_compiled_with_every_exact_solver_and_python_with_qp(solver):
    from nonsmooth_rod.solvers import available_solvers

    if solver not in available_solvers():
        pytest.skip(f"{solver} not installed")
    p = RodProblem.paper(2)
    run = MoreauJean(MoreauJeanOptions(h=1e-3, solver=solver)).run(p.scene(), *p.initial_state(), 0.05)
    assert run.status == "ok" and run.stats["compiled"] == (solver != "osqp")
