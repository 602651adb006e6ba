"""The regularised-friction, penalty-contact baseline: its force laws and what it computes."""
from __future__ import annotations

import math

import numpy as np
import pytest

from nonsmooth_rod.cli import main
from nonsmooth_rod.integrators.regularized import (
    HERTZ_STEEL_STIFFNESS,
    Regularized,
    RegularizedOptions,
    friction_coefficient,
)
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import DiskOnLine, Line
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.model.scene import Scene
from nonsmooth_rod.rod.simulation import simulate
from nonsmooth_rod.validation import InputError

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)


def test_friction_curves_have_their_documented_shape():
    eps, mu_s, mu_d = 1e-3, 0.28, 0.20
    f = lambda curve, v: friction_coefficient(curve, v, eps, mu_s, mu_d, 10.0)  # noqa: E731
    # Stribeck: 0 at rest, the static peak μs at ε, μd from 10 ε on, odd.
    assert f("stribeck", 0.0) == 0.0
    assert f("stribeck", eps) == pytest.approx(mu_s, rel=1e-13)
    assert f("stribeck", 5.5 * eps) == pytest.approx(0.5 * (mu_s + mu_d), abs=1e-12)
    assert f("stribeck", 10 * eps) == pytest.approx(mu_d, rel=1e-13)
    assert f("stribeck", -3 * eps) == pytest.approx(-f("stribeck", 3 * eps), rel=1e-13)
    assert max(f("stribeck", v) for v in np.linspace(0, 0.05, 2001)) == pytest.approx(mu_s, abs=1e-12)
    # The one-coefficient curves saturate at μd and never reach μs.
    assert f("linear", 0.5 * eps) == pytest.approx(0.5 * mu_d)
    assert f("linear", 3 * eps) == mu_d
    assert f("tanh", eps) == pytest.approx(mu_d * math.tanh(1.0))
    assert f("tanh", -20 * eps) == pytest.approx(-mu_d, rel=1e-13)


@pytest.mark.parametrize("bad, match", [
    (dict(epsilon=0.0), "epsilon"), (dict(friction_curve="coulomb"), "friction_curve"),
    (dict(ode_method="Euler"), "ode_method"), (dict(contact_model="hertz"), "contact_model"),
    (dict(stiffness=-1.0), "stiffness"), (dict(stribeck_ratio=0.5), "stribeck_ratio"),
])
def test_bad_options_are_one_line_input_errors(bad, match):
    with pytest.raises(InputError, match=match):
        RegularizedOptions(**bad)


def _disk_scene(mu, radius=0.1, mass=1.0, law_e=0.0):
    body = RigidBody(mass, 0.5 * mass * radius**2, name="disk")
    contact = DiskOnLine(0, (0.0, 0.0), Line(), radius, ContactLaw.of(mu, mu, law_e), name="floor")
    return Scene([body], [contact])


def test_resting_disk_settles_at_the_hertz_penetration():
    scene = _disk_scene(0.3)
    q0, v0 = np.array([0.0, 0.1, 0.0]), np.zeros(3)
    res = Regularized(RegularizedOptions(rtol=1e-8, atol=1e-12)).run(scene, q0, v0, 0.05)
    assert res.status == "ok"
    delta = 0.1 - res.trajectory.q[-1, 1]
    expected = (9.81 / HERTZ_STEEL_STIFFNESS) ** (2 / 3)  # k δ^1.5 = m g
    assert delta == pytest.approx(expected, rel=1e-3)
    assert res.trajectory.normal_force[-1, 0] == pytest.approx(9.81, rel=1e-4)


def test_disk_launched_without_spin_starts_rolling_at_the_closed_form_time():
    # Slides with μ g deceleration until ω r = v: rolls from t* = v0 / (3 μ g) at 2 v0 / 3.
    mu, v0, r = 0.3, 1.0, 0.1
    scene = _disk_scene(mu, radius=r)
    delta = (9.81 / HERTZ_STEEL_STIFFNESS) ** (2 / 3)
    q0 = np.array([0.0, r - delta, 0.0])  # resting on its spring from the start
    res = Regularized(RegularizedOptions(epsilon=1e-5, friction_curve="tanh", ode_method="LSODA", rtol=1e-8,
                                         atol=1e-12)).run(scene, q0, np.array([v0, 0.0, 0.0]), 0.2)
    t_star = v0 / (3 * mu * 9.81)
    phases = res.phases["floor"]
    assert [p.mode for p in phases] == ["slip+", "stick"]
    assert phases[0].t_end == pytest.approx(t_star, abs=2e-4)
    assert res.trajectory.v[-1, 0] == pytest.approx(2 * v0 / 3, rel=1e-4)


def test_paper_case_2_converges_to_the_reference_as_epsilon_shrinks():
    # Reference (event-driven, rtol 1e-12): stick until 0.104101, slip- until 0.302348, impact 0.375302.
    run = simulate(RodProblem.paper(2), "regularized", epsilon=1e-6, ode_method="LSODA", rtol=1e-9)
    assert run.status == "ok"
    assert [p.mode for p in run.phases] == ["stick", "slip-", "slip+"]
    assert run.phases[0].t_end == pytest.approx(0.104101, abs=1e-3)
    assert run.phases[1].t_end == pytest.approx(0.302348, abs=1e-3)
    assert run.impact["t"] == pytest.approx(0.375302, abs=1e-4)
    # Penalty contact: ball A sinks by the Hertz depth of its load, nowhere near a visible amount.
    assert 1e-7 < run.result.stats["max_penetration"] < 2e-6


def test_time_limit_stops_an_expensive_run_with_its_status():
    run = simulate(RodProblem.paper(3), "regularized", epsilon=1e-7, ode_method="RK45", rtol=1e-8,
                   time_limit=0.5)
    assert run.status == "time-limit"
    assert run.result.stats["wall_time_s"] < 1.5
    assert run.impact is None


def test_cli_runs_the_regularized_method_and_rejects_a_bad_curve(tmp_path, capsys):
    out = tmp_path / "reg"
    assert main(["simulate", "--method", "regularized", "--epsilon", "1e-5", "--ode-method", "LSODA",
                 "--rtol", "1e-7", "--no-plot", "--quiet", "--out", str(out)]) == 0
    assert (out / "summary.json").exists()
    import json
    summary = json.loads((out / "summary.json").read_text())
    assert summary["method"] == "regularized"
    assert summary["settings"]["friction_curve"] == "stribeck"
    assert summary["impact"]["t"] == pytest.approx(0.375302, abs=5e-4)
    assert main(["simulate", "--method", "regularized", "--friction-curve", "coulomb", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "friction_curve" in err[0]
