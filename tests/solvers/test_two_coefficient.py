"""solvers.two_coefficient: the dense step solved one group of coupled contacts at a time."""
from __future__ import annotations

import math

import numpy as np
import pytest

from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import Line, PointOnLine
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.model.scene import Scene
from nonsmooth_rod.solvers.kernels import KERNEL_SOLVED, SOLVER_CODES, solver_scratch
from nonsmooth_rod.solvers.two_coefficient import (GROUP_MIN_CONTACTS, STATE_SLIP_MINUS, STATE_SLIP_PLUS, STATE_STICK,
                                                   two_coefficient_by_group, two_coefficient_kernel)
from solver_cases import block_on_incline

G = 9.81


def _interpreted(function):
    return getattr(function, "py_func", function)


def _three_blocks():
    """Three independent blocks on two corners each (W block-diagonal, 6 contacts): one holds
    (tan 0.3 < 0.5), two slide (tan 0.6 > 0.5, tan 0.5 > 0.4)."""
    parts = [(block_on_incline(0.3, 0.5), 0.5), (block_on_incline(0.6, 0.5), 0.5), (block_on_incline(0.5, 0.4), 0.4)]
    W = np.zeros((12, 12))
    for k, (problem, _) in enumerate(parts):
        W[4 * k:4 * k + 4, 4 * k:4 * k + 4] = problem.W
    q = np.concatenate([problem.q for problem, _ in parts])
    mu_s = np.repeat([mu for _, mu in parts], 2)
    return W, q, mu_s, 0.8 * mu_s, parts


@pytest.mark.parametrize("compiled", [True, False])
@pytest.mark.parametrize("solver", ["lemke", "enum"])
def test_each_group_gets_the_answer_it_gets_alone(solver, compiled):
    by_group = two_coefficient_by_group if compiled else _interpreted(two_coefficient_by_group)
    W, q, mu_s, mu_d, parts = _three_blocks()
    assert len(mu_s) > GROUP_MIN_CONTACTS
    n = len(mu_s)
    p, u, states, guess = np.zeros(2 * n), np.zeros(2 * n), np.zeros(n, dtype=np.int64), np.zeros(n)
    status, solves, _, consistent, _ = by_group(SOLVER_CODES[solver], W, q, mu_s, mu_d, guess, np.zeros(n),
                                               np.ones(n), 0.0, 0, p, u, states, *solver_scratch(2))
    assert status == KERNEL_SOLVED and consistent
    empty = np.zeros(0, dtype=np.int64)
    total_solves = 0
    for k, (problem, mu) in enumerate(parts):
        pk, uk, sk, gk = np.zeros(4), np.zeros(4), np.zeros(2, dtype=np.int64), np.zeros(2)
        result = two_coefficient_kernel(SOLVER_CODES[solver], problem.W, empty, empty, np.zeros((0, 2, 2)), problem.q,
                                        np.full(2, mu), np.full(2, 0.8 * mu), gk, np.zeros(2), np.ones(2), 0.0, 0,
                                        pk, uk, sk)
        total_solves += result[1]
        np.testing.assert_array_equal(p[4 * k:4 * k + 4], pk)  # the very same solve: bit for bit
        np.testing.assert_array_equal(states[2 * k:2 * k + 2], sk)
        np.testing.assert_array_equal(guess[2 * k:2 * k + 2], gk)
    assert solves == total_solves
    assert list(states[:2]) == [STATE_STICK, STATE_STICK]  # the first block holds; the others slide down
    assert len(set(states[2:])) == 1 and states[2] in (STATE_SLIP_PLUS, STATE_SLIP_MINUS)  # the same way down
    np.testing.assert_allclose(u, W @ p + q, rtol=0, atol=1e-12 * np.max(np.abs(q)))


def _blocks_scene(angles, mu_s, mu_d, width=0.2, height=0.1):
    """One block per incline angle, each on its own incline (they never touch): 2 corners each."""
    bodies, contacts, q0 = [], [], []
    for b, alpha in enumerate(angles):
        incline = Line((0.0, 0.0), alpha)
        law = ContactLaw.of(mu_s, mu_d)
        bodies.append(RigidBody(1.0, (width**2 + height**2) / 12, f"block{b}"))
        contacts += [PointOnLine(b, (-width / 2, -height / 2), incline, law, f"rear{b}"),
                     PointOnLine(b, (width / 2, -height / 2), incline, law, f"front{b}")]
        n = incline.normal
        q0 += [n[0] * height / 2, n[1] * height / 2, alpha]
    return Scene(bodies, contacts, gravity=G), np.array(q0)


@pytest.mark.parametrize("solver", ["lemke", "enum"])
def test_enum_and_lemke_run_a_scene_of_more_contacts_than_enum_takes_at_once(solver):
    angles = [math.radians(a) for a in (15.0, 30.0, 40.0)]  # μs = 0.5: the first holds, the others slide
    scene, q0 = _blocks_scene(angles, 0.5, 0.3)
    h, steps = 1e-3, 100
    run = MoreauJean(MoreauJeanOptions(h=h, solver=solver)).run(scene, q0, np.zeros(9), h * steps)
    assert run.status == "ok" and run.steps == steps and run.stats["compiled"]
    v = run.trajectory.v
    assert np.max(np.abs(v[:, :3])) < 1e-12  # held
    for b, alpha in enumerate(angles[1:], start=1):
        t = np.array([math.cos(alpha), math.sin(alpha)])
        accel = np.diff(v[:, 3 * b:3 * b + 2] @ t) / h
        np.testing.assert_allclose(accel, -G * (math.sin(alpha) - 0.3 * math.cos(alpha)), rtol=1e-9)
