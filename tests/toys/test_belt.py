"""Stick–slip oscillator: a block on a belt (a moving line) held by a spring. The limit cycle
against its closed form: stick time 2 y0/v_b, slip time (2π − 2 atan(ω y0/v_b))/ω, slip onset
at spring force μs N, friction μd N while slipping."""
import numpy as np
import pytest

from nonsmooth_rod import toys

BELT = toys.BeltOscillator(belt_speed=0.1, stiffness=100.0, mu_s=0.6, mu_d=0.4)


def _durations(phases, word):
    return np.array([end - start for mode, start, end in phases if mode == word])


def _friction_ratio(run):
    """T/N of the block; Moreau–Jean's first sample (t = 0) carries no step, hence no force."""
    tr = run.trajectory
    ratio = np.full(len(tr.t), np.nan)
    N = tr.normal_force.sum(axis=1)
    ratio[N > 0] = tr.tangential_force.sum(axis=1)[N > 0] / N[N > 0]
    return ratio


def test_event_driven_limit_cycle_matches_closed_form():
    run = toys.run(BELT, "event-driven", 2.0)
    assert run.status == "ok", run.message
    phases = toys.stick_slip_phases(run)
    assert [p[0] for p in phases] == ["stick", "slip", "stick", "slip", "stick"]
    assert phases[1][1] == pytest.approx(BELT.first_slip_time, abs=1e-9)
    np.testing.assert_allclose(_durations(phases, "slip"), BELT.slip_time, atol=1e-9)
    np.testing.assert_allclose(_durations(phases[:-1], "stick")[1:], BELT.stick_time, atol=1e-9)
    # slip onset where the spring force reaches μs N, re-stick at x = (2 μd − μs) N / k
    tr = run.trajectory
    for mode, start, end in phases[1:-1]:
        k0 = np.flatnonzero(run.t == start)[0]
        if mode == "slip":
            assert BELT.stiffness * tr.q[k0, 0] == pytest.approx(BELT.mu_s * BELT.normal_force, rel=1e-9)
        else:
            assert tr.q[k0, 0] == pytest.approx(BELT.restick_position, rel=1e-8)
            assert tr.v[k0, 0] == pytest.approx(BELT.belt_speed, rel=1e-8)
    slipping = np.array([set(m) == {"slip-"} for m in tr.modes])
    np.testing.assert_allclose(_friction_ratio(run)[slipping], BELT.mu_d, rtol=1e-9)


@pytest.mark.parametrize("h", [1e-3, 5e-4])
def test_moreau_jean_limit_cycle_first_order(h):
    run = toys.run(BELT, "moreau-jean", 2.0, h=h)
    assert run.status == "ok", run.message
    phases = toys.stick_slip_phases(run)
    assert [p[0] for p in phases] == ["stick", "slip", "stick", "slip", "stick"]
    # onset within the step after t* (measured 0.4 h, 0.8 h): the spring force is explicit
    assert 0 < phases[1][1] - BELT.first_slip_time <= h * (1 + 1e-9)
    # slip and stick within the bounds of phase_time_bounds (r = 1.96: slip in [−3.0 h, 0],
    # stick in [0, 6.9 h]; measured −1.43 h, −0.86 h and +3.6 h, +3.2 h)
    _, slip, stick = phase_time_bounds(BELT, h)
    slips = _durations(phases, "slip") - BELT.slip_time
    sticks = _durations(phases[:-1], "stick")[1:] - BELT.stick_time
    assert np.all((slip[0] <= slips) & (slips <= slip[1]))
    assert np.all((stick[0] <= sticks) & (sticks <= stick[1]))
    tr = run.trajectory
    slipping = np.array([set(m) == {"slip-"} for m in tr.modes])
    slipping[0] = False
    assert slipping.sum() > 0.3 / h
    np.testing.assert_allclose(_friction_ratio(run)[slipping], BELT.mu_d, rtol=1e-9)
    sticking = np.array([set(m) == {"stick"} for m in tr.modes])
    sticking[0] = False
    # while stuck it rides the belt and the spring is held by at most μs N
    np.testing.assert_allclose(tr.v[sticking, 0], BELT.belt_speed, rtol=1e-9)
    assert np.all(np.abs(_friction_ratio(run)[sticking]) <= BELT.mu_s * (1 + 1e-9))


def phase_time_bounds(belt, h):
    """Bounds (docs/toys.md) on Moreau–Jean's onset, slip and stick time errors, in terms of
    r = ω y0 / v_b: onset in (0, h]; slip in [−2 (1 + 1/r) h, 0]; stick in
    [0, 2 (1 + r + 1/r) h]. The slip ends where its velocity reaches the belt's with slope
    ω² y0, so an O(v_b ω h) velocity error moves the re-stick by ~h/r; the stick then starts
    at a position off by O(√(y0² + (v_b/ω)²) ω h), i.e. ~h √(1 + r²) of belt travel."""
    r = belt.omega * belt.slip_amplitude / belt.belt_speed
    return (0.0, h), (-2 * (1 + 1 / r) * h, 0.0), (0.0, 2 * (1 + r + 1 / r) * h)


# r = 0.08 (grazing re-stick), 1.2, 2.0 (the default belt), 11.8 (slow belt: long stick)
BELTS = [toys.BeltOscillator(0.3, 400.0, 0.5, 0.45), toys.BeltOscillator(0.3, 30.0, 0.6, 0.4), BELT,
         toys.BeltOscillator(0.05, 100.0, 0.8, 0.2)]


@pytest.mark.parametrize("belt", BELTS, ids=lambda b: f"r={b.omega * b.slip_amplitude / b.belt_speed:.2g}")
def test_moreau_jean_phase_times_within_their_bounds_for_every_belt(belt):
    """What holds for all parameters (measured over v_b = 0.05…0.3, k = 30…400, (μs, μd) =
    (0.6, 0.4), (0.5, 0.45), (0.8, 0.2), h = 2e-3…1e-4, r = 0.08…21: slip errors within 0.8
    of their bound, stick errors within 0.8, onset errors 0.13 h … 1.0 h)."""
    for h in (2e-3, 5e-4):
        run = toys.run(belt, "moreau-jean", belt.first_slip_time + belt.period + belt.slip_time / 2, h=h)
        assert run.status == "ok", run.message
        phases = toys.stick_slip_phases(run)
        assert [p[0] for p in phases] == ["stick", "slip", "stick", "slip"]
        onset, slip, stick = phase_time_bounds(belt, h)
        assert onset[0] < phases[1][1] - belt.first_slip_time <= onset[1] * (1 + 1e-9)
        assert slip[0] <= phases[1][2] - phases[1][1] - belt.slip_time <= slip[1]
        assert stick[0] <= phases[2][2] - phases[2][1] - belt.stick_time <= stick[1]
