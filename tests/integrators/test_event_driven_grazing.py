"""Event-driven reference: events in windows far shorter than a step are never missed.

Every case is checked against a closed form (the rod's pure-rolling equations, free flight,
a polynomial force), and run with a huge step cap and a loose tolerance too: what finds the
event is the watch over each step's indicators (their interior extrema), not a small step.
"""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from nonsmooth_rod.integrators.event_driven import EventDriven, EventDrivenOptions
from nonsmooth_rod.rod import closed_form as cf
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import DiskOnLine, Line, PointOnLine
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.model.scene import Scene
from nonsmooth_rod.rod.hypotheses import rolling_hypothesis

TIGHT = {"rtol": 1e-12, "atol": 1e-12}  # default step cap (none)
LOOSE = {"rtol": 1e-6, "atol": 1e-6, "max_step": 1.0}
G = 9.81


def rolling_ratio(p):
    """T/N(t) of pure rolling from the paper's closed form, on a tight dense solution."""
    sol = solve_ivp(lambda t, y: [y[1], cf.rolling(p, y[0], y[1])[0]], (0.0, 0.4), [p.theta0, 0.0],
                    method="DOP853", rtol=1e-13, atol=1e-15, dense_output=True)

    def ratio(t):
        _, _, N, T = cf.rolling(p, *sol.sol(t))
        return T / N
    return ratio


@pytest.fixture(scope="module")
def rod_peak():
    """max T/N of the rolling rod (0.2900265631…) and where it is reached."""
    rh = rolling_hypothesis(RodProblem.paper(None, mu_s=0.3, mu_d=0.2))
    assert rh.T_over_N_max == pytest.approx(0.2900265631, abs=1e-10)
    return rh.T_over_N_max, rh.t_max


def run_rod(mu_s, options):
    p = RodProblem.paper(None, mu_s=mu_s, mu_d=0.2)
    res = EventDriven(EventDrivenOptions(stop_at_impact="B", **options)).run(p.scene(), *p.initial_state(), 10.0)
    assert res.status == "ok"
    return p, res


@pytest.mark.parametrize("options", [TIGHT, LOOSE], ids=["tight", "loose-huge-step"])
@pytest.mark.parametrize("below", [1e-7, 1e-9])
def test_rod_breaks_away_where_T_over_N_just_touches_mu_s(rod_peak, below, options):
    peak, t_peak = rod_peak
    p, res = run_rod(peak - below, options)
    # The exact window where rolling would need T/N > μs: 0.26 ms wide at 1e-7, 26 µs at 1e-9.
    ratio = rolling_ratio(p)
    t_in = brentq(lambda t: ratio(t) - p.mu_s, t_peak - 0.01, t_peak, xtol=1e-15)
    t_out = brentq(lambda t: ratio(t) - p.mu_s, t_peak, t_peak + 0.01, xtol=1e-15)
    assert t_out - t_in < 3e-4
    modes = [ph.mode for ph in res.phases["A"]]
    assert modes[:2] == ["stick", "slip-"] and modes[-1] == "slip+"  # not rolling on to t_r2
    t_break = res.phases["A"][0].t_end
    tol = 1e-9 if options is TIGHT else 0.2 * (t_out - t_in)
    assert abs(t_break - t_in) < tol
    # The labels follow the slip velocity v_C = ẋ_O + r θ̇ of the trajectory.
    traj = res.trajectory
    (_, _, _), (xo_dot, _, om) = p.ball_a_coordinates(traj.q, traj.v)
    v_c = p.slip_velocity(xo_dot, om)
    for phase in res.phases["A"]:
        inside = (traj.t > phase.t_start + 1e-6) & (traj.t < phase.t_end - 1e-6)
        assert inside.sum() > 3
        if phase.mode == "stick":
            assert np.max(np.abs(v_c[inside])) < (1e-9 if options is TIGHT else 1e-6)
        else:
            assert np.all(np.sign(v_c[inside]) == {"slip-": -1.0, "slip+": 1.0}[phase.mode])


@pytest.mark.parametrize("options", [TIGHT, LOOSE], ids=["tight", "loose-huge-step"])
def test_rod_keeps_rolling_when_mu_s_just_exceeds_the_peak(rod_peak, options):
    peak, _ = rod_peak
    p, res = run_rod(peak + 1e-7, options)
    assert [ph.mode for ph in res.phases["A"]] == ["stick", "slip+"]
    t_r2 = rolling_hypothesis(p).t_r2
    assert res.phases["A"][0].t_end == pytest.approx(t_r2, abs=1e-9 if options is TIGHT else 1e-5)


def ball_scene(line, applied_force=None, radius=0.05, mass=2.0):
    body = RigidBody(mass, 0.4 * mass * radius**2, name="ball")
    contact = DiskOnLine(0, (0.0, 0.0), line, radius, ContactLaw.of(0.5, 0.4, 0.0), name="ball")
    return Scene([body], [contact], gravity=G, applied_force=applied_force)


@pytest.mark.parametrize("options", [TIGHT, LOOSE], ids=["tight", "loose-huge-step"])
def test_a_ball_thrown_up_that_grazes_a_ceiling_strikes_it(options):
    # Ceiling y = 1 (normal −y). The apex would put the ball 1 nm into it: the gap is positive at
    # both ends of the one free-flight step and dips below zero for 29 µs around the apex.
    radius, overlap, v_up = 0.05, 1e-9, 3.0
    y0 = 1.0 - radius + overlap - v_up**2 / (2 * G)
    scene = ball_scene(Line((0.0, 1.0), math.pi), radius=radius)
    res = EventDriven(EventDrivenOptions(**options)).run(scene, [0.0, y0, 0.0], [0.0, v_up, 0.0], 1.0)
    assert res.status == "ok"
    t_hit = (v_up - math.sqrt(2 * G * overlap)) / G  # y(t) + r = 1 on the way up
    assert len(res.impacts) == 1
    assert res.impacts[0].t == pytest.approx(t_hit, abs=1e-9 if options is TIGHT else 1e-6)
    assert res.impacts[0].v_after[1] == pytest.approx(0.0, abs=1e-12)  # e = 0: the approach stops
    assert [ph.mode for ph in res.phases["ball"]] == ["open"]  # it drops away at once
    assert res.trajectory.q[-1, 1] == pytest.approx(1.0 - radius - 0.5 * G * (1.0 - t_hit) ** 2, abs=1e-9)


def block_scene(applied_force, mass, width=0.2, height=0.1):
    law = ContactLaw.of(0.5, 0.4, 0.0)
    corners = [PointOnLine(0, (-width / 2, -height / 2), Line(), law, name="left"),
               PointOnLine(0, (width / 2, -height / 2), Line(), law, name="right")]
    body = RigidBody(mass, mass * (width**2 + height**2) / 12, name="block")
    return Scene([body], corners, gravity=G, applied_force=applied_force), [0.0, height / 2, 0.0]


def ball_on_floor(applied_force, mass, radius=0.05):
    return ball_scene(Line(), applied_force=applied_force, radius=radius, mass=mass), [0.0, radius, 0.0]


@pytest.mark.parametrize("options", [TIGHT, LOOSE], ids=["tight", "loose-huge-step"])
@pytest.mark.parametrize("body", [ball_on_floor, block_scene], ids=["ball", "block-two-corners"])
def test_a_lift_that_outweighs_gravity_for_a_millisecond_lifts_the_body_off(body, options):
    # F(t) = m g (1 + ε − k (t − t0)²) up: N = m g (k (t − t0)² − ε) < 0 for |t − t0| < w = √(ε/k).
    # Flight from t0 − w: ÿ = g k (2wτ − τ²), τ = t − (t0 − w), lands at τ = 4w with
    # ẏ = −16/3 g k w³, having risen 2.25 g k w⁴ (5.5 pm) at τ = 3w. The block's two corners
    # carry statically indeterminate forces and lift off together.
    mass, t0, eps, w = 2.0, 0.1, 1e-6, 5e-4
    k = eps / w**2

    def lift(t, q, v):
        return np.array([0.0, mass * G * (1.0 + eps - k * (t - t0) ** 2), 0.0])
    scene, q0 = body(lift, mass)
    res = EventDriven(EventDrivenOptions(output_dt=0.02, **options)).run(scene, q0, np.zeros(3), 0.2)
    assert res.status == "ok"
    for contact in scene.contacts:
        liftoffs = [e.t for e in res.events if e.kind == "liftoff" and e.contact == contact.name]
        assert len(liftoffs) == 1 and liftoffs[0] == pytest.approx(t0 - w, abs=1e-9)
        assert [ph.mode for ph in res.phases[contact.name]] == ["stick", "open", "stick"]
    assert len(res.impacts) == 1
    assert res.impacts[0].t == pytest.approx(t0 + 3 * w, abs=1e-8)
    assert res.impacts[0].v_before[1] == pytest.approx(-16 / 3 * G * k * w**3, rel=1e-3)
    assert not [e for e in res.events if e.kind in ("stick-slip", "slip-zero")]
    assert res.steps < 100  # the step grows while nothing happens: no cap forces small steps


@pytest.mark.parametrize("h", [1e-3, 1e-4])
@pytest.mark.parametrize("below", [1e-7, 1e-9])
def test_moreau_jean_also_breaks_away_in_the_grazing_window(rod_peak, below, h):
    """Moreau–Jean sees the short window too: the reference's phase sequence (stick, slip−,
    stick, slip+) and the impact within 3h. Its break-away time converges only like √h here:
    near the maximum T/N − μs is quadratic in t, so an O(h) error in the state moves the
    crossing by O(√h) (measured 6, 19 and 60 h at h = 1e-3, 1e-4, 1e-5)."""
    from nonsmooth_rod.rod.simulation import simulate

    p = RodProblem.paper(None, mu_s=rod_peak[0] - below, mu_d=0.2)
    reference, run = simulate(p), simulate(p, "moreau-jean", h=h)
    assert [ph.mode for ph in run.phases] == [ph.mode for ph in reference.phases] == ["stick", "slip-", "stick",
                                                                                       "slip+"]
    assert abs(run.phases[1].t_start - reference.phases[1].t_start) < 0.3 * math.sqrt(h)
    assert abs(run.impact["t"] - reference.impact["t"]) <= 3 * h
