"""Painlevé's sliding rod: the event-driven sliding equations lose consistency at the edge of
the band J/m + a² cos²θ < μd a² cos θ sin θ; Moreau–Jean passes it with a tangential impact
(a finite impulse without a collision)."""
import math

import numpy as np
import pytest

from nonsmooth_rod import toys

ROD = toys.PainleveRod()  # μs = μd = 2, end launched at −10 m/s at θ0 = 30°
THETA_EDGE = ROD.painleve_band()[0]  # 37.377°: the lower edge of the inconsistent band


def _slip_and_normal_velocity(rod, run):
    scene = rod.scene()
    kin = [scene.kinematics(q, v)[0] for q, v in zip(run.trajectory.q, run.trajectory.v)]
    u_T = np.array([k.H_T @ v for k, v in zip(kin, run.trajectory.v)])
    u_N = np.array([k.H_N @ v for k, v in zip(kin, run.trajectory.v)])
    return u_T, u_N


def test_band_and_critical_friction_closed_form():
    lo, hi = ROD.painleve_band()
    np.testing.assert_allclose(ROD.consistency([lo, hi]), 0.0, atol=1e-12)
    assert ROD.consistency(0.5 * (lo + hi)) < 0 < ROD.consistency(lo - 0.01)
    theta = np.linspace(0.01, 1.56, 20001)
    # thin uniform rod: sliding can become inconsistent only for μ > 4/3
    assert min(toys.PainleveRod.critical_mu(t) for t in theta) == pytest.approx(4 / 3, rel=1e-6)
    assert toys.PainleveRod(mu_s=1.3, mu_d=1.3).painleve_band() is None


def test_event_driven_stops_with_painleve_at_the_band_edge_not_garbage():
    # rtol 1e-10: at 1e-12 the stiff approach to N → ∞ costs ten times the evaluations (2.4 s)
    # for the same stop (θ agrees to 1e-12 rad)
    run = toys.run(ROD, "event-driven", 0.3, rtol=1e-10)
    assert run.status == "painleve", run.message
    tr = run.trajectory
    assert np.all(np.isfinite(tr.q)) and np.all(np.isfinite(tr.v))
    assert tr.q[-1, 2] == pytest.approx(THETA_EDGE, abs=1e-6)  # measured 1e-12 rad
    u_T, _ = _slip_and_normal_velocity(ROD, run)
    assert np.all(u_T < -1.0)  # still sliding when consistency is lost: no stick in sight
    assert set(tr.modes.ravel()) == {"slip-"}
    # the normal force grows without bound on the approach (15 N at the start)
    assert tr.normal_force[-1, 0] > 1e6 and tr.normal_force[0, 0] < 20


def _tangential_impact(h):
    run = toys.run(ROD, "moreau-jean", 0.13, h=h)
    assert run.status == "ok", run.message
    tr = run.trajectory
    impulse = tr.normal_force[:, 0] * h
    k = int(np.argmax(impulse))
    u_T, u_N = _slip_and_normal_velocity(ROD, run)
    return run, k, impulse, u_T, u_N


def test_moreau_jean_passes_the_band_edge_with_a_tangential_impact():
    impulses = {}
    for h in (1e-4, 1e-5):
        run, k, impulse, u_T, u_N = _tangential_impact(h)
        mg_h = ROD.mass * ROD.g * h
        # one step carries a finite impulse, thousands of times a step of weight ...
        assert impulse[k] > 500 * mg_h
        assert np.all(np.delete(impulse, k) < 0.5 * impulse[k])
        # ... where the sliding equations lose consistency, without a collision: the end
        # arrives with no normal approach speed (|u_N⁻| ~ 1e-4 m/s, the O(h) drift of a
        # velocity-level constraint) against a slip of ~2 m/s
        assert abs(run.trajectory.q[k - 1, 2] - THETA_EDGE) < 5e-3
        assert abs(u_N[k - 1]) < 1e-3
        # the slip stops (|u_T| collapses) and the rod is thrown off the floor
        assert u_T[k - 1] < -1.5 and abs(u_T[k]) < 0.15 * abs(u_T[k - 1])
        assert u_N[k] > 0.0 and set(run.trajectory.modes[k + 1:, 0]) == {"open"}
        impulses[h] = impulse[k]
    # an impact: the impulse stays finite as h → 0 (measured 0.652 and 0.627 N·s)
    assert impulses[1e-5] == pytest.approx(impulses[1e-4], rel=0.1)
