"""Prescribed motions: the kernel's displacement and velocity against their closed forms, a
driven obstacle's contact kinematics, and one-line refusals of bad motions."""
import math

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

import nonsmooth_rod as nr
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import DiskOnLine, DiskOnSegment, Line, Segment
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.model.motion import (NOW_END, NOW_START, NOW_START_VELOCITY, NOW_VELOCITY, DrivenBody, Harmonic,
                                        Prescribed, Tabulated, evaluate_motions, pack_motions)
from nonsmooth_rod.model.packing import pack_scene
from nonsmooth_rod.model.scene import Scene
from nonsmooth_rod.validation import InputError


@pytest.mark.parametrize("t", [0.0, 0.013, 0.4, 2.7])
def test_harmonic_is_amplitude_times_sine_and_its_derivative(t):
    motion = Harmonic((0.02, -0.01, 0.1), 3.0, 0.7)
    w = 2 * math.pi * 3.0
    d, v = motion.at(t)
    np.testing.assert_allclose(d, np.array([0.02, -0.01, 0.1]) * math.sin(w * t + 0.7), rtol=1e-14, atol=1e-17)
    np.testing.assert_allclose(v, np.array([0.02, -0.01, 0.1]) * w * math.cos(w * t + 0.7), rtol=1e-14, atol=1e-15)


@pytest.mark.parametrize("t, d, v", [(-1.0, (0.0, 1.0), (0.0, 0.0)), (0.5, (0.5, 1.5), (1.0, 1.0)),
                                     (1.0, (1.0, 2.0), (-2.0, 0.0)), (1.25, (0.5, 2.0), (-2.0, 0.0)),
                                     (9.0, (0.0, 2.0), (0.0, 0.0))])
def test_a_table_is_linear_between_its_rows_and_held_beyond_them(t, d, v):
    motion = Tabulated([0.0, 1.0, 1.5], [[0.0, 1.0], [1.0, 2.0], [0.0, 2.0]])
    got_d, got_v = motion.at(t)
    np.testing.assert_allclose(got_d, (*d, 0.0), atol=1e-15)
    np.testing.assert_allclose(got_v, (*v, 0.0), atol=1e-15)


def test_a_linear_table_is_bit_for_bit_the_row_plus_slope_times_elapsed_time():
    """The packed piecewise cubic of a linear table (higher coefficients zero) gives exactly
    d_j + ((d_{j+1} − d_j)/(t_{j+1} − t_j)) (t − t_j), as the table's kernel always has."""
    times = [0.0, 0.1, 0.35, 0.4, 1.3]
    rows = [[0.0, 1.0, 0.2], [0.3, -0.7, 0.1], [1.0 / 3.0, 0.25, -2.0], [math.pi, 0.0, 0.0], [0.1, 0.2, 0.3]]
    motion = Tabulated(times, rows)
    for t in np.linspace(-0.2, 1.5, 173):
        j = min(max(int(np.searchsorted(times, t, side="right")) - 1, 0), len(times) - 1)
        d, v = np.array(rows[j], dtype=float), np.zeros(3)
        if 0.0 <= t < times[-1]:
            v = (np.array(rows[j + 1]) - np.array(rows[j])) / (times[j + 1] - times[j])
            d = d + v * (t - times[j])
        got_d, got_v = motion.at(t)
        assert np.array_equal(got_d, d) and np.array_equal(got_v, v), t


def _cubic(t):
    """Three cubic polynomials (x, y, θ) and their derivatives."""
    d = np.array([2.0 * t ** 3 - t ** 2 + 0.5 * t - 1.0, -0.3 * t ** 3 + 4.0 * t, t ** 3 - 3.0 * t ** 2 + 2.0])
    v = np.array([6.0 * t ** 2 - 2.0 * t + 0.5, -0.9 * t ** 2 + 4.0, 3.0 * t ** 2 - 6.0 * t])
    return d, v


def test_a_spline_table_reproduces_a_cubic_and_its_derivative_to_round_off():
    """Not-a-knot ends make the spline through a cubic's samples that cubic (uneven rows too),
    so d and ḋ are the polynomial's to round-off, also through the compiled `evaluate_motions`."""
    times = [0.0, 0.3, 0.45, 1.0, 1.7, 2.0]
    motion = Tabulated(times, [_cubic(t)[0] for t in times], "spline")
    scale = np.max(np.abs([_cubic(t)[0] for t in times])) + np.max(np.abs([_cubic(t)[1] for t in times]))
    for t in np.linspace(0.0, 1.999, 97):
        d, v = motion.at(t)
        np.testing.assert_allclose(d, _cubic(t)[0], rtol=0, atol=1e-13 * scale)
        np.testing.assert_allclose(v, _cubic(t)[1], rtol=0, atol=1e-13 * scale)
    now = np.zeros((1, 12))
    evaluate_motions(0.37, 1.21, *pack_motions([motion]), now)
    for column, t, derivative in ((NOW_START, 0.37, 0), (NOW_START_VELOCITY, 0.37, 1), (NOW_END, 1.21, 0),
                                  (NOW_VELOCITY, 1.21, 1)):
        np.testing.assert_allclose(now[0, column:column + 3], _cubic(t)[derivative], rtol=0, atol=1e-13 * scale)


@pytest.mark.parametrize("t, row", [(-0.5, 0), (0.0, 0), (2.0, -1), (7.0, -1)])
def test_a_spline_table_is_held_at_its_end_rows_like_a_linear_one(t, row):
    times = [0.0, 0.5, 1.0, 2.0]
    positions = [[0.0, 1.0], [0.2, 0.4], [1.0, -1.0], [0.5, 0.5]]
    d, v = Tabulated(times, positions, "spline").at(t)
    assert list(d) == [*positions[row], 0.0]
    if t != 0.0:  # at times[0] the spline's own slope; before and from times[-1] on, at rest
        assert list(v) == [0.0, 0.0, 0.0]


def test_a_ball_on_a_spline_driven_floor_lifts_off_where_the_splines_acceleration_is_minus_g():
    """The floor rises along a not-a-knot spline whose acceleration d'' falls below −g at t*
    (found from the spline's piecewise linear d''). The ball rides it (ḋ its velocity) until t*,
    then flies freely from the floor's (d(t*), ḋ(t*)). A linear table would throw it at a row."""
    g, r, h, t_end = 9.81, 0.05, 1e-4, 0.025
    times = np.array([0.0, 0.01, 0.018, 0.03, 0.04])
    heights = np.array([0.0, 0.0008, 0.001, 0.0002, -0.001])
    spline = CubicSpline(times, heights, bc_type="not-a-knot")
    t_lift = min(spline.derivative(2).solve(-g, extrapolate=False))
    assert spline(0.0, 2) > -g and 0.012 < t_lift < 0.018  # inside a row interval, not at a row
    floor = Line(motion=Tabulated(times, np.c_[0 * times, heights], "spline"))
    scene = Scene([RigidBody(1.0, 0.4 * r * r)], [DiskOnLine(0, (0.0, 0.0), floor, r, ContactLaw(), name="floor")],
                  gravity=g)
    result = nr.simulate(scene, [0.0, r, 0.0], [0.0, float(spline(0.0, 1)), 0.0], t_end, h=h)
    assert [e.kind for e in result.events] == ["liftoff"]
    assert result.events[0].t == pytest.approx(t_lift, abs=2 * h)
    tr = result.trajectory
    riding = tr.t < t_lift - h
    jerk, acceleration = np.max(np.abs(spline(times, 3))), np.max(np.abs(spline(times, 2)))
    # riding: the step's end velocity is the floor's; the gap the θ-method's quadrature error (≤ h² max|d''|/6)
    assert np.max(np.abs(tr.v[riding, 1] - spline(tr.t[riding], 1))) < 1e-12
    assert np.max(np.abs(tr.q[riding, 1] - r - spline(tr.t[riding]))) <= h * h * acceleration / 6 + 1e-15
    # flying: a lift-off step late by < h leaves at a velocity off by < h · |d'' + g| < h² max|d'''|
    tau = t_end - t_lift
    assert tr.v[-1, 1] == pytest.approx(spline(t_lift, 1) - g * tau, abs=h * h * jerk)
    assert tr.q[-1, 1] == pytest.approx(r + spline(t_lift) + spline(t_lift, 1) * tau - g / 2 * tau * tau,
                                        abs=h * h * (jerk * tau + acceleration / 6))


def test_a_driven_line_moves_the_gap_and_the_relative_velocity():
    """A floor at y = A sin(ωt) under a disk at rest: gap y − r − A sin ωt, u_N = −A ω cos ωt."""
    line = Line(motion=Harmonic((0.3, 0.2), 1.0))
    contact = DiskOnLine(0, (0.0, 0.0), line, 0.1)
    t = 0.1
    kin = contact.kinematics(np.array([0.0, 1.0, 0.0]), np.zeros(3), 3, t)
    s, c = math.sin(2 * math.pi * t), 2 * math.pi * math.cos(2 * math.pi * t)
    assert kin.gap == pytest.approx(1.0 - 0.1 - 0.2 * s, rel=1e-15)
    assert kin.normal_velocity == pytest.approx(0.2 * c, rel=1e-15)
    assert kin.surface_velocity == pytest.approx(0.3 * c, rel=1e-15)  # the floor's slip under the disk
    assert contact.kinematics(np.array([0.0, 1.0, 0.0]), np.zeros(3), 3).gap == pytest.approx(0.9)  # at rest


def test_driven_bodies_have_infinite_mass_in_the_packed_scene():
    scene = Scene([RigidBody(1.0, 1.0), RigidBody(2.0, 3.0)], driven=[DrivenBody(1, Harmonic((0.0, 1.0), 1.0))])
    assert list(pack_scene(scene).minv) == [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]
    assert list(scene.inverse_mass_diagonal[3:]) == [0.5, 0.5, 1 / 3]  # the scene's own masses stay


@pytest.mark.parametrize("build, message", [
    (lambda: Tabulated([0.0, 0.0], [[0, 0], [1, 1]]), "motion times must increase strictly"),
    (lambda: Tabulated([0.0, math.inf], [[0, 0], [1, 1]]), "motion times[1] must be finite"),
    (lambda: Tabulated([0.0, 1.0], [[0, 0]]), "one row per time (2), got 1"),
    (lambda: Tabulated([0.0, 1.0], [[0, 0], [1, 1, 0]]), "positions[1] must have 2 numbers"),
    (lambda: Tabulated([], []), "at least one time"),
    (lambda: Tabulated([0.0, 1.0], [[0, 0], [1, 1]], "cubic"), "motion interpolation must be one of linear, spline"),
    (lambda: Tabulated([0.0, 1.0, 2.0], [[0, 0], [1, 1], [0, 2]], "spline"),
     "a spline motion table needs at least 4 rows (not-a-knot cubic), got 3"),
    (lambda: Tabulated([0.0, 1e-300], [[0, -1e300], [0, 1e300]]), "the table's linear slopes overflow"),
    (lambda: Tabulated([0.0, 1e-100, 2e-100, 3e-100], [[0, 0], [0, 1e200], [0, -1e200], [0, 0]], "spline"),
     "the table's spline slopes overflow"),
    (lambda: Harmonic((0.0, math.nan), 1.0), "motion amplitude[1] must be finite"),
    (lambda: Harmonic((0.0,), 1.0), "motion amplitude must have 2 or 3 numbers"),
    (lambda: Harmonic((0.0, 1.0), -1.0), "motion frequency_hz must be non-negative"),
    (lambda: Harmonic((0.0, 1e300), 1e10), "the motion's acceleration is not finite"),
    (lambda: Line(motion=Harmonic((0.0, 1.0, 0.5), 1.0)), "line motion: a line or segment translates"),
    (lambda: Segment((0, 0), (1, 0), motion="shake"), "segment 'segment' motion must be a Harmonic"),
    (lambda: Prescribed(3.0), "needs a callable"),
    (lambda: Prescribed(lambda t: ((0.0, math.nan), (0.0, 0.0))).at(0.5), "must return 2 finite numbers"),
    (lambda: Scene([RigidBody(1.0, 1.0)], driven=[DrivenBody(1, Harmonic((0, 1), 1))]), "beyond the scene's 1"),
    (lambda: pack_scene(Scene([RigidBody(1.0, 1.0)], [DiskOnSegment(0, (0, 0), Segment((0, 0), (1, 0)), 0.1)],
                              driven=[DrivenBody(0, Harmonic((0, 1), 1))])), "every body it touches is driven"),
])
def test_bad_motions_are_one_line(build, message):
    with pytest.raises(InputError) as err:
        build()
    assert message in str(err.value) and "\n" not in str(err.value)
