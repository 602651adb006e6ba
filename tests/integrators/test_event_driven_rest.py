"""Event-driven reference: a body at rest costs (almost) nothing, and the rest is exact."""
import math
from pathlib import Path

import numpy as np
import pytest

import nonsmooth_rod as nr

from nonsmooth_rod.integrators.event_driven import EventDriven, EventDrivenOptions
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import DiskOnLine, Line, PointOnLine
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.model.scene import Scene
from nonsmooth_rod.validation import InputError
from scripts import load_script

G, MASS, WIDTH, HEIGHT, MU_S, MU_D = 9.81, 2.0, 0.2, 0.1, 0.5, 0.4
BENCH = Path(__file__).resolve().parents[2] / "benchmarks" / "bench_event_driven_rest.py"


def block(applied_force=None):
    law = ContactLaw.of(MU_S, MU_D, 0.0)
    corners = [PointOnLine(0, (-WIDTH / 2, -HEIGHT / 2), Line(), law, name="left"),
               PointOnLine(0, (WIDTH / 2, -HEIGHT / 2), Line(), law, name="right")]
    body = RigidBody(MASS, MASS * (WIDTH**2 + HEIGHT**2) / 12, name="block")
    return Scene([body], corners, gravity=G, applied_force=applied_force), np.array([0.0, HEIGHT / 2, 0.0])


def test_a_block_at_rest_is_held_to_t_end_without_a_step():
    scene, q0 = block()
    res = EventDriven().run(scene, q0, np.zeros(3), 100.0)
    assert res.status == "ok" and res.steps == 0 and res.stats["rest_from"] == 0.0
    traj = res.trajectory
    assert len(traj.t) == 100_001 and traj.t[-1] == 100.0
    assert np.all(traj.q == q0) and np.all(traj.v == 0.0)
    assert np.allclose(traj.normal_force, MASS * G / 2, rtol=1e-12)  # each corner carries half
    assert np.allclose(traj.tangential_force, 0.0, atol=1e-12 * MASS * G)
    assert [ph.mode for ph in res.phases["left"]] == ["stick"] and res.phases["left"][0].t_end == 100.0


def test_a_block_slides_to_rest_then_is_held():
    # Launched at 1 m/s: it stops after v0 / (μd g) having slid v0² / (2 μd g), and stays.
    scene, q0 = block()
    v0 = 1.0
    res = EventDriven().run(scene, q0, np.array([v0, 0.0, 0.0]), 50.0)
    t_stop = v0 / (MU_D * G)
    assert [ph.mode for ph in res.phases["left"]] == ["slip+", "stick"]
    assert res.phases["left"][0].t_end == pytest.approx(t_stop, abs=1e-9)
    assert res.stats["rest_from"] == pytest.approx(t_stop, abs=1e-9)
    assert res.trajectory.q[-1, 0] == pytest.approx(v0**2 / (2 * MU_D * G), abs=1e-9)
    assert res.trajectory.v[-1, 0] == 0.0
    assert res.steps < 50


def test_under_an_applied_force_the_step_grows_instead_of_being_capped():
    # A ball pushed along the floor at its contact point stays at rest, friction T = −F holding
    # it. The push is a function of t, which the integrator cannot assume constant: it
    # integrates, but with nothing happening the step grows to the whole run.
    radius, push_force = 0.05, 1.0

    def push(t, q, v):
        return np.array([push_force, 0.0, push_force * radius])  # applied at the contact point
    ball = DiskOnLine(0, (0.0, 0.0), Line(), radius, ContactLaw.of(MU_S, MU_D, 0.0), name="ball")
    scene = Scene([RigidBody(MASS, 0.4 * MASS * radius**2)], [ball], gravity=G, applied_force=push)
    q0 = np.array([0.0, radius, 0.0])
    res = EventDriven(EventDrivenOptions(output_dt=1.0)).run(scene, q0, np.zeros(3), 1000.0)
    assert res.status == "ok" and res.stats["rest_from"] is None
    assert [ph.mode for ph in res.phases["ball"]] == ["stick"]
    assert res.steps < 60
    assert np.max(np.abs(res.trajectory.q - q0)) < 1e-9
    assert np.allclose(res.trajectory.tangential_force, -push_force, rtol=1e-9)
    assert np.allclose(res.trajectory.normal_force, MASS * G, rtol=1e-12)


def test_an_output_grid_too_fine_to_hold_is_refused_up_front():
    scene, q0 = block()
    with pytest.raises(InputError, match="output_dt"):
        nr.simulate(scene, q0, np.zeros(3), 100.0, method="event-driven", output_dt=1e-12)
    with pytest.raises(InputError, match="v0"):
        nr.simulate(scene, q0, [0.0, math.nan, 0.0], 1.0, method="event-driven")
    with pytest.raises(InputError, match="q0"):
        nr.simulate(scene, q0[:2], np.zeros(3), 1.0, method="event-driven")


def test_the_resting_benchmark_runs_in_quick_mode(capsys):
    bench = load_script(BENCH)
    assert bench.main(["--quick"]) == 0
    out = capsys.readouterr().out
    assert "at rest" in out and "applied force" in out and "ED/MJ" in out
