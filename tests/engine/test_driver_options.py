"""nr.simulate's options: one check per option, by type and range, whoever passes them
(issue 29's cases, each a test). The scene-file and CLI routes are in tests/test_scenefile_limits.py."""
from __future__ import annotations

import math

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod.integrators.moreau_jean import MoreauJeanOptions


def dropped_ball():
    """A 1 kg disk of radius 0.1 m, 0.2 m above the floor (it lands at t = √(0.4 / g))."""
    contact = nr.DiskOnLine(0, (0.0, 0.0), nr.Line(), 0.1, nr.ContactLaw.of(0.3, 0.3, 0.0), name="floor")
    scene = nr.Scene([nr.RigidBody(1.0, 0.005, name="disk")], [contact])
    return scene, np.array([0.0, 0.3, 0.0]), np.zeros(3)


def refusal(method, **options) -> str:
    scene, q0, v0 = dropped_ball()
    with pytest.raises(nr.InputError) as err:
        nr.simulate(scene, q0, v0, 0.05, method, **options)
    text = str(err.value)
    assert "\n" not in text and len(text) < 300
    return text


@pytest.mark.parametrize("options, fragment", [
    (dict(h="1e-3"), "h (step size) must be a number, got '1e-3'"),
    (dict(h=10**30), "h (step size) is an integer beyond ±2^63"),
    (dict(h=True), "h (step size) must be a number, got True"),
    (dict(allow_energy_gain="false", theta=0.4), "allow_energy_gain must be true or false"),
    (dict(fast="no"), "fast must be true or false"),
    (dict(solver_options={"tol": "x"}), "solver_options.tol must be a number"),
    (dict(solver_options={"max_iter": 1e30}), "solver_options.max_iter must be a whole number"),
    (dict(solver_options={"max_iter": math.nan}), "solver_options.max_iter must be a whole number"),
    (dict(solver_options={"tol": -1.0}), "solver_options.tol must lie in (0, 1]"),
    (dict(solver_options=[1, 2]), "solver_options must be a table"),
    (dict(solver_options={"foo": 1}), "unknown setting 'foo' for solver 'lemke'"),
    (dict(solver="enum", solver_options={"max_iter": 5}), "unknown setting 'max_iter' for solver 'enum'"),
])
def test_moreau_jean_options(options, fragment):
    assert fragment in refusal("moreau-jean", **options)


@pytest.mark.parametrize("options, fragment", [
    (dict(max_events=-1), "max_events must be a whole number in [1, "),
    (dict(max_events=2.5), "max_events must be a whole number"),
    (dict(gap_tol=-1.0), "gap_tol must lie in (0, 0.001]"),
    (dict(rtol=10.0), "rtol must lie in ["),
    (dict(rtol=1e-20), "rtol must lie in ["),  # below scipy's floor, which would warn and raise it
    (dict(atol=1e20), "atol must lie in (0, 0.01]"),
    (dict(ode_method="Euler"), "unknown ode_method 'Euler'"),
    (dict(max_step=-math.inf), "max_step must be finite (or inf)"),
])
def test_event_driven_options(options, fragment):
    assert fragment in refusal("event-driven", **options)


def test_event_driven_ode_method_option_runs():
    # was `method`, which clashed with simulate's own argument and always failed
    scene, q0, v0 = dropped_ball()
    result = nr.simulate(scene, q0, v0, 0.3, "event-driven", ode_method="Radau", rtol=1e-10, atol=1e-12)
    assert result.status == "ok"
    landing = [e.t for e in result.events if e.kind in ("touchdown", "impact")]
    assert landing and landing[0] == pytest.approx(math.sqrt(0.4 / scene.gravity), rel=1e-6)


@pytest.mark.parametrize("options, fragment", [
    (dict(stiffness=1e300), "stiffness must lie in [1, 1e+15]"),
    (dict(damping=1e300), "damping must lie in [0, 1e+09]"),
    (dict(epsilon=1e-30), "epsilon (regularisation velocity) must lie in"),
    (dict(epsilon="0.1"), "must be a number"),
    (dict(time_limit=True), "time_limit must be a number"),
])
def test_regularized_options(options, fragment):
    assert fragment in refusal("regularized", **options)


def test_the_stiffest_allowed_penalty_runs_plausibly():
    # the top of the stiffness range: the disk lands and rests on the floor, no overflow
    scene, q0, v0 = dropped_ball()
    result = nr.simulate(scene, q0, v0, 0.4, "regularized", stiffness=1e15, time_limit=60)
    assert result.status in ("ok", "time-limit")
    assert np.all(np.isfinite(result.q)) and abs(result.q[-1, 1] - 0.1) < 1e-3


def test_checked_values_are_what_the_run_uses():
    opts = MoreauJeanOptions(h=1, theta=1, solver_options={"max_iter": 20.0})
    assert type(opts.h) is float and type(opts.theta) is float
    assert type(opts.solver_options["max_iter"]) is int


def test_options_checked_once_are_still_checked_by_type_and_value():
    """The driver keeps the options it checked (a study's runs share them): a value equal to a
    checked one but of another type (1 for True, 1 for 1.0 in a table) is checked afresh."""
    scene, q0, v0 = dropped_ball()
    for _ in range(2):
        run = nr.simulate(scene, q0, v0, 0.05, h=1e-3, repeat_rest=True, solver_options={"tol": 1e-12})
        assert run.status == "ok" and run.stats["h"] == 1e-3 and run.stats["steps"] == 50
    assert "repeat_rest must be true or false, got 1" in refusal("moreau-jean", h=1e-3, repeat_rest=1,
                                                                 solver_options={"tol": 1e-12})
    assert "h (step size) must be a number, got True" in refusal("moreau-jean", h=True)
    # another step: another run (the checked options are copied, never shared between runs)
    assert nr.simulate(scene, q0, v0, 0.05, h=1e-2, repeat_rest=True, solver_options={"tol": 1e-12}).steps == 5


@pytest.mark.parametrize("method", [["moreau-jean"], 7, None])
def test_a_method_that_is_not_a_name(method):
    assert "unknown method" in refusal(method)


@pytest.mark.parametrize("method", ["event-driven", "regularized"])
def test_a_step_cap_that_would_hang_is_refused(method):
    assert "max_step = 1e-12 s over a run of 0.05 s asks for more than" in refusal(method, max_step=1e-12)


def test_an_initial_state_whose_squares_overflow_is_refused():
    scene, q0, _ = dropped_ball()
    with pytest.raises(nr.InputError, match=r"v0 must lie within ±1e\+100"):
        nr.simulate(scene, q0, [1e300, 0.0, 0.0], 0.05, "event-driven")
