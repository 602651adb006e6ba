"""Block on an incline, a block pushed by a force ramp, a disk rolling or sliding down an
incline: accelerations, thresholds and stick–slip onset against their closed forms."""
import math

import numpy as np
import pytest

from nonsmooth_rod import toys

METHODS = ["moreau-jean", "event-driven"]


def _fitted_slope_acceleration(run, toy):
    _, ds = toys.slope_motion(run, toy)
    return np.polyfit(run.t, ds, 1)[0]


def _contact_modes(run):
    return set(run.trajectory.modes[1:].ravel())


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("degrees", [20.0, 30.0])
def test_block_released_on_incline_sticks_or_slides(method, degrees):
    block = toys.BlockOnIncline(angle=math.radians(degrees), mu_s=0.5, mu_d=0.3)
    run = toys.run(block, method, 0.5, h=1e-3)
    assert run.status == "ok", run.message
    s, ds = toys.slope_motion(run, block)
    if block.holds:  # tan 20° = 0.364 ≤ μs = 0.5: held by static friction, no creep
        assert np.max(np.abs(s)) < 1e-12 and np.max(np.abs(ds)) < 1e-12
        assert _contact_modes(run) == {"stick"}
    else:  # tan 30° = 0.577 > μs: slides with g (sin α − μd cos α) (measured error ~1e-14)
        a = _fitted_slope_acceleration(run, block)
        assert a == pytest.approx(block.sliding_down_acceleration, rel=1e-6)
        assert _contact_modes(run) == {"slip-"}
    # it neither tips nor leaves the slope
    assert np.max(np.abs(run.trajectory.q[:, 2] - block.angle)) < 1e-9


# Event-driven included: with two sticking corners the forces are statically indeterminate,
# and "held" means some split lies inside both cones (model.dynamics._most_admissible_split).
THRESHOLD_CASES = [
    ("moreau-jean", +1e-3, True), ("moreau-jean", -1e-3, False),
    ("event-driven", -1e-3, False), ("event-driven", +1e-3, True),
]


@pytest.mark.parametrize("method, margin, holds", THRESHOLD_CASES)
def test_block_threshold_is_tan_alpha_equal_mu_s(method, margin, holds):
    """μs a thousandth above or below tan α decides between rest and sliding with μd."""
    alpha = math.radians(25.0)
    block = toys.BlockOnIncline(angle=alpha, mu_s=math.tan(alpha) + margin, mu_d=0.3)
    run = toys.run(block, method, 0.2, h=1e-3)
    s, _ = toys.slope_motion(run, block)
    if holds:
        assert np.max(np.abs(s)) < 1e-12
    else:
        assert _fitted_slope_acceleration(run, block) == pytest.approx(block.sliding_down_acceleration, rel=1e-6)


@pytest.mark.parametrize("h", [1e-3, 7e-4, 3e-4])
@pytest.mark.parametrize("degrees", [20.0, 30.0])
def test_block_launched_up_stops_then_resticks_or_slides_back(h, degrees):
    """Launched up at 1 m/s it decelerates at g (sin α + μd cos α); at the stop it stays iff
    tan α ≤ μs — for every step size (the naive 'μd if it slid' rule fails this)."""
    block = toys.BlockOnIncline(angle=math.radians(degrees), mu_s=0.5, mu_d=0.3, v0=1.0)
    run = toys.run(block, "moreau-jean", 0.6, h=h)
    s, ds = toys.slope_motion(run, block)
    going_up = run.t < block.stop_time - h
    decel = np.polyfit(run.t[going_up], ds[going_up], 1)[0]
    assert decel == pytest.approx(block.sliding_up_acceleration, rel=1e-6)
    stopped = np.flatnonzero(ds < 1e-12)[0]  # the end of the step in which it stops
    assert 0.0 <= run.t[stopped] - block.stop_time <= h
    after = run.t > block.stop_time + 2 * h
    if block.holds:
        assert np.max(np.abs(ds[after])) < 500 * np.finfo(float).eps * block.v0  # at rest to round-off
        assert np.ptp(s[after]) < 1e-12  # no creep
    else:
        back = np.polyfit(run.t[after], ds[after], 1)[0]
        assert back == pytest.approx(block.sliding_down_acceleration, rel=1e-6)
    # position against the closed form: exact except within the stopping step (measured 1.7e-3 m
    # at h = 1e-3 for 30°: the stop falls inside a step)
    assert np.max(np.abs(s - block.slope_position(run.t))) < 3 * h


def test_block_launched_up_event_driven_matches_closed_form():
    for degrees in (20.0, 30.0):
        block = toys.BlockOnIncline(angle=math.radians(degrees), mu_s=0.5, mu_d=0.3, v0=1.0)
        run = toys.run(block, "event-driven", 0.6)
        s, ds = toys.slope_motion(run, block)
        np.testing.assert_allclose(s, block.slope_position(run.t), atol=1e-10)
        np.testing.assert_allclose(ds, block.slope_velocity(run.t), atol=1e-10)


# ----------------------------------------------------------------------------- force ramp
PUSHED = toys.PushedBlock(rate=10.0, mu_s=0.5, mu_d=0.3)  # onset at μs m g / rate = 0.4905 s


@pytest.mark.parametrize("h", [1e-3, 3e-4])
def test_force_ramp_onset_and_dynamic_friction_moreau_jean(h):
    run = toys.run(PUSHED, "moreau-jean", 0.7, h=h)
    onset = toys.first_slip_time(run)
    assert abs(onset - PUSHED.onset_time) <= 2 * h  # measured 0.5 h (1e-3)
    tr = run.trajectory
    N = tr.normal_force.sum(axis=1)
    T = tr.tangential_force.sum(axis=1)
    sticking = run.t < onset
    # before the onset the floor holds the push: T = −F(t), |T| < μs N
    np.testing.assert_allclose(T[1:][sticking[1:]], -PUSHED.push(run.t[1:][sticking[1:]] - 0.5 * h), atol=1e-9)
    sliding = run.t > onset + h
    np.testing.assert_allclose(T[sliding] / N[sliding], -PUSHED.mu_d, rtol=1e-12)
    np.testing.assert_allclose(N[1:], PUSHED.mass * PUSHED.g, rtol=1e-9)
    # first order in h after the onset: velocity error (μs − μd) g × onset error
    assert np.max(np.abs(tr.v[:, 0] - PUSHED.velocity(run.t))) < 2 * (PUSHED.mu_s - PUSHED.mu_d) * PUSHED.g * h + 1e-12


def test_force_ramp_event_driven_onset_and_jump_of_acceleration():
    run = toys.run(PUSHED, "event-driven", 0.7)
    onset = toys.first_slip_time(run)
    assert abs(onset - PUSHED.onset_time) < 1e-9
    tr = run.trajectory
    np.testing.assert_allclose(tr.q[:, 0], PUSHED.position(run.t), atol=1e-10)
    np.testing.assert_allclose(tr.v[:, 0], PUSHED.velocity(run.t), atol=1e-10)
    # friction drops from μs N to μd N at the onset: ẍ jumps from 0 to (μs − μd) g and then
    # follows (rate t − μd m g)/m
    before, after = run.t <= onset, run.t > onset
    np.testing.assert_allclose(tr.a[before, 0], 0.0, atol=1e-9)
    expected = (PUSHED.rate * run.t[after] - PUSHED.mu_d * PUSHED.mass * PUSHED.g) / PUSHED.mass
    np.testing.assert_allclose(tr.a[after, 0], expected, rtol=1e-9)
    assert expected[0] - (PUSHED.mu_s - PUSHED.mu_d) * PUSHED.g < PUSHED.rate * 1e-3 / PUSHED.mass + 1e-12


# ---------------------------------------------------------------------------- disk on incline
DISK_CASES = [  # (degrees, μs, μd): rolls iff tan α ≤ 3 μs
    (30.0, 0.3, 0.2),   # tan = 0.577 ≤ 0.9: rolls
    (40.0, 0.3, 0.25),  # tan = 0.839 ≤ 0.9: rolls, although 3 μd = 0.75 would not hold it
    (45.0, 0.3, 0.3),   # tan = 1 > 0.9: slides
    (50.0, 0.3, 0.2),   # slides
]


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("degrees, mu_s, mu_d", DISK_CASES)
def test_disk_rolls_iff_tan_alpha_at_most_three_mu_s(method, degrees, mu_s, mu_d):
    disk = toys.DiskOnIncline(angle=math.radians(degrees), mu_s=mu_s, mu_d=mu_d)
    run = toys.run(disk, method, 0.5, h=1e-3)
    assert run.status == "ok", run.message
    assert _fitted_slope_acceleration(run, disk) == pytest.approx(disk.slope_acceleration, rel=1e-6)
    spin = np.polyfit(run.t, run.trajectory.v[:, 2], 1)[0]
    assert spin == pytest.approx(disk.angular_acceleration, rel=1e-6)
    assert _contact_modes(run) == ({"stick"} if disk.rolls else {"slip-"})
    if disk.rolls:
        assert disk.slope_acceleration == pytest.approx(-2 / 3 * disk.g * math.sin(disk.angle))
