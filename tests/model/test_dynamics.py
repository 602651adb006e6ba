"""The mode solve set up once (ModeSystem, compiled) against mode_dynamics, the reference's:
the same accelerations, forces and constrained matrix to round-off for every mode of a rod on
two balls and of two bodies on two lines (one of them moving as a belt, one under a spring);
None where A is statically indeterminate (a block resting on two sticking corners), so that
the caller falls back on mode_dynamics' choice of split. The hybrid method, which runs it, is
checked against the event-driven reference in tests/integrators/test_hybrid.py."""
from __future__ import annotations

import itertools

import numpy as np
import pytest

from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import DiskOnLine, Line
from nonsmooth_rod.model.dynamics import WATCH_CODES, ModeSystem, indeterminate_everywhere, mode_dynamics
from nonsmooth_rod.model.forces import Spring
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.model.scene import Scene
from nonsmooth_rod.rod.problem import RodProblem

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

MODES = ("open", "stick", "slip+", "slip-")


def _two_bodies() -> Scene:
    law = ContactLaw.of(mu_s=0.4, mu_d=0.3)
    floor, belt = Line(), Line(point=(0.0, 0.1), angle=-0.6, velocity=0.7)
    bodies = [RigidBody(mass=1.3, inertia=0.02), RigidBody(mass=0.7, inertia=0.05)]
    contacts = [DiskOnLine(0, (0.1, -0.05), floor, radius=0.03, law=law, name="a"),
                DiskOnLine(1, (-0.2, 0.1), belt, radius=0.0, law=law, name="b")]
    return Scene(bodies, contacts, forces=[Spring(0, (0.0, 0.0), 1, (0.05, 0.0), stiffness=40.0, rest_length=0.3)])


def _compare(scene, modes, q, v):
    watched = [(what, i, 0.01 * i) for i in range(len(scene.contacts)) for what in WATCH_CODES]
    system = ModeSystem(scene, modes, watched)
    out = system.evaluate(0.3, np.concatenate([q, v]))
    ref = mode_dynamics(scene, 0.3, q, v, modes)
    if ref.singular:  # two sticking contacts of one body: more unknowns than coordinates
        assert out is None
        return
    assert out is not None
    lean = system.dynamics(out)
    a, normal, tangential, A = lean.a, lean.normal_force, lean.tangential_force, lean.matrix
    det = out[system.det]
    np.testing.assert_array_equal(out[system.rates], np.concatenate([v, a]))
    force = float(np.max(np.abs(ref.normal_force)) + np.max(np.abs(scene.force(0.3, q, v))))
    np.testing.assert_allclose(a, ref.a, rtol=0, atol=1e-12 * max(1.0, float(np.max(np.abs(ref.a)))))
    np.testing.assert_allclose(normal, ref.normal_force, rtol=0, atol=1e-12 * force)
    np.testing.assert_allclose(tangential, ref.tangential_force, rtol=0, atol=1e-12 * force)
    np.testing.assert_allclose(A, ref.matrix, rtol=1e-14, atol=1e-14)
    assert det == pytest.approx(np.linalg.det(ref.matrix) if ref.matrix.size else 1.0, rel=1e-12)
    kin = scene.kinematics(q, v)
    for (what, i, offset), value in zip(watched, out[system.values]):
        mu_s = scene.contacts[i].law.friction.mu_s
        expected = {"gap": kin[i].gap, "slip": kin[i].H_T @ v - kin[i].surface_velocity, "normal": ref.normal_force[i],
                    "upper": ref.tangential_force[i] - mu_s * ref.normal_force[i],
                    "lower": ref.tangential_force[i] + mu_s * ref.normal_force[i], "det": det}[what]
        assert value == pytest.approx(expected - offset, rel=0, abs=1e-12 * max(force, 1.0, abs(det)))


@pytest.mark.parametrize("modes", list(itertools.product(MODES, repeat=2)))
def test_every_mode_of_the_rod_as_mode_dynamics(modes):
    problem = RodProblem.paper(2)
    scene = problem.scene()
    q0, v0 = problem.initial_state()
    rng = np.random.default_rng(len(modes[0]) + 7 * len(modes[1]))
    for _ in range(5):
        _compare(scene, list(modes), q0 + 0.05 * rng.standard_normal(3), v0 + rng.standard_normal(3))


@pytest.mark.parametrize("modes", list(itertools.product(MODES, repeat=2)))
def test_two_bodies_a_belt_and_a_spring_as_mode_dynamics(modes):
    scene = _two_bodies()
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = np.array([0.0, 0.08, 0.3, 0.4, 0.2, -0.4]) + 0.02 * rng.standard_normal(6)
        _compare(scene, list(modes), q, rng.standard_normal(6))


def test_a_block_on_two_sticking_corners_is_left_to_mode_dynamics():
    """Four unknowns for three degrees of freedom: A is singular, the split is mode_dynamics'."""
    law = ContactLaw.of(mu_s=0.5, mu_d=0.4)
    corners = [DiskOnLine(0, (x, -0.3), Line(), law=law, name=name) for x, name in ((-0.2, "left"), (0.2, "right"))]
    scene = Scene([RigidBody(mass=2.0, inertia=0.1)], corners)
    q, v = np.array([0.0, 0.3, 0.0]), np.zeros(3)
    modes = ["stick", "stick"]
    assert ModeSystem(scene, modes, [("normal", 0, 0.0)]).evaluate(0.0, np.concatenate([q, v])) is None
    assert mode_dynamics(scene, 0.0, q, v, modes).singular
    assert ModeSystem(scene, ["stick", "open"]).evaluate(0.0, np.concatenate([q, v])) is not None


def _block_on_three_corners() -> Scene:
    """A block with two corners on the floor and one on a wall (a slanted line): 3 contacts, 3 freedoms."""
    law = ContactLaw.of(mu_s=0.5, mu_d=0.4)
    corners = [DiskOnLine(0, (-0.2, -0.3), Line(), law=law, name="left"),
               DiskOnLine(0, (0.2, -0.3), Line(), radius=0.01, law=law, name="right"),
               DiskOnLine(0, (0.2, 0.3), Line(point=(0.3, 0.0), angle=1.9), law=law, name="wall")]
    return Scene([RigidBody(mass=2.0, inertia=0.1)], corners)


@pytest.mark.parametrize("modes", list(itertools.product(MODES, repeat=3)))
def test_a_block_on_three_corners_every_mode_as_mode_dynamics(modes):
    """Every mode of three contacts of one body: those holding it by more rows than its three
    freedoms (indeterminate_everywhere: two sticking corners, or a sticking one and two closed)
    are singular at every state for mode_dynamics too, and declined without a compiled solve
    (`usable` False: a prediction of them costs no mode solve); the others are solved as
    mode_dynamics solves them, to round-off, at random states."""
    scene, modes = _block_on_three_corners(), list(modes)
    rng = np.random.default_rng(sum(MODES.index(m) * 4 ** i for i, m in enumerate(modes)))
    states = [(np.array([0.0, 0.3, 0.0]) + 0.1 * rng.standard_normal(3), rng.standard_normal(3)) for _ in range(4)]
    rows = sum({"open": 0, "stick": 2}.get(mode, 1) for mode in modes)
    assert indeterminate_everywhere(ModeSystem(scene, modes).bodies, modes) == (rows > 3)
    if rows > 3:
        assert not ModeSystem(scene, modes).usable
        assert all(mode_dynamics(scene, 0.3, q, v, modes).singular for q, v in states)
    for q, v in states:
        _compare(scene, modes, q, v)


RK4_A = np.array([[0.0, 0.0, 0.0, 0.0], [0.5, 0.0, 0.0, 0.0], [0.0, 0.5, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
RK4_B = np.array([1 / 6, 1 / 3, 1 / 3, 1 / 6])


@pytest.mark.parametrize("modes", [["stick", "open"], ["slip+", "open"], ["slip-", "stick"], ["open", "open"]])
def test_a_runge_kutta_step_in_one_call_as_mode_dynamics_stage_by_stage(modes):
    """ModeSystem.runge_kutta (the hybrid method's step): the classical RK4 step of the rod's mode
    written out with mode_dynamics, every stage's state, the end state and what is watched there
    to round-off; None where the mode solve would decline (a block on two sticking corners) or
    the forces are not constant (a spring: the caller steps stage by stage)."""
    problem = RodProblem.paper(2)
    scene = problem.scene()
    q0, v0 = problem.initial_state()
    y, h, n = np.concatenate([q0 + 0.01, v0 + 0.3]), 0.05, scene.n_dof
    system = ModeSystem(scene, modes, [("gap", 1, 0.0), ("normal", 0, 0.0)])
    states, outs = system.runge_kutta(y, h, RK4_A, RK4_B)
    expected, rates = [y], []
    for i in range(4):
        ys = expected[i]
        rates.append(np.concatenate([ys[n:], mode_dynamics(scene, 0.0, ys[:n], ys[n:], modes).a]))
        weights = RK4_B if i == 3 else RK4_A[i + 1]
        expected.append(y + h * sum(w * f for w, f in zip(weights, rates)))
    scale = float(np.max(np.abs(np.concatenate(rates))))
    np.testing.assert_allclose(states, np.array(expected), rtol=0, atol=1e-13 * max(1.0, scale))
    for state, out in zip(states, outs):
        evaluated = system.evaluate(0.0, state)
        np.testing.assert_array_equal(out, evaluated)  # the same compiled solve at the same state
    law = ContactLaw.of(mu_s=0.5, mu_d=0.4)
    corners = [DiskOnLine(0, (x, -0.3), Line(), law=law, name=name) for x, name in ((-0.2, "left"), (0.2, "right"))]
    block = Scene([RigidBody(mass=2.0, inertia=0.1)], corners)
    assert ModeSystem(block, ["stick", "stick"]).runge_kutta(np.r_[0.0, 0.3, 0.0, np.zeros(3)], h, RK4_A, RK4_B) is None
    assert ModeSystem(_two_bodies(), ["open", "open"]).runge_kutta(np.zeros(12), h, RK4_A, RK4_B) is None
