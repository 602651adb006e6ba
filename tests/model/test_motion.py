"""Prescribed motions: the kernel's displacement and velocity against their closed forms, a
driven obstacle's contact kinematics, and one-line refusals of bad motions."""
import math

import numpy as np
import pytest

from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import DiskOnLine, DiskOnSegment, Line, Segment
from nonsmooth_rod.model.motion import DrivenBody, Harmonic, Prescribed, Tabulated
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
