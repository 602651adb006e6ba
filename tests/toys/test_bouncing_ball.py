"""Bouncing ball: impact times, the accumulation (Zeno) time and the resting state against the
closed forms t_1 = √(2 h0/g), flights 2 e^k v_1/g, t_∞ = t_1 (1 + e)/(1 − e)."""
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
    # every flight within 2h (measured ≤ 1.55 h): the rebound speed is e·v_k, v_k being the
    # velocity at the start of the impact step, not at the impact
    assert np.max(np.abs(np.diff(times) - np.diff(exact))) < 2 * h
    # At rest once a rebound no longer outlasts a step of gravity: the tail of hops shorter than
    # ~2h/(1−e) is cut, and the flight errors add up; measured 6.6 h (1e-3), 6.1 h (5e-4).
    rest = toys.rest_time(run, BALL)
    assert abs(rest - BALL.zeno_time) < 10 * h
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
