"""The paper's switched formulation: right where nothing reverses, wrong where it should re-stick."""
from __future__ import annotations

import pytest

from nonsmooth_rod.rod.switched import SwitchedOptions, SwitchedRod
from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.rod.simulation import simulate
from nonsmooth_rod.validation import InputError

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

# Event-driven reference (rtol 1e-12).
REF = {1: (0.336957, [("slip-", 0.328527), ("slip+", 0.336957)]),
       2: (0.375302, [("stick", 0.104101), ("slip-", 0.302348), ("slip+", 0.375302)]),
       3: (0.381775, [("stick", 0.301986), ("slip+", 0.381775)])}


@pytest.mark.parametrize("case", [1, 2, 3])
def test_rk4_reproduces_the_paper_cases_within_the_step(case):
    h = 1e-4
    run = simulate(RodProblem.paper(case), "switched", h=h)
    t_impact, phases = REF[case]
    assert run.status == "ok"
    assert [p.mode for p in run.phases] == [m for m, _ in phases]
    # Switches are seen at step ends only: every boundary lies within the step around it.
    for ph, (_, t_end) in zip(run.phases[:-1], phases[:-1]):
        assert abs(ph.t_end - t_end) <= h + 1e-9
    assert run.impact["t"] == pytest.approx(t_impact, abs=2 * h)


def test_adaptive_steps_without_event_location_miss_the_break_away():
    # Rolling is smooth, so RK45 takes long steps and notices |T/N| > μs only at a step's end:
    # in case 2 the slide starts ~20 ms late (the exact break-away is at 0.104101 s).
    run = simulate(RodProblem.paper(2), "switched", ode_method="RK45", rtol=1e-8, h=1e-3)
    assert run.status == "ok"
    late = run.phases[0].t_end - 0.104101
    assert 5e-3 < late < 5e-2
    assert abs(run.impact["t"] - 0.375302) > 1e-3


def test_misses_the_restick_and_chatters_at_a_reversal():
    # (μs, μd) = (0.28, 0.24): the reference rolls, slides left, STICKS again at the reversal
    # (0.2806–0.2921 s) and slides right. The switched equations never test for re-sticking.
    p = RodProblem.paper(None, mu_s=0.28, mu_d=0.24)
    ref = simulate(p)
    assert [ph.mode for ph in ref.phases] == ["stick", "slip-", "stick", "slip+"]
    rk4 = simulate(p, "switched", h=1e-4)
    assert [ph.mode for ph in rk4.phases] == ["stick", "slip-", "slip+"]  # the re-stick is missed
    assert rk4.phases[1].t_end == pytest.approx(ref.phases[1].t_end, abs=2e-4)
    # An adaptive method meets the sign switch step after step: v_C flips sign hundreds of times.
    rk45 = simulate(p, "switched", ode_method="RK45", rtol=1e-6, h=1e-3, time_limit=20)
    assert rk45.result.stats["reversals"] > 100
    assert rk45.result.stats["min_step"] < 1e-5
    assert len(rk45.phases) > 100


def test_bad_integrator_is_an_input_error():
    with pytest.raises(InputError, match="integrator"):
        SwitchedOptions(integrator="euler")
    with pytest.raises(InputError, match="h"):
        SwitchedOptions(h=0.0)


def test_time_limit_ends_a_stalled_adaptive_run():
    p = RodProblem.paper(None, mu_s=0.28, mu_d=0.24)
    run = simulate(p, "switched", ode_method="LSODA", rtol=1e-6, h=1e-3, time_limit=1.0)
    assert run.status == "time-limit"
    assert run.result.stats["wall_time_s"] < 2.5
    assert run.result.stats["reversals"] > 1000
