"""Driven obstacles against closed forms: Housner's block on a floor shaken horizontally, a ball
on a plate shaken vertically (a driven line, and a driven body)."""
import math

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod import toys
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import DiskOnDisk
from nonsmooth_rod.model.motion import DrivenBody, Harmonic, Prescribed, Tabulated
from nonsmooth_rod.model.scene import Scene

H = 1e-4
ROUNDOFF = 1e-10  # the closed forms below hold to round-off of quantities of order 1


def _relative_motion(block, result):
    tr = result.trajectory
    floor_x = block.amplitude * np.sin(block.omega * tr.t)
    floor_v = block.amplitude * block.omega * np.cos(block.omega * tr.t)
    return tr.q[:, 0] - floor_x - (tr.q[0, 0] - floor_x[0]), tr.v[:, 0] - floor_v


def test_a_block_below_both_thresholds_moves_with_the_floor():
    block = toys.ShakenBlock(mu_s=0.5)  # b/c = 1/3: peak 3.16 m/s² < g b/c = 3.27 < μs g = 4.9
    assert block.first_motion == "hold"
    result = toys.run(block, "moreau-jean", 0.5, h=H)
    displacement, velocity = _relative_motion(block, result)
    assert np.max(np.abs(result.trajectory.q[:, 2])) < ROUNDOFF
    assert np.max(np.abs(velocity)) < ROUNDOFF  # sticks: the floor's velocity at every step's end
    assert not [e for e in result.events if e.kind in ("stick-slip", "liftoff")]
    # The block's position is the θ-method's (trapezoid) quadrature of the floor's velocity, whose
    # error is (h²/12)(a(t) − a(0)) in closed form: what is left is round-off.
    trapezoid = H * H / 12 * (block.floor_acceleration(result.t) - block.floor_acceleration(0.0))
    assert np.max(np.abs(displacement - trapezoid)) < ROUNDOFF


@pytest.mark.parametrize("kwargs, motion, kind", [
    (dict(mu_s=0.2), "slide", ("stick-slip",)),  # μs = 0.2 < b/c = 1/3
    (dict(half_width=0.05, half_height=0.25, mu_s=0.8), "rock", ("liftoff",)),  # b/c = 0.2 < μs
])
def test_the_block_slides_or_rocks_first_when_the_floor_accelerates_past_its_threshold(kwargs, motion, kind):
    block = toys.ShakenBlock(**kwargs)
    assert block.first_motion == motion
    result = toys.run(block, "moreau-jean", 0.08, h=H)
    first = min((e for e in result.events if e.kind in ("stick-slip", "liftoff")), key=lambda e: e.t)
    assert first.kind in kind
    assert first.t == pytest.approx(block.onset_time, abs=2 * H)
    tilt = np.max(np.abs(result.trajectory.q[:, 2]))
    assert (tilt > 1e-4) if motion == "rock" else (tilt < ROUNDOFF)


@pytest.mark.parametrize("amplitude, lifts", [(0.003, False), (0.01, True)])
def test_a_ball_on_a_vertically_shaken_plate_lifts_off_where_the_plate_accelerates_at_minus_g(amplitude, lifts):
    plate = toys.BallOnShakenPlate(amplitude=amplitude)  # A ω² = 7.6 and 25.3 m/s² against g
    result = toys.run(plate, "moreau-jean", 0.05, h=H)
    liftoffs = [e.t for e in result.events if e.kind == "liftoff"]
    if not lifts:
        assert plate.liftoff_time is None and not liftoffs
        tr = result.trajectory
        gap = tr.q[:, 1] - plate.radius - amplitude * np.sin(plate.omega * tr.t)
        # it rides the plate: its gap is at most the θ-method's (trapezoid) quadrature error of the
        # plate's motion, (h²/12) |a(t) − a(0)| ≤ h² A ω²/6 (a gap that opens is closed next step)
        assert np.max(np.abs(gap)) <= H * H * amplitude * plate.omega ** 2 / 6 + 1e-12
        assert np.all(tr.normal_force[1:, 0] > 0.0)
    else:
        assert liftoffs[0] == pytest.approx(plate.liftoff_time, abs=2 * H)


def _ball_on_driven_disk(motion):
    """A ball (r = 0.05) on top of a heavy disk (R = 0.2) that a motion drives: a driven body."""
    bodies = [RigidBody(1.0, 1e-3, "ball"), RigidBody(5.0, 0.1, "shaker")]
    contact = DiskOnDisk(0, 1, 0.05, 0.2, name="top")
    return Scene(bodies, [contact], driven=[DrivenBody(1, motion)])


def test_a_ball_on_a_driven_body_lifts_off_at_the_same_closed_form():
    plate = toys.BallOnShakenPlate(amplitude=0.01)
    w = plate.omega
    scene = _ball_on_driven_disk(Harmonic((0.0, plate.amplitude), plate.frequency_hz))
    q0, v0 = np.array([0.0, 0.25, 0.0, 0.0, 0.0, 0.0]), np.array([0.0, plate.amplitude * w, 0, 0, 0, 0])
    result = nr.simulate(scene, q0, v0, 0.02, h=H)
    tr = result.trajectory
    # the driven body follows its motion exactly, whatever the ball's weight on it
    assert np.max(np.abs(tr.q[:, 4] - plate.amplitude * np.sin(w * tr.t))) < ROUNDOFF
    assert np.max(np.abs(tr.v[:, 4] - plate.amplitude * w * np.cos(w * tr.t))) < ROUNDOFF
    liftoff = [e.t for e in result.events if e.kind == "liftoff"][0]
    assert liftoff == pytest.approx(plate.liftoff_time, abs=2 * H)


def test_tabulated_and_python_motions_drive_like_the_harmonic_one():
    """The same floor motion three ways: a dense table and a Python callable give the harmonic
    run's lift-off (the table to its interpolation error, the callable exactly)."""
    plate = toys.BallOnShakenPlate(amplitude=0.01)
    A, w = plate.amplitude, plate.omega
    times = np.linspace(0.0, 0.02, 2001)
    motions = {"table": Tabulated(times, np.c_[0 * times, A * np.sin(w * times)]),
               "python": Prescribed(lambda t: ((0.0, A * math.sin(w * t)), (0.0, A * w * math.cos(w * t))))}
    reference = nr.simulate(_ball_on_driven_disk(Harmonic((0.0, A), plate.frequency_hz)),
                            [0, 0.25, 0, 0, 0, 0], [0, A * w, 0, 0, 0, 0], 0.02, h=H)
    for name, motion in motions.items():
        result = nr.simulate(_ball_on_driven_disk(motion), [0, 0.25, 0, 0, 0, 0], [0, A * w, 0, 0, 0, 0], 0.02, h=H)
        error = np.max(np.abs(result.trajectory.q - reference.trajectory.q))
        assert error < (1e-6 if name == "table" else ROUNDOFF), (name, error)


@pytest.mark.parametrize("solver", ["pgs", "enum", "clarabel"])
def test_every_solver_sees_the_moving_plate(solver):
    plate = toys.BallOnShakenPlate(amplitude=0.01)
    result = toys.run(plate, "moreau-jean", 0.012, h=H, solver=solver)
    assert [e.t for e in result.events if e.kind == "liftoff"][0] == pytest.approx(plate.liftoff_time, abs=2 * H)


def test_a_driven_run_restarts_bit_for_bit():
    """run(0 → T) and run(0 → T/2) + restart(T/2 → T) agree exactly: the motions are functions of
    the step's time, and a driven body's origin q0 − d(t0) is the same from either start."""
    plate = toys.BallOnShakenPlate(amplitude=0.01)
    scene = _ball_on_driven_disk(Harmonic((0.0, plate.amplitude), plate.frequency_hz))
    q0, v0 = [0.0, 0.25, 0.0, 0.0, 0.0, 0.0], [0.0, plate.amplitude * plate.omega, 0, 0, 0, 0]
    full = nr.simulate(scene, q0, v0, 0.02, h=H)
    half = nr.simulate(scene, q0, v0, 0.01, h=H)
    rest = nr.simulate(scene, half.end_state.q[-1], half.end_state.v[-1], 0.02, h=H, t0=0.01, resume=half.end_state)
    assert np.array_equal(rest.trajectory.q[-1], full.trajectory.q[-1])
    assert np.array_equal(rest.trajectory.v[-1], full.trajectory.v[-1])
