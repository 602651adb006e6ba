"""Disk–disk contact: two-ball collisions against the closed form of Newton's law, an oblique
collision, and what Moreau's simultaneous impact law gives for a three-ball Newton's cradle."""
import math

import numpy as np
import pytest

from nonsmooth_rod import toys
from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import DiskOnDisk
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.model.scene import Scene
from nonsmooth_rod.validation import InputError


@pytest.mark.parametrize("e", [1.0, 0.5, 0.0])
def test_two_ball_central_collision(e):
    row = toys.BallRow(masses=(1.0, 3.0), radii=(0.05, 0.08), gaps=(0.1,), velocities=(2.0, -0.5), restitution=e)
    h = 1e-3
    run = toys.run(row, "moreau-jean", 0.2, h=h)
    assert run.status == "ok", run.message
    # gravity-free straight motion: one impact step gives the closed form to round-off
    np.testing.assert_allclose(toys.ball_velocities(run), row.two_ball_outcome(), atol=1e-12)
    assert len(run.impacts) == 1
    assert run.impacts[0].t == pytest.approx(row.first_impact_time(), abs=1e-12)
    v_before, v_after = np.array(row.velocities), toys.ball_velocities(run)
    m = np.array(row.masses)
    assert m @ v_after == pytest.approx(m @ v_before, abs=1e-12)
    ke_ratio = (m @ v_after**2) / (m @ v_before**2)
    reduced = m[0] * m[1] / m.sum()
    lost = 0.5 * reduced * (1 - e * e) * (v_before[0] - v_before[1]) ** 2
    assert 0.5 * m @ v_before**2 - 0.5 * m @ v_after**2 == pytest.approx(lost, abs=1e-12)
    assert ke_ratio <= 1 + 1e-12
    # penetration bound of the activation rule: (2 − e) h |u⁻| / 2 (measured equal for e < 1)
    gap = run.trajectory.q[:, 3] - run.trajectory.q[:, 0] - sum(row.radii)
    assert gap.min() >= -(2 - e) * h * 2.5 / 2 - 1e-12


def _oblique_scene(restitution=1.0, radius=0.05):
    law = ContactLaw.of(0.0, 0.0, restitution)
    balls = [RigidBody(1.0, 0.4 * radius**2, name="striker"), RigidBody(1.0, 0.4 * radius**2, name="target")]
    return Scene(balls, [DiskOnDisk(1, 0, radius, radius, law=law, name="hit")], gravity=0.0)


@pytest.mark.parametrize("aligned", [True, False])
def test_oblique_collision_of_equal_balls(aligned):
    """Striker at 1 m/s along x, target offset by half the sum of radii: the line of centres
    is at φ = 30°. With e = 1 the target leaves along it at v cos φ, the striker at v sin φ
    perpendicular to it."""
    h, radius, offset = 1e-3, 0.05, 0.05
    phi = math.asin(offset / (2 * radius))
    along = math.sqrt((2 * radius) ** 2 - offset**2)
    # aligned: the balls touch exactly at t = 0.2 s, a step boundary
    start = 0.3 - along - 0.2 if aligned else 0.0
    q0 = np.array([start, 0.0, 0.0, 0.3, offset, 0.0])
    v0 = np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    run = MoreauJean(MoreauJeanOptions(h=h)).run(_oblique_scene(), q0, v0, 0.4)
    v = run.trajectory.v[-1]
    n = np.array([math.cos(phi), math.sin(phi)])
    target = math.cos(phi) * n
    striker = np.array([1.0, 0.0]) - target
    assert 0.5 * v @ v == pytest.approx(0.5, abs=1e-12)  # e = 1, frictionless: energy kept
    np.testing.assert_allclose(v[[0, 1]] + v[[3, 4]], [1.0, 0.0], atol=1e-12)  # momentum
    error = np.abs(np.concatenate([v[[0, 1]] - striker, v[[3, 4]] - target])).max()
    if aligned:
        assert error < 1e-9
    else:
        # The impulse acts along the normal of the step's start, when the balls may already
        # overlap by up to h |u_N| / 2: the normal is turned by at most ~h |v| / (2 r); measured
        # 2.0e-3 (0.2 h |v| / r) at h = 1e-3.
        assert 1e-6 < error < h * 1.0 / (2 * radius)


def test_disk_on_disk_drift_is_the_second_derivative_of_the_gap():
    """Ḣ_N v by central differences along a force-free motion (a = 0): g̈ = Ḣ_N v."""
    c = DiskOnDisk(1, 0, 0.05, 0.08, offset_a=(0.02, -0.01), offset_b=(-0.03, 0.04))
    rng = np.random.default_rng(1)
    q = np.array([0.0, 0.0, 0.3, 0.15, 0.05, -0.7])
    v = rng.normal(size=6)
    dt = 1e-5
    k0, kp, km = (c.kinematics(q + s * dt * v, v, 6) for s in (0.0, 1.0, -1.0))
    assert (kp.H_N @ v - km.H_N @ v) / (2 * dt) == pytest.approx(k0.drift_N, rel=1e-6)
    assert (kp.gap - 2 * k0.gap + km.gap) / dt**2 == pytest.approx(k0.drift_N, rel=1e-3)
    assert abs(k0.drift_N) > 1e-2  # a real test: the turning normal and spins contribute


def test_disk_on_disk_rejects_bad_input():
    with pytest.raises(InputError, match="two different bodies"):
        DiskOnDisk(0, 0, 0.1, 0.1)
    with pytest.raises(InputError, match="radius_a"):
        DiskOnDisk(0, 1, -0.1, 0.1)


# ------------------------------------------------------------------------- Newton's cradle
def test_cradle_simultaneous_moreau_impact_is_not_the_experiment():
    """Touching balls: both contacts are in one step's impact problem and Moreau's law gives
    (−1/3, 2/3, 2/3) v — energy and momentum kept — where a real cradle shows (0, 0, v). A known
    limit of simultaneous impact laws: they cannot propagate the impact through the chain."""
    cradle = toys.BallRow.cradle(3, speed=1.0, gap=0.0, restitution=1.0)
    run = toys.run(cradle, "moreau-jean", 0.2, h=1e-3)
    after = toys.ball_velocities(run)
    np.testing.assert_allclose(after, [-1 / 3, 2 / 3, 2 / 3], atol=1e-12)
    np.testing.assert_allclose(after, cradle.simultaneous_outcome(), atol=1e-12)
    assert np.sum(after) == pytest.approx(1.0, abs=1e-12)
    assert np.sum(after**2) == pytest.approx(1.0, abs=1e-12)
    assert np.max(np.abs(after - [0.0, 0.0, 1.0])) > 0.3  # not the experimental outcome


def test_cradle_with_gaps_gives_sequential_impacts():
    """Gaps of 1 cm (> h |v| = 1 mm): two separate two-ball impacts, which swap velocities."""
    cradle = toys.BallRow.cradle(3, speed=1.0, gap=0.01, restitution=1.0)
    run = toys.run(cradle, "moreau-jean", 0.2, h=1e-3)
    np.testing.assert_allclose(toys.ball_velocities(run), cradle.sequential_outcome(), atol=1e-12)
    assert [imp.contact for imp in run.impacts] == ["0-1", "1-2"]


def test_cradle_simultaneous_outcome_with_restitution():
    cradle = toys.BallRow.cradle(3, speed=2.0, gap=0.0, restitution=0.5)
    run = toys.run(cradle, "moreau-jean", 0.2, h=1e-3)
    np.testing.assert_allclose(toys.ball_velocities(run), [0.0, 1.0, 1.0], atol=1e-12)  # ((1−2e), (1+e), (1+e))/3 · v
