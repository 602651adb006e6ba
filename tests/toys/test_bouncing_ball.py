"""Bouncing ball: impact times, the accumulation (Zeno) time and the resting state against the
closed forms t_1 = √(2 h0/g), flights 2 e^k v_1/g, t_∞ = t_1 (1 + e)/(1 − e)."""
import math

import numpy as np
import pytest

from nonsmooth_rod import toys

BALL = toys.BouncingBall(drop_height=1.0, restitution=0.5)


def test_event_driven_hits_every_impact_time_and_stops_at_the_accumulation():
    run = toys.run(BALL, "event-driven", 2.0)
    assert run.status == "zeno", run.message
    times = np.array([imp.t for imp in run.impacts])
    # 15 impacts until a rebound no longer leaves the 1e-9 m contact band (measured: 15)
    assert len(times) >= 12
    np.testing.assert_allclose(times, BALL.impact_times(len(times)), rtol=0, atol=1e-9)
    speeds = np.array([imp.v_after[1] for imp in run.impacts])
    np.testing.assert_allclose(speeds, BALL.impact_speed * BALL.restitution ** np.arange(1, len(times) + 1),
                               rtol=1e-9)
    stop = run.events[-1]
    assert stop.kind == "zeno"
    assert abs(stop.detail["t_accumulation"] - BALL.zeno_time) < 1e-9
    assert times[-1] < BALL.zeno_time < times[-1] + 1e-4


def test_event_driven_ball_never_falls_through_the_floor():
    """Regression: a rebound that started a few ulps below the floor made a short hop cross
    zero twice inside one integrator step; the touchdown was missed and the ball fell through
    the floor (gap −2 m at t = 2 s, status "ok")."""
    run = toys.run(BALL, "event-driven", 2.0)
    assert toys.ball_height(run, BALL).min() > -1e-9


@pytest.mark.parametrize("h", [1e-3, 5e-4])
def test_moreau_jean_impacts_rest_and_penetration(h):
    run = toys.run(BALL, "moreau-jean", BALL.zeno_time + 0.2, h=h)
    assert run.status == "ok"
    times = np.array([imp.t for imp in run.impacts])
    exact = BALL.impact_times(len(times))
    assert len(times) >= 8  # measured 9 (h = 1e-3), 10 (h = 5e-4)
    # the first impact ends a free fall, which θ = ½ integrates exactly: the crossing root is exact
    assert abs(times[0] - exact[0]) < 1e-9
    # every flight within (1 + e)/e h = 3 h (measured ≤ 1.55 h): the rebound speed is e·v_k, v_k
    # being the velocity at the start of the impact step, and it starts from a penetration
    assert np.max(np.abs(np.diff(times) - np.diff(exact))) <= 3 * h
    # at rest within the bounds of docs/toys.md (measured 5.6 h, 5.1 h before t_∞)
    rest = toys.rest_time(run, BALL)
    early, late = rest_time_bounds(BALL, h)
    assert early <= rest - BALL.zeno_time <= late
    assert np.all(run.trajectory.v[run.t >= rest, 1] == 0.0)
    gap = toys.ball_height(run, BALL)
    # Stated bound: a contact enters a step when g + h u/2 ≤ 0, then the impact step moves by
    # h (u⁻ + u⁺)/2 = −(1 − e) h |u⁻|/2, so g ≥ −(2 − e) h (v_1 + g h)/2 (measured 0.73 and 0.33
    # of h v_1).
    e, g = BALL.restitution, BALL.g
    bound = (2 - e) * h * (BALL.impact_speed + g * h) / 2
    assert gap.min() >= -bound
    assert gap.min() < -0.2 * bound  # the bound is the right scale, not a loose one
    # resting: the remaining penetration is that of the last, tiny impacts (≤ g h²)
    assert -g * h * h <= gap[-1] <= 0.0


def test_plastic_ball_stops_at_its_first_impact():
    ball = toys.BouncingBall(drop_height=0.5, restitution=0.0)
    h = 1e-3
    run = toys.run(ball, "moreau-jean", 0.6, h=h)
    assert len(run.impacts) == 1
    assert abs(run.impacts[0].t - ball.first_impact_time) < 1e-9
    assert abs(toys.rest_time(run, ball) - ball.first_impact_time) <= h


def _hops_resolved(ball, h):
    """Upper bound on the impacts Moreau–Jean resolves: no rebound leaves the floor once the
    incoming speed e^k v_1 is below about g h/e (it stays within h² g of the floor, where the
    contact stays closed); plus 2."""
    e = ball.restitution
    return math.log(ball.impact_speed / (ball.g * h)) / math.log(1 / e) + 2


def rest_time_bounds(ball, h):
    """(earliest, latest) rest time − t_∞ that Moreau–Jean's mechanism allows (docs/toys.md).

    Per impact the rebound is e·|v| with v the velocity at the start of the impact step and it
    starts from a penetration: this moves the remaining accumulation time by between −h/e and
    +h. The ball stops at the first impact whose rebound apex stays below the floor, e² U² ≤
    2 g (2 − e) h U/2, cutting the remaining hops, 2 e U/(g (1 − e)) ≤ 2 (2 − e) h/(e (1 − e))."""
    e, n = ball.restitution, _hops_resolved(ball, h)
    return -(n / e + 2 * (2 - e) / (e * (1 - e))) * h, n * h


GRID = [toys.BouncingBall(drop_height=d, restitution=e) for e in (0.3, 0.5, 0.8) for d in (0.2, 3.0)]


def test_moreau_jean_rest_time_flights_and_penetration_within_their_bounds_for_every_ball():
    """What holds for all parameters (measured over e = 0.1…0.9, drop 0.05…3 m, h = 2e-3…1e-4:
    rest at most 0.55 of the early bound before t_∞ and 0.43 of the late one after it, flights
    within 0.83 of their bound, penetration within 0.97 of its)."""
    worst_early = 0.0
    for ball in GRID:
        e, g, v1 = ball.restitution, ball.g, ball.impact_speed
        for h in (1e-3, 2e-4):
            run = toys.run(ball, "moreau-jean", ball.zeno_time + 0.2, h=h)
            assert run.status == "ok", run.message
            times = np.array([imp.t for imp in run.impacts])
            exact = ball.impact_times(len(times))
            assert 2 <= len(times) <= _hops_resolved(ball, h)
            assert abs(times[0] - exact[0]) < 1e-9
            assert np.max(np.abs(np.diff(times) - np.diff(exact))) <= (1 + e) / e * h
            early, late = rest_time_bounds(ball, h)
            offset = toys.rest_time(run, ball) - ball.zeno_time
            assert early <= offset <= late, (e, ball.drop_height, h, offset / h)
            worst_early = max(worst_early, offset / early)
            assert toys.ball_height(run, ball).min() >= -(2 - e) * h * (v1 + g * h) / 2
    assert worst_early > 0.2  # the bound has the right scale, not a loose one
