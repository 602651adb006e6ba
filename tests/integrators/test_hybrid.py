"""The hybrid method (fixed Runge–Kutta steps in each smooth mode, the event-driven reference's
events, integrators/hybrid.py) against the event-driven reference at rtol 1e-12 and the toys'
closed forms: its order measured on the rolling rod, the rod's phases and impact, the grazing
break-away decided by the exact law, and bad options refused."""
from __future__ import annotations

import math

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod.rod import study
from nonsmooth_rod.rod.hypotheses import rolling_hypothesis
from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.rod.simulation import simulate as simulate_rod
from nonsmooth_rod.toys.bouncing_ball import BouncingBall
from nonsmooth_rod.validation import InputError

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

ROLLING_UNTIL = 0.09  # s: case 2 sticks (rolls) until 0.1041 s


@pytest.fixture(scope="module")
def rolling_reference():
    problem = RodProblem.paper(2)
    q0, v0 = problem.initial_state()
    ref = nr.simulate(problem.scene(), q0, v0, ROLLING_UNTIL, "event-driven", rtol=1e-12, atol=1e-12)
    assert [p.mode for p in ref.phases["A"]] == ["stick"]
    return problem, ref.trajectory.q[-1], ref.trajectory.v[-1]


@pytest.mark.parametrize("order", [2, 3, 4])
def test_order_on_the_rolling_rod(rolling_reference, order):
    """The rod rolling on ball A (a smooth constrained ODE until its break-away): the end state's
    error falls as h^order (measured slope ≥ order − 0.2; Moreau–Jean's is 1)."""
    problem, q_ref, v_ref = rolling_reference
    q0, v0 = problem.initial_state()
    steps = (ROLLING_UNTIL / 9, ROLLING_UNTIL / 18, ROLLING_UNTIL / 36)
    errors = []
    for h in steps:
        run = nr.simulate(problem.scene(), q0, v0, ROLLING_UNTIL, "hybrid", h=h, order=order)
        assert [p.mode for p in run.phases["A"]] == ["stick"]
        errors.append(max(np.max(np.abs(run.trajectory.q[-1] - q_ref)), np.max(np.abs(run.trajectory.v[-1] - v_ref))))
    slopes = np.diff(np.log(errors)) / np.diff(np.log(steps))
    assert errors[-1] > 1e-13  # above round-off: the slopes measure the scheme
    assert np.all(slopes >= order - 0.2), (errors, slopes)


@pytest.mark.parametrize("mu_s, mu_d", [(0.28, 0.20), (0.12, 0.10), (0.40, 0.30), (0.6, 0.05), (0.05, 0.05),
                                        (0.35, 0.33)])
def test_rod_phases_and_impact(mu_s, mu_d):
    """The paper's rod over μs, μd in 0.05–0.6 at h = 1e-2: the reference's phase sequence, every
    boundary and ball B's impact within 1e-5 s."""
    problem = RodProblem.paper(None, mu_s=mu_s, mu_d=mu_d)
    reference = simulate_rod(problem, "event-driven")
    run = simulate_rod(problem, "hybrid", h=1e-2)
    assert run.status == "ok"
    assert [p.mode for p in run.phases] == [p.mode for p in reference.phases]
    assert max(abs(a.t_end - b.t_end) for a, b in zip(run.phases, reference.phases)) <= 1e-5
    assert abs(run.impact["t"] - reference.impact["t"]) <= 1e-5


def test_case_2_impact_within_1e_5_at_h_5e_2():
    """Nine steps of 5e-2 s locate ball B's impact of case 2 within 1e-5 s (measured 3.5e-6)."""
    reference = study.reference(2)
    run = simulate_rod(reference.problem, "hybrid", h=5e-2)
    m = study.measure(run, reference)
    assert m["phase_sequence_ok"] and m["impact_error_s"] <= 1e-5 and m["x_O_error_m"] <= 1e-5


@pytest.mark.parametrize("delta", [1e-6, -1e-6, 1e-5, -1e-5])
def test_grazing_break_away_at_h_1e_3(delta):
    """μs = max T/N + δ on the rod (μd = 0.2): with |δ| = 1e-6 at h = 1e-3 the rod rolls through
    the peak (δ > 0) or breaks away at it (δ < 0) as the reference does, boundaries within 1e-5 s."""
    peak = rolling_hypothesis(RodProblem.paper(None, mu_s=0.3, mu_d=0.2)).T_over_N_max
    problem = RodProblem.paper(None, mu_s=peak + delta, mu_d=0.2)
    reference = simulate_rod(problem, "event-driven")
    run = simulate_rod(problem, "hybrid", h=1e-3)
    assert [p.mode for p in run.phases] == [p.mode for p in reference.phases]
    assert max(abs(a.t_end - b.t_end) for a, b in zip(run.phases, reference.phases)) <= 1e-5


def test_bouncing_ball_impacts_on_the_closed_form():
    """A ball dropped on a floor (e = 0.5): the first five impacts at the closed-form times, the
    rebound speeds e^k v_1, with steps much longer than the flights' ends (h = 0.1 s)."""
    toy = BouncingBall(drop_height=1.0, restitution=0.5)
    q0, v0 = toy.initial_state()
    run = nr.simulate(toy.scene(), q0, v0, 2.0, "hybrid", h=0.1)
    times = np.array([imp.t for imp in run.impacts[:5]])
    np.testing.assert_allclose(times, toy.impact_times(5), rtol=0, atol=1e-9)
    speeds = np.array([imp.v_after[1] for imp in run.impacts[:5]])
    np.testing.assert_allclose(speeds, toy.impact_speed * 0.5 ** np.arange(1, 6), rtol=1e-9)


@pytest.mark.parametrize("options, field", [({"order": 5}, "order"), ({"order": 1}, "order"),
                                            ({"h": 0.0}, "h"), ({"h": math.nan}, "h")])
def test_bad_options_are_refused(options, field):
    toy = BouncingBall()
    q0, v0 = toy.initial_state()
    with pytest.raises(InputError, match=field):
        nr.simulate(toy.scene(), q0, v0, 1.0, "hybrid", **options)


def test_rocking_block_impacts_at_housners_ratio():
    """Housner's block (α = 41°, e = 0) at h = 1e-2: every impact while |θ̇| ≥ 0.05 rad/s at the
    reference's time (1e-6 s) with Housner's velocity ratio 1 − 1.5 sin²α (1e-6)."""
    from nonsmooth_rod import toys

    toy = toys.RockingBlock(half_width=0.3 * math.tan(math.radians(41.0)), half_height=0.3)
    q0, v0 = toy.initial_state()
    reference = nr.simulate(toy.scene(), q0, v0, 1.0, "event-driven", rtol=1e-11, atol=1e-11)
    run = nr.simulate(toy.scene(), q0, v0, 1.0, "hybrid", h=1e-2)
    pairs = [(t, before, after) for t, before, after in toys.impact_rate_pairs(run) if abs(before) >= 0.05]
    assert len(pairs) == 4  # |θ̇| 1.95, 0.69, 0.24, 0.087 rad/s: each the ratio times the one before
    ref_times = [imp.t for imp in reference.impacts]
    for k, (t, before, after) in enumerate(pairs):
        assert abs(t - ref_times[k]) <= 1e-6
        assert abs(abs(after / before) - toy.ratio) <= 1e-6


@pytest.mark.parametrize("delta", [1e-6, -1e-6])
def test_first_event_predicts_the_grazing_break_away(delta):
    """Hybrid.first_event (what error-controlled Moreau–Jean plans its windows on) from the
    rod's start in its rolling modes: the reference's first break-away within 1e-7 s (below the
    peak, δ < 0, T/N meets μs at a slope ~ √δ: the hybrid method's steps of 1e-2 s measured 6e-8 s
    there; above it, 1e-8), with δ = +1e-6 the one after rolling through the peak."""
    from nonsmooth_rod.integrators.hybrid import Hybrid, HybridOptions

    peak = rolling_hypothesis(RodProblem.paper(None, mu_s=0.3, mu_d=0.2)).T_over_N_max
    problem = RodProblem.paper(None, mu_s=peak + delta, mu_d=0.2)
    reference = simulate_rod(problem, "event-driven")
    q0, v0 = problem.initial_state()
    first = reference.phases[0].t_end
    predicted = Hybrid(HybridOptions(h=1e-2)).first_event(problem.scene(), 0.0, q0, v0, ["stick", "open"], 0.5)
    assert predicted[1].startswith("break") and predicted[2] == 0
    assert abs(predicted[0] - first) <= 1e-7
    if delta > 0:
        assert first > 0.2  # rolls through the peak at 0.158 s
