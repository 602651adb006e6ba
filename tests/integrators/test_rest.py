"""An exact rest is a fixed point of the step map: the loop repeats the step instead of solving
it again (moreau_jean_loop._run), and the run is the very one stepping gives."""
from pathlib import Path

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod import toys
from nonsmooth_rod.integrators.scene_plans import forget_plans
from nonsmooth_rod.model.scene import Scene
from nonsmooth_rod.scenefile import load_scene

SCENES = Path(__file__).resolve().parents[2] / "examples" / "scenes"


def _ladder(mu_s):
    sf = load_scene(SCENES / "ladder.toml", [f"contacts.foot.law.mu_s={mu_s}", "contacts.foot.law.mu_d=0.1"])
    return sf.scene, sf.q0, sf.v0


def _resting_ball():
    ball = toys.BouncingBall(drop_height=0.01, restitution=0.2)
    return (ball.scene(), *ball.initial_state())


def _stepped(monkeypatch, scene, q0, v0, t_end, **opts):
    """The same run with the repetition off (the loop believes the forces change in time)."""
    with monkeypatch.context() as m:
        m.setattr(Scene, "forces_vary_in_time", lambda self: True)
        forget_plans()  # a kept plan holds what the unpatched method said (integrators/scene_plans.py)
        try:
            return nr.simulate(scene, q0, v0, t_end, **opts)
        finally:
            forget_plans()


def _assert_same_run(a, b):
    for name in ("t", "q", "v"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    for name in ("normal_force", "tangential_force", "modes"):
        np.testing.assert_array_equal(getattr(a.trajectory, name), getattr(b.trajectory, name))
    assert a.events == b.events and a.phases == b.phases
    for key in ("solves", "solver_iterations", "inconsistent_steps", "solver_fallbacks", "steps"):
        assert a.stats[key] == b.stats[key], key


@pytest.mark.parametrize("solver", ["lemke", "pgs"])
def test_a_ladder_that_holds_is_repeated_not_solved_and_the_run_is_unchanged(monkeypatch, solver):
    scene, q0, v0 = _ladder(0.5)  # holds: 0.5 > cot 60° / 2
    fast = nr.simulate(scene, q0, v0, 0.5, h=1e-3, solver=solver)
    assert fast.stats["steps_at_rest"] >= 0.9 * fast.steps  # at rest within its first steps (pgs: ~36)
    np.testing.assert_array_equal(fast.q[-1], q0)  # exact hold: no creep
    stepped = _stepped(monkeypatch, scene, q0, v0, 0.5, h=1e-3, solver=solver)
    assert stepped.stats["steps_at_rest"] == 0
    _assert_same_run(fast, stepped)


def test_a_sliding_ladder_is_never_at_rest():
    scene, q0, v0 = _ladder(0.2)  # slides: 0.2 < 0.2887
    run = nr.simulate(scene, q0, v0, 0.3, h=1e-3)
    assert run.stats["steps_at_rest"] == 0
    assert run.q[-1, 0] > q0[0] + 1e-3  # its centre moved away from the wall


def test_a_ball_that_stops_bouncing_rests_and_windows_and_restarts_do_not_change_it(monkeypatch):
    from nonsmooth_rod.integrators import moreau_jean

    scene, q0, v0 = _resting_ball()
    fast = nr.simulate(scene, q0, v0, 1.0, h=1e-3)
    assert 0 < fast.stats["steps_at_rest"] < fast.steps and len(fast.events) >= 2
    _assert_same_run(fast, _stepped(monkeypatch, scene, q0, v0, 1.0, h=1e-3))
    monkeypatch.setattr(moreau_jean, "MAX_CHUNK", 37)  # rests found again in each window
    _assert_same_run(fast, nr.simulate(scene, q0, v0, 1.0, h=1e-3))
    half = nr.simulate(scene, q0, v0, 0.5, h=1e-3)
    again = nr.simulate(scene, half.q[-1], half.v[-1], 1.0, h=1e-3, t0=half.t[-1], resume=half.end_state)
    np.testing.assert_array_equal(again.q[-1], fast.q[-1])
    np.testing.assert_array_equal(again.v[-1], fast.v[-1])


def test_forces_that_change_in_time_always_step():
    ball = toys.BouncingBall(drop_height=1e-3, restitution=0.0)  # lands at 14 ms and rests
    late_push = nr.RampedForce(body=0, force=(1.0, 0.0), t_start=0.1, t_full=0.2)  # nothing before 0.1 s
    scene = Scene(ball.scene().bodies, ball.scene().contacts, forces=[late_push])
    run = nr.simulate(scene, *ball.initial_state(), 0.15, h=1e-3)
    assert run.stats["steps_at_rest"] == 0
    assert run.q[-1, 0] > 0.0  # the push came, at rest as the ball was before it


def test_repeat_rest_off_steps_every_step_to_the_same_run():
    scene, q0, v0 = _ladder(0.5)
    fast = nr.simulate(scene, q0, v0, 0.2, h=1e-3)
    stepped = nr.simulate(scene, q0, v0, 0.2, h=1e-3, repeat_rest=False)
    assert fast.stats["steps_at_rest"] > 0 and stepped.stats["steps_at_rest"] == 0
    _assert_same_run(fast, stepped)
