"""The compiled screen of the hybrid method's step watch (integrators/watch_screen.py): a
prediction (Hybrid.first_event) through it finds the event the step-by-step watch finds, to the
bit, from the rod's states in every mode — a grazing peak whose dip the watch looks at and passes
included — and from a state whose steps the compiled mode solve declines part-way."""
from __future__ import annotations

import math

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod.integrators import event_driven, hybrid, watch_screen
from nonsmooth_rod.integrators.adaptive_breakaway import consistent_velocity
from nonsmooth_rod.integrators.hybrid import Hybrid, HybridOptions
from nonsmooth_rod.rod.hypotheses import rolling_hypothesis
from nonsmooth_rod.rod.problem import RodProblem


def _stepwise(predictor, scene, t, q, v, modes, t_end):
    """The prediction with the watch stepping step by step (the hybrid method's own segments)."""
    indicators = event_driven._indicators(scene, modes, 1e-9 * event_driven._force_scale(scene, t, q, v))
    mode = hybrid._Mode(scene, modes, indicators, predictor._system)
    start = hybrid._Stage(mode, t, np.concatenate([q, v]))
    hit, _, _ = predictor._watched_steps(mode, start, hybrid._StepWatch(mode, start), t_end, math.inf,
                                         hybrid._Counts(), lambda stage: None)
    return None if hit is None else (float(hit[0]), indicators[hit[1]].kind, indicators[hit[1]].contact)


@pytest.mark.parametrize("delta", [1e-6, -1e-6, -0.02])
def test_screened_prediction_is_the_stepwise_one(delta):
    """μs = max T/N + δ: from states along a fixed-step run, in its modes, all sticking, all
    sliding either way: the same first event (time, kind, contact) to the bit, and a sticking
    start near the peak (δ = 1e-6) that rolls through it (a dip looked at, no crossing)."""
    peak = rolling_hypothesis(RodProblem.paper(None, mu_s=0.3, mu_d=0.2)).T_over_N_max
    problem = RodProblem.paper(None, mu_s=peak + delta, mu_d=0.2)
    scene, (q0, v0) = problem.scene(), problem.initial_state()
    run = nr.simulate(scene, q0, v0, 0.4, "moreau-jean", h=1e-3)
    predictor, kinds = Hybrid(HybridOptions(h=1e-2)), set()
    for k in range(0, run.q.shape[0], 40):
        q, v, t = run.q[k], run.v[k], float(run.t[k])
        closed = ["stick" if c.gap < 1e-6 else "open" for c in scene.kinematics(q, v)]
        for slide in ("stick", "slip+", "slip-"):
            modes = [slide if m == "stick" else m for m in closed]
            v_modes = consistent_velocity(scene, q, v, modes)
            expected = _stepwise(predictor, scene, t, q, v_modes, modes, 0.5)
            assert predictor.first_event(scene, t, q, v_modes, modes, 0.5) == expected
            kinds.add(None if expected is None else expected[1])
    assert {"break-upper", "slip-zero"} <= kinds
    if delta > 0:  # rolls through the peak at 0.158 s: the screen flags its dip, the watch passes it
        ahead = predictor.first_event(scene, 0.0, q0, v0, ["stick", "open"], 0.5)
        assert ahead[0] > 0.2


def test_a_declined_step_goes_on_step_by_step(monkeypatch):
    """A step the compiled solve declines (a singular A, here forced at the fourth step): the
    prediction goes on step by step from there and finds the same event."""
    problem = RodProblem.paper(2)
    scene, (q0, v0) = problem.scene(), problem.initial_state()
    expected = _stepwise(Hybrid(HybridOptions(h=1e-2)), scene, 0.0, q0, v0, ["stick", "open"], 0.3)
    screened = watch_screen.screened_steps_into
    calls = []

    def declining(*args):  # the first call's steps cut after three, the fourth declined
        calls.append(args[7].shape[0])
        if len(calls) > 1:
            return screened(*args)
        m = screened(*args[:7], args[7][:3], args[8][:4], *args[9:])
        return -4 if m == 3 else m
    monkeypatch.setattr(hybrid, "screened_steps_into", declining)
    assert Hybrid(HybridOptions(h=1e-2)).first_event(scene, 0.0, q0, v0, ["stick", "open"], 0.3) == expected
    assert calls == [hybrid.BLOCK] and expected[0] > 0.05  # declined before the event: the rest step by step
