"""Event-driven reference on the paper's rod: the paper's three scenarios and exact limits."""
import math

import numpy as np
import pytest

from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.rod.hypotheses import rolling_hypothesis, sliding_hypothesis
from nonsmooth_rod.rod.simulation import scenario, simulate


def modes(run):
    return [ph.mode for ph in run.phases]


def test_rolling_hypothesis_matches_the_paper():
    rh = rolling_hypothesis(RodProblem.paper(2))
    assert rh.T_over_N_max == pytest.approx(0.29, abs=0.005)  # paper: max(T/N) ≈ 0.29
    assert rh.T_over_N_initial == pytest.approx(0.263, abs=0.001)
    # μs = 0.28 < max: T/N first reaches +μs (t_r1), later falls through −μs (t_r2).
    assert 0.0 < rh.t_r1 < rh.t_max < rh.t_r2 < rh.t_horizontal
    i = np.searchsorted(rh.t, rh.t_r1)
    assert rh.T_over_N[i - 1] < 0.28 <= rh.T_over_N[i]


def test_case_1_slides_throughout_left_then_right():
    run = simulate(RodProblem.paper(1))
    assert run.status == "ok"
    assert modes(run) == ["slip-", "slip+"]
    assert run.phases[0].t_start == 0.0
    # The reversal is where the slip velocity crosses zero and μs = 0.12 cannot hold the
    # rolling contact (|T/N| > μs there), so it slides the other way.
    t_rev = run.phases[1].t_start
    k = np.argmin(abs(run.table["t"] - t_rev))
    assert abs(run.table["x_O_dot"][k] + 0.02 * run.table["theta_dot"][k]) < 1e-8
    assert scenario(run.phases) == "slide-at-start"


def test_case_2_rolls_until_t_r1_then_slides():
    run = simulate(RodProblem.paper(2))
    assert modes(run)[:2] == ["stick", "slip-"]
    assert run.phases[0].t_end == pytest.approx(run.rolling.t_r1, abs=1e-9)
    assert scenario(run.phases) == "roll-until-r1"
    # While rolling, the contact point does not slip and x_O = −r (θ − θ0).
    tab = run.table
    rolling = (tab["mode"] == "stick") & (tab["t"] < run.phases[0].t_end - 1e-9)
    slip = tab["x_O_dot"][rolling] + 0.02 * tab["theta_dot"][rolling]
    assert np.max(np.abs(slip)) < 1e-9
    assert np.allclose(tab["x_O"][rolling], -0.02 * (tab["theta"][rolling] - math.pi / 3), atol=1e-10)


def test_case_3_rolls_until_T_over_N_falls_to_minus_mu_s():
    run = simulate(RodProblem.paper(3))
    assert modes(run) == ["stick", "slip+"]
    assert run.phases[0].t_end == pytest.approx(run.rolling.t_r2, abs=1e-9)
    assert scenario(run.phases) == "roll-until-r2"
    assert run.impact is not None and run.impact["t"] > run.phases[0].t_end


def test_phases_are_contiguous_and_end_at_the_impact():
    for case in (1, 2, 3):
        run = simulate(RodProblem.paper(case))
        assert run.phases[0].t_start == 0.0
        for a, b in zip(run.phases, run.phases[1:]):
            assert a.t_end == b.t_start
        assert run.phases[-1].t_end == pytest.approx(run.impact["t"], abs=1e-12)
        assert abs(run.impact["theta"]) < 1e-9  # ball B strikes with the axis horizontal


def test_large_friction_rolls_until_the_impact():
    run = simulate(RodProblem.paper(None, mu_s=2.5, mu_d=2.0))
    assert modes(run) == ["stick"]
    assert scenario(run.phases) == "roll-to-impact"
    assert run.impact["t"] == pytest.approx(run.rolling.t_horizontal, abs=1e-9)


def test_frictionless_keeps_the_centre_of_mass_abscissa_and_the_energy():
    p = RodProblem.paper(None, mu_s=0.0, mu_d=0.0)
    run = simulate(p)
    assert run.status == "ok"
    traj = run.result.trajectory
    x_com = traj.q[:, 0]
    assert np.max(np.abs(x_com - x_com[0])) < 1e-12
    scene = p.scene()
    before = [scene.energy(q, v) for q, v, t in zip(traj.q, traj.v, traj.t) if t < run.impact["t"] - 1e-12]
    energy0 = scene.energy(*p.initial_state())
    assert np.max(np.abs(np.array(before) - energy0)) / energy0 < 1e-9


def test_restitution_and_continuation_after_the_impact():
    """With --t-end the run goes on after ball B's impact with both balls on the plane."""
    run = simulate(RodProblem.paper(2), t_end=0.6)
    assert run.status == "ok"
    assert run.impact is not None
    tab = run.table
    after = tab["t"] > run.impact["t"] + 1e-9
    assert np.all(np.abs(tab["theta"][after]) < 1e-9)
    # Both balls slide to rest under μd, then stick: the end state is at rest.
    assert abs(tab["x_O_dot"][-1]) < 1e-9
    assert run.phases[-1].mode == "stick"


def test_pure_sliding_hypothesis_reverses_and_sticks_filippov_when_mu_d_exceeds_the_need():
    low = sliding_hypothesis(RodProblem.paper(None, mu_s=0.10, mu_d=0.10))
    assert low.status == "ok" and low.filippov == [] and len(low.reversals) == 1
    high = sliding_hypothesis(RodProblem.paper(None, mu_s=0.30, mu_d=0.30))
    # μd = 0.30 > T/N(0) = 0.263: neither slip direction is consistent at release.
    assert high.filippov and high.filippov[0][0] == 0.0
