"""Where each method fails, measured: regularised creep and cost, the bistable start, Painlevé,
Zeno, and Moreau–Jean's θ < ½."""
from __future__ import annotations

import math

import numpy as np
import pytest

from nonsmooth_rod.rod import study
from nonsmooth_rod.cli import main
from nonsmooth_rod.integrators.moreau_jean import MoreauJeanOptions
from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.rod.simulation import simulate
from nonsmooth_rod.validation import InputError


@pytest.fixture(scope="module")
def eps_rows():
    return study.epsilon_study(epsilons=(1e-3, 1e-4, 1e-5), ode_methods=("RK45", "LSODA"))


def test_regularized_stick_creeps_in_proportion_to_epsilon(eps_rows):
    # Case 3 should roll for 0.30 s: the contact point must not move. With a regularised curve
    # it creeps at about ε·(something of order one) — measured over three ε.
    rk = [r for r in eps_rows if r["ode_method"] == "RK45"]
    creep = [r["creep_m"] for r in rk]
    assert creep[0] > 1e-5  # ε = 1e-3: tens of µm in 50 ms
    for big, small in zip(creep, creep[1:]):
        assert 7.0 < big / small < 13.0  # ∝ ε
    # The creep velocity stays below ε: the held contact sits on the rising part of the curve.
    for r in rk:
        assert 0.2 * r["epsilon"] < r["creep_velocity"] < r["epsilon"]


def test_explicit_integrator_cost_grows_like_one_over_epsilon(eps_rows):
    rk = [r for r in eps_rows if r["ode_method"] == "RK45"]
    for big, small in zip(rk, rk[1:]):
        assert 5.0 < small["nfev"] / big["nfev"] < 15.0
        assert 5.0 < big["median_step"] / small["median_step"] < 15.0
    # A stiff integrator does not pay for the small ε.
    ls = [r for r in eps_rows if r["ode_method"] == "LSODA"]
    assert max(r["nfev"] for r in ls) < 3 * min(r["nfev"] for r in ls)
    assert ls[-1]["nfev"] < rk[-1]["nfev"] / 10


def test_large_epsilon_gets_the_phases_wrong():
    # ε = 1e-2: case 3's contact slides (creeps beyond the stick band) from the start instead of
    # rolling until 0.302 s, and x_O drifts by millimetres.
    ref = study.reference(3)
    run = simulate(RodProblem.paper(3), "regularized", epsilon=1e-2, ode_method="LSODA", rtol=1e-8)
    m = study.measure(run, ref)
    assert run.phases[0].mode != "stick"
    assert not m["phases_ok"]
    assert m["creep_m"] > 1e-3
    finished, right, reasons = study.verdict(m, ref.problem)
    assert finished and not right and "creep at stick" in reasons


def test_bistable_start_map_right_only_with_small_epsilon_and_tight_tolerance():
    rows = study.bistable_map(epsilons=(1e-3, 1e-6), tolerances=(1e-3, 1e-8), ode_method="LSODA")
    cell = {(r["epsilon"], r["rtol"]): r for r in rows}
    right = cell[(1e-6, 1e-8)]
    assert right["rolls"] and right["phases_ok"]
    assert abs(right["impact_shift_s"]) < 1e-4
    # Loose tolerance: the integrator overshoots the static peak and the rod slides away early;
    # the impact comes ~14 ms early.
    loose = cell[(1e-6, 1e-3)]
    assert not loose["rolls"] and loose["stick_until"] < 0.05
    assert -20e-3 < loose["impact_shift_s"] < -8e-3
    # Large ε: slides from the start whatever the tolerance.
    for tol in (1e-3, 1e-8):
        assert not cell[(1e-3, tol)]["rolls"]
        assert not cell[(1e-3, tol)]["phases_ok"]


def test_event_driven_stops_at_painleve_and_zeno_where_moreau_jean_runs_on():
    out = study.painleve_and_zeno(h=1e-3)
    pa, ze = out["painleve"], out["zeno"]
    assert pa["ed_status"] == "painleve" and 0.0 < pa["ed_t_stop"] < 0.2
    assert pa["mj_status"] == "ok" and pa["mj_t_end"] == pytest.approx(0.2)
    assert pa["mj_E_max"] <= pa["E0"] * (1 + 1e-9)  # energy never above the start
    assert pa["mj_E_end"] < 0.5 * pa["E0"]  # friction took most of it
    assert ze["ed_status"] == "zeno"
    assert ze["ed_t_stop"] == pytest.approx(ze["zeno_time"], abs=1e-3)
    assert ze["mj_status"] == "ok" and ze["mj_t_end"] == pytest.approx(1.0)
    assert ze["mj_E_max"] <= ze["E0"] * (1 + 1e-9)
    assert ze["mj_final_speed"] < 1e-6 and abs(ze["mj_final_height"]) < 1e-4
    assert ze["mj_E_end"] == pytest.approx(ze["E_rest"], abs=1e-3)


def test_moreau_jean_theta_below_half_gains_energy_and_is_refused_by_default(capsys):
    rows = {r["theta"]: r for r in study.theta_energy(thetas=(0.3, 0.5))}
    gain = rows[0.3]
    assert gain["gain_before_impact"] > 0.05  # J: 45 free-flight steps of (½ − θ) m g² h²
    assert gain["gain_before_impact"] == pytest.approx(gain["predicted_gain"], rel=1e-6)
    assert gain["E_max"] > gain["E0"] * 1.005
    assert abs(rows[0.5]["gain_before_impact"]) < 1e-9
    assert rows[0.5]["E_max"] <= rows[0.5]["E0"] * (1 + 1e-12)
    with pytest.raises(InputError, match="gain energy"):
        MoreauJeanOptions(theta=0.3)
    with pytest.raises(InputError, match="gain energy"):
        simulate(RodProblem.paper(2), "moreau-jean", theta=0.3)
    assert main(["simulate", "--method", "moreau-jean", "--theta", "0.3", "--no-plot", "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "gain energy" in err[0]


def test_event_driven_keeps_a_short_break_away_window_at_loose_tolerance_without_a_step_cap():
    # Case 2: T/N exceeds μs = 0.28 only between 0.104 and ~0.21 s (its maximum is 0.290).
    # Watching for sign changes between steps, DOP853 at rtol 1e-6 without a step cap stepped
    # across that window and never saw the event (it rolled on to 0.295 s, impact 6.7 ms late).
    # The integrator now watches each indicator over the whole step (its interior extrema), so
    # the break-away is found at every tolerance, with or without the cap.
    from nonsmooth_rod.integrators.event_driven import EventDriven, EventDrivenOptions

    ref = study.reference(2)
    for rtol in (1e-4, 1e-6, 1e-8):
        run = simulate(RodProblem.paper(2), rtol=rtol)
        assert [p.mode for p in run.phases] == [p.mode for p in ref.phases]
        assert abs(run.impact["t"] - ref.t_impact) < 1e-3
        assert math.isfinite(study.measure(run, ref)["x_O_error_m"])
    p = RodProblem.paper(2)
    uncapped = EventDriven(EventDrivenOptions(rtol=1e-6, atol=1e-6, max_step=np.inf, stop_at_impact="B"))
    res = uncapped.run(p.scene(), *p.initial_state(), 10.0)
    assert [ph.mode for ph in res.phases["A"]] == [ph.mode for ph in ref.phases]
    assert abs(res.impacts[0].t - ref.t_impact) < 1e-3
    assert np.isfinite(ref.x_O_at([0.1, 0.2])).all()
