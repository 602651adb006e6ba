"""Event-driven reference on the paper's rod: the paper's three scenarios and exact limits."""
import math

import numpy as np
import pytest

from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.rod.hypotheses import rolling_hypothesis, sliding_hypothesis
from nonsmooth_rod.rod.simulation import scenario, simulate

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)


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


def test_frictionless_slide_is_labelled_by_its_slip_velocity():
    # μs = μd = 0: the rod slides left from release (v_C < 0 throughout) — slip−, not slip+.
    p = RodProblem.paper(None, mu_s=0.0, mu_d=0.0)
    run = simulate(p)
    assert modes(run) == ["slip-"]
    tab = run.table
    v_c = p.slip_velocity(tab["x_O_dot"], tab["theta_dot"])
    moving = tab["t"] > 0.0
    assert moving.sum() > 100 and np.all(v_c[moving] < 0)
    assert np.all(tab["mode"] == "slip-")


def test_frictionless_block_slip_label_follows_a_reversing_push():
    # A frictionless block on a floor pushed along it by F = F0 cos(2πt) at its base: from rest,
    # v = F0 sin(2πt) / (2π m) — right on (0, ½), left on (½, 1). Each corner carries no
    # friction yet slides one way, then the other, reversing exactly at t = ½.
    from nonsmooth_rod.integrators.event_driven import EventDriven
    from nonsmooth_rod.model.body import RigidBody
    from nonsmooth_rod.model.contacts import PointOnLine
    from nonsmooth_rod.model.laws import ContactLaw
    from nonsmooth_rod.model.scene import Scene

    mass, width, height, F0 = 2.0, 0.2, 0.1, 3.0

    def push(t, q, v):
        f = F0 * math.cos(2 * math.pi * t)
        return np.array([f, 0.0, f * height / 2])  # at the base: no moment about the corners
    law = ContactLaw.of(0.0, 0.0, 0.0)
    corners = [PointOnLine(0, (-width / 2, -height / 2), law=law, name="left"),
               PointOnLine(0, (width / 2, -height / 2), law=law, name="right")]
    scene = Scene([RigidBody(mass, mass * (width**2 + height**2) / 12)], corners, applied_force=push)
    res = EventDriven().run(scene, [0.0, height / 2, 0.0], np.zeros(3), 1.0)
    assert res.status == "ok"
    for name in ("left", "right"):
        assert [ph.mode for ph in res.phases[name]] == ["slip+", "slip-"]
        assert res.phases[name][0].t_end == pytest.approx(0.5, abs=1e-9)
    traj = res.trajectory
    assert np.allclose(traj.v[:, 0], F0 * np.sin(2 * math.pi * traj.t) / (2 * math.pi * mass), atol=1e-9)
    inside = (traj.t > 1e-3) & (np.abs(traj.t - 0.5) > 1e-3) & (traj.t < 1.0)
    expected = np.where(traj.t[inside] < 0.5, "slip+", "slip-")
    assert np.all(traj.modes[inside, 0] == expected) and np.all(np.sign(traj.v[inside, 0]) == np.where(
        expected == "slip+", 1.0, -1.0))
