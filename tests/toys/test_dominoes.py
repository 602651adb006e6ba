"""A row of 20 dominoes (toys/dominoes.py) against the first domino's tipping threshold: pushed at
1.1 J* the whole row falls, at 0.9 J* the first rocks back after tilting by the closed-form angle
and nothing else moves; no two dominoes ever overlap (neighbours or not: each collides with its
neighbours only). The compiled loop (what users run); a few seconds."""
import math

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod.model.collision import deepest_overlap
from nonsmooth_rod.toys.dominoes import Dominoes

H = 1e-3


def _run(toy, t_end):
    q0, v0 = toy.initial_state()
    scene = toy.scene()
    result = nr.simulate(scene, q0, v0, t_end, "moreau-jean", h=H, save_every=0.01)
    assert result.status == "ok", result.message
    return scene, result


def test_the_tipping_impulse_is_the_closed_form():
    """J* from ½ I_c ω*² = m g (R − h), ω* = J* z / I_c, written out for the default domino."""
    toy = Dominoes()
    m, b, h, z = 0.01, 0.005, 0.025, 0.04
    corner = m * (b * b + h * h) / 3 + m * (b * b + h * h)
    assert toy.tipping_impulse == pytest.approx(corner / z * math.sqrt(2 * m * 9.81 * (math.hypot(b, h) - h) / corner),
                                                rel=1e-14)
    assert len(toy.scene().contacts) == 20 * 4 + 19 * 32  # the floor and the neighbours only


def test_pushed_above_its_tipping_impulse_the_whole_row_falls():
    toy = Dominoes(push_ratio=1.1)
    scene, result = _run(toy, 1.2)  # the last falls at 1.04 s
    q = result.trajectory.q
    assert toy.fallen(q[-1]).all(), np.round(q[-1, 2::3], 3)
    times = [float(result.trajectory.t[np.flatnonzero(toy.fallen(q.T)[k])[0]]) for k in range(toy.n)]
    assert np.all(np.diff(times) > 0)  # one after the other, down the row
    # within one step of travel of the fastest point: a domino's top falling flat, √(3 g H)
    assert deepest_overlap(scene.bodies, toy.shapes(), q, [nr.Line()]) < H * math.sqrt(3 * 9.81 * toy.height)


def test_pushed_below_its_tipping_impulse_the_first_rocks_back_and_nothing_else_moves():
    toy = Dominoes(push_ratio=0.9)
    _, result = _run(toy, 1.0)
    q = result.trajectory.q
    tilt = -q[:, 2]
    assert tilt.max() == pytest.approx(toy.largest_tilt(), rel=2e-2)
    assert not toy.fallen(q.T).any()  # it rocks (Housner: slowly damped, ω⁺/ω⁻ = 1 − 1.5 sin² α) and never tips
    assert q[:, 2].max() > 0.0  # it rocked back past its base onto its back corner
    q0, _ = toy.initial_state()
    assert np.abs(q[:, 3:] - q0[3:]).max() < 1e-12  # the others stand still (to round-off)
