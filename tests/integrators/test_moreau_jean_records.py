"""How a Moreau–Jean run proceeds and what it keeps: it ends exactly at t_end, thins while it runs,
tries stop conditions while it runs, and a restart from its end state continues bit for bit."""
import math
import time
from pathlib import Path

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod import toys
from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.scenefile import load_scene
from nonsmooth_rod.toys import stacks

SCENES = Path(__file__).resolve().parents[2] / "examples" / "scenes"
SOLVERS = ("lemke", "pgs", "enum")


def sliding_ladder():
    """examples/scenes/ladder.toml with floor μs 0.2, μd 0.1: it slides (issue 22's case)."""
    sf = load_scene(SCENES / "ladder.toml", ["contacts.foot.law.mu_s=0.2", "contacts.foot.law.mu_d=0.1"])
    return sf.scene, sf.q0, sf.v0, 0.3


def belt():
    toy = toys.BeltOscillator()
    return toy.scene(), *toy.initial_state(), 1.2


def rod():
    p = RodProblem.paper(2)
    return p.scene(), *p.initial_state(), 0.36


def ball_row():
    scene, q0, v0 = stacks.ball_row(2)  # 3 contacts: within enum's 4
    return scene, q0, v0, 0.2


def clipped(phases, t_from):
    return {c: [(p.mode, max(p.t_start, t_from), p.t_end) for p in ps if p.t_end > t_from] for c, ps in phases.items()}


def assert_same_continuation(full, again, t_half):
    n = len(again.t)
    for name in ("t", "q", "v", "normal_force", "tangential_force"):
        np.testing.assert_array_equal(getattr(again, name), getattr(full, name)[-n:], err_msg=name)
    assert again.modes.tolist() == full.modes[-n:].tolist()
    later = [i for i in full.impacts if i.t >= t_half]
    assert [(i.t, i.contact) for i in again.impacts] == [(i.t, i.contact) for i in later]
    for a, b in zip(again.impacts, later):
        for name in ("q", "v_before", "v_after", "normal_impulse", "tangential_impulse"):
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert clipped(again.phases, t_half) == clipped(full.phases, t_half)
    assert [(e.t, e.kind, e.contact) for e in again.events] == \
        [(e.t, e.kind, e.contact) for e in full.events if e.t >= t_half]


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("make", [sliding_ladder, belt, rod, ball_row])
def test_a_restart_at_half_time_continues_bit_for_bit(make, solver):
    scene, q0, v0, t_end = make()
    h = 1e-3
    full = nr.simulate(scene, q0, v0, t_end, h=h, solver=solver)
    half = nr.simulate(scene, q0, v0, t_end / 2, h=h, solver=solver)
    assert full.success and half.success, (full.message, half.message)
    again = half.restart(t_end=t_end)
    assert again.t[0] == half.t[-1] and again.t[-1] == t_end
    assert_same_continuation(full, again, half.t[-1])
    assert len(full.events) > 0 or make is sliding_ladder  # something happens after the restart point


def test_a_loaded_result_restarts_bit_for_bit_too(tmp_path):
    scene, q0, v0, t_end = sliding_ladder()
    sf = load_scene(SCENES / "ladder.toml", ["contacts.foot.law.mu_s=0.2", "contacts.foot.law.mu_d=0.1"])
    full = nr.simulate(scene, q0, v0, t_end, **sf.options)
    half = nr.simulate_scene(load_scene(SCENES / "ladder.toml", ["contacts.foot.law.mu_s=0.2",
                                                                 "contacts.foot.law.mu_d=0.1", "simulation.t_end=0.15"]))
    half.save(tmp_path)
    again = nr.load(tmp_path).restart(t_end=t_end)
    assert_same_continuation(full, again, 0.15)
    # from (q, v) alone the contact memory is lost: the end differs (by ~7e-7 m, issue 22)
    qv_only = nr.simulate(scene, half.q[-1], half.v[-1], t_end, t0=0.15, **sf.options)
    assert not np.array_equal(qv_only.q[-1], full.q[-1])


def test_a_run_ends_exactly_at_t_end_and_a_step_longer_than_the_run_is_shortened():
    ball = toys.BouncingBall()
    scene, (q0, v0) = ball.scene(), ball.initial_state()
    g, y0 = 9.81, q0[1]
    one = nr.simulate(scene, q0, v0, 0.1, h=10.0)  # issue 29: reported t_end = 1 s at t = 10 s, y = −489 m
    assert one.t.tolist() == [0.0, 0.1] and one.steps == 1
    # one step of 0.1 s from rest: v = −g 0.1, y = y0 + 0.1 (0 + v)/2 (θ = ½), no contact reached
    assert one.v[-1, 1] == pytest.approx(-g * 0.1, rel=1e-12)
    assert one.q[-1, 1] == pytest.approx(y0 - g * 0.1 ** 2 / 2, rel=1e-12)
    odd = nr.simulate(scene, q0, v0, 0.0105, h=1e-3)  # 10 steps and a half
    assert odd.t[-1] == 0.0105 and odd.steps == 11 and odd.t[-2] == pytest.approx(0.010, abs=1e-15)
    assert odd.v[-1, 1] == pytest.approx(-g * 0.0105, rel=1e-12)  # free fall: exact at any step
    assert odd.q[-1, 1] == pytest.approx(y0 - g * 0.0105 ** 2 / 2, rel=1e-12)
    for method, options in (("event-driven", {}), ("regularized", {})):
        other = nr.simulate(scene, q0, v0, 0.0105, method=method, **options)
        assert other.t[-1] == pytest.approx(0.0105, abs=1e-15)
        assert other.q[-1, 1] == pytest.approx(y0 - g * 0.0105 ** 2 / 2, rel=1e-9)


def test_save_every_thins_during_the_run_and_keeps_events_and_phases_exact():
    scene, q0, v0, t_end = belt()
    every = nr.simulate(scene, q0, v0, t_end, h=1e-3)
    thin = nr.simulate(scene, q0, v0, t_end, h=1e-3, save_every=0.05)
    assert len(thin.t) == 25 and thin.t[-1] == t_end  # 0, 0.05, …, 1.2
    rows = np.searchsorted(every.t, thin.t)
    np.testing.assert_array_equal(thin.q, every.q[rows])
    assert thin.modes.tolist() == every.modes[rows].tolist()
    assert [(e.t, e.kind) for e in thin.events] == [(e.t, e.kind) for e in every.events]
    assert clipped(thin.phases, 0.0) == clipped(every.phases, 0.0)
    np.testing.assert_array_equal(thin.end_state.q, every.end_state.q)


def test_a_stop_condition_ends_the_run_where_it_first_holds_without_running_on():
    ball = toys.BouncingBall(restitution=0.99)  # bounces past t_end (Zeno at 90 s): the run never comes to rest
    scene, (q0, v0) = ball.scene(), ball.initial_state()
    t_end, h = 40.0, 1e-4
    t_hold = 0.05 * t_end
    full_cpu = nr.simulate(scene, q0, v0, t_end, h=h, save_every=0.1).cpu_time_s
    stopped = nr.simulate(scene, q0, v0, t_end, h=h, save_every=0.1, stop=lambda t, q, v: t >= t_hold)
    assert stopped.status == "stopped" and stopped.t[-1] == pytest.approx(t_hold, abs=1e-9)
    assert stopped.steps == round(t_hold / h)
    assert stopped.cpu_time_s <= 0.25 * full_cpu  # ~0.08 measured (benchmarks/bench_memory.py --stop)
    # its end state is the state at the stop: a restart goes on as the unstopped run
    again = nr.simulate(scene, stopped.q[-1], stopped.v[-1], 2.5, h=h, save_every=0.1,
                        t0=stopped.t[-1], resume=stopped.end_state)
    reference = nr.simulate(scene, q0, v0, 2.5, h=h, save_every=0.1)
    np.testing.assert_array_equal(again.q[-1], reference.q[-1])


@pytest.mark.parametrize("make", [belt, rod])
def test_small_windows_give_the_very_same_run(make, monkeypatch):
    from nonsmooth_rod.integrators import moreau_jean

    scene, q0, v0, t_end = make()
    whole = nr.simulate(scene, q0, v0, t_end, h=1e-3)
    monkeypatch.setattr(moreau_jean, "MAX_CHUNK", 7)  # windows of 7 steps: slides between phase boundaries
    windows = nr.simulate(scene, q0, v0, t_end, h=1e-3)
    assert_same_continuation(whole, windows, 0.0)
    assert len(whole.events) >= 2
