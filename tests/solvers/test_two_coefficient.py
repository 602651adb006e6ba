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
from nonsmooth_rod.solvers._common import python_body
from nonsmooth_rod.solvers.kernels import KERNEL_SOLVED, SOLVER_CODES, solver_scratch
from nonsmooth_rod.solvers.two_coefficient import (GROUP_MIN_CONTACTS, STATE_SLIP_MINUS, STATE_SLIP_PLUS, STATE_STICK,
                                                   two_coefficient_by_group, two_coefficient_kernel)
from solver_cases import block_on_incline

G = 9.81


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


@pytest.mark.parametrize("solver", ["lemke", "enum"])
def test_each_group_gets_the_answer_it_gets_alone(solver):
    by_group = python_body(two_coefficient_by_group)  # (the loop's compiled kernels; it exists only inlined)
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


def _hold_pending(u, states, p_zero=True, start_guess=None, resting=None, closing=None):
    from nonsmooth_rod.solvers.two_coefficient import hold_decision_pending
    na = states.shape[0]
    start_guess = np.zeros(na) if start_guess is None else start_guess
    resting = np.ones(na) if resting is None else resting
    closing = np.zeros(na) if closing is None else closing
    return hold_decision_pending(start_guess, resting, 1e-9, closing, np.asarray(u, float), states)


def test_a_hold_decision_is_pending_only_when_a_contact_that_was_at_rest_moves():
    """The hold search can only change the answer when a contact that started at rest slides or
    lifted off; one that touches without load (open, u = 0: a pile's unloaded pairs) or sticks
    leaves nothing to decide (sticking._resting_contacts finds no moving candidate)."""
    from nonsmooth_rod.solvers.two_coefficient import STATE_OPEN
    stick_and_unloaded = np.array([STATE_STICK, STATE_OPEN], dtype=np.int64)
    assert not _hold_pending([0.0, 0.0, 0.0, 3e-10], stick_and_unloaded)  # touching, slip below tol
    assert _hold_pending([0.0, 0.0, 1e-6, 0.0], stick_and_unloaded)  # the unloaded one lifted off
    assert not _hold_pending([0.0, 0.0, 1e-6, 0.0], stick_and_unloaded, closing=np.array([0.0, 1e-6]))  # closing its gap
    sliding = np.array([STATE_STICK, STATE_SLIP_PLUS], dtype=np.int64)
    assert _hold_pending([0.0, 0.0, 0.0, 1e-6], sliding)
    assert not _hold_pending([0.0, 0.0, 0.0, 1e-6], sliding, start_guess=np.array([0.0, 1.0]))  # was sliding
    assert not _hold_pending([0.0, 0.0, 0.0, 1e-6], sliding, resting=np.array([1.0, 0.0]))  # was not at rest
    all_stick = np.array([STATE_STICK, STATE_STICK], dtype=np.int64)
    assert not _hold_pending([0.0, 0.0, 0.0, 0.0], all_stick)


def test_a_pile_at_rest_starts_no_hold_search():
    """The 4-row pile settles in its first steps, then its unloaded contacts (open, touching, no
    slip) made the hold search run — its set-up and ~26 allocations — every step for nothing. Run
    interpreted in a child process (the compiled loop cannot be counted), the search counted:
    none after the first 20 steps (before: one every step)."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    code = """
import numpy as np
import nonsmooth_rod as nr
from nonsmooth_rod.solvers import two_coefficient as tc
from nonsmooth_rod.toys import stacks
steps = []
search = tc._hold_search
def counted(*args):
    steps.append(1)
    return search(*args)
tc._hold_search = counted
scene, q0, v0 = stacks.disk_pile(4)
early = nr.simulate(scene, q0, v0, 0.02, h=1e-3, solver="pgs", repeat_rest=False)
settled = len(steps)
run = nr.simulate(scene, early.q[-1], early.v[-1], 0.06, h=1e-3, solver="pgs", repeat_rest=False)
print(run.status.value, run.steps, len(steps) - settled, float(np.max(np.abs(run.q - q0))))
"""
    src = Path(__file__).resolve().parents[2] / "src"
    env = dict(os.environ, NONSMOOTH_ROD_NO_JIT="1", PYTHONPATH=str(src))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    status, steps, searches, moved = out.stdout.split()
    assert status == "ok" and int(steps) == 60
    assert int(searches) == 0
    assert float(moved) < 1e-6  # the pile holds: what moved is its first steps' settling
