"""Bilateral joints in the Moreau–Jean step (integrators/joint_step.py, docs/joints.md), against
closed forms: a rod pinned to the world swinging into a wall, its pin reaction, a double
pendulum's energy and drift, a block on an inclined slider, a redundant pin, every solver."""
import math

import numpy as np
import pytest

import nonsmooth_rod as nr

M, L, G = 1.0, 1.0, 9.81
I_PIVOT = M * L * L / 3  # the rod about its end
ARM = L / 2  # pivot to centre of mass


def pinned_rod(restitution=0.5, wall=True):
    """A uniform rod pinned at its end (body point (−L/2, 0)) to the world origin, horizontal at
    θ = 0; its free end (L/2, 0) strikes the vertical wall x = 0 (normal +x) at the bottom, θ = −π/2."""
    contacts = []
    if wall:
        contacts = [nr.PointOnLine(0, (L / 2, 0.0), nr.Line((0.0, 0.0), -math.pi / 2),
                                   nr.ContactLaw.of(0.0, 0.0, restitution), name="wall")]
    return nr.Scene([nr.RigidBody(M, M * L * L / 12, name="rod")], contacts, gravity=G,
                    joints=[nr.Pin(0, (-L / 2, 0.0), None, (0.0, 0.0), name="pivot")])


def released(scene, t_end, **options):
    return nr.simulate(scene, [L / 2, 0.0, 0.0], [0.0, 0.0, 0.0], t_end, **options)


def rebound_angle(restitution):
    """Released horizontal: ½ I ω² = m g l at the bottom; after ω⁺ = −e ω⁻ it rises by φ with
    m g l (1 − cos φ) = e² m g l."""
    return math.acos(1.0 - restitution ** 2)


def test_pin_reaction_during_the_swing_is_the_closed_form():
    """About a fixed pivot: θ̇² = 2 m g l (−sin θ)/I, θ̈ = −m g l cos θ / I; the pin's force on the
    rod is m a_G + m g ŷ with a_G = l θ̈ t̂ − l θ̇² r̂ (r̂ from the pivot to the centre)."""
    h = 2e-4
    res = released(pinned_rod(wall=False), 0.5, h=h)  # past the bottom (t = 0.4833 s)
    theta = res.q[1:, 2]
    rate2 = 2 * M * G * ARM * -np.sin(theta) / I_PIVOT
    accel = -M * G * ARM * np.cos(theta) / I_PIVOT
    r_hat, t_hat = np.stack([np.cos(theta), np.sin(theta)]), np.stack([-np.sin(theta), np.cos(theta)])
    force = M * (ARM * accel * t_hat - ARM * rate2 * r_hat) + np.array([[0.0], [M * G]])
    got = np.stack([res.joint_forces["pivot"]["Fx"][1:], res.joint_forces["pivot"]["Fy"][1:]])
    # each sample is the step's mean force and the step's speed lags O(h): a first-order scheme
    scale = M * G * 3.0
    assert np.max(np.abs(got - force)) < 5e-3 * scale
    radial = np.sum(got * r_hat, axis=0)  # at the bottom: m l θ̇² + m g = 2.5 m g for a rod
    assert radial[np.argmin(np.abs(theta + math.pi / 2))] == pytest.approx(-2.5 * M * G, rel=2e-3)


@pytest.mark.parametrize("solver", ["lemke", "pgs", "enum"])
def test_rod_striking_the_wall_rebounds_with_e_times_its_speed(solver):
    e = 0.5
    res = released(pinned_rod(e), 0.9, h=5e-4, solver=solver)
    assert res.status == "ok"
    (impact,) = res.impacts
    assert impact.contact == "wall"
    assert impact.v_after[2] / impact.v_before[2] == pytest.approx(-e, abs=1e-5)
    assert abs(impact.q[2] + math.pi / 2) < 5e-4 * 5.5  # struck at the bottom (within a step's turn)
    # the pin holds through the impact: the rod's centre stays at its arm from the pivot
    np.testing.assert_allclose(np.hypot(res.q[:, 0], res.q[:, 1]), ARM, atol=1e-14)


def rebound_angle_reached(h, e=0.5):
    """The highest angle from the vertical the rod reaches after the impact (the rebound's peak is
    near t = 0.9 s: the swing back takes a quarter of its period, ~0.42 s)."""
    res = released(pinned_rod(e), 1.2, h=h)
    k = np.searchsorted(res.t, res.impacts[0].t)
    assert res.t[-1] - res.t[k + np.argmax(res.q[k:, 2])] > 0.1  # the peak is inside the run
    return np.max(res.q[k:, 2]) + math.pi / 2


def test_rebound_angle_converges_to_the_closed_form_at_first_order():
    """Moreau–Jean with the joint rows at q_k is first order in energy (docs/joints.md): the
    rebound angle's error halves with h (measured 0.43 h relative, from h = 1e-3 to 1.25e-5), and
    Richardson's extrapolation of two steps meets acos(1 − e²) to 1e-6."""
    exact = rebound_angle(0.5)
    coarse, fine = rebound_angle_reached(1e-4), rebound_angle_reached(5e-5)
    assert (coarse - exact) / (fine - exact) == pytest.approx(2.0, rel=0.05)
    assert abs(fine / exact - 1.0) < 3e-5
    assert abs((2.0 * fine - coarse) / exact - 1.0) < 1e-6


def double_pendulum():
    """Two uniform rods, the first pinned to the world at its end, the second to its free end."""
    rods = [nr.RigidBody(M, M * L * L / 12, name=f"rod{i}") for i in (1, 2)]
    joints = [nr.Pin(0, (-L / 2, 0.0), None, (0.0, 0.0), name="shoulder"),
              nr.Pin(1, (-L / 2, 0.0), 0, (L / 2, 0.0), name="elbow")]
    q0 = np.array([L / 2, 0.0, 0.0, 1.5 * L, 0.0, 0.0])  # both horizontal: chaotic from here
    return nr.Scene(rods, gravity=G, joints=joints), q0


def joint_drift(res, scene):
    from nonsmooth_rod.model.joints import joint_violation

    return max(np.max(np.abs(joint_violation(scene.joints, 2, q))) for q in res.q)


def energy(scene, res):
    return np.array([scene.energy(q, v) for q, v in zip(res.q, res.v)])


def test_double_pendulum_keeps_its_joints_at_round_off_and_loses_energy_at_first_order():
    scene, q0 = double_pendulum()
    losses = []
    for h in (2e-4, 1e-4):
        res = nr.simulate(scene, q0, np.zeros(6), 0.5, h=h)
        assert joint_drift(res, scene) < 1e-14
        e = energy(scene, res)
        assert np.all(np.diff(e) < 1e-9 * M * G * L)  # dissipative: the projection removes, never adds
        losses.append(e[0] - e[-1])
    assert 0.0 < losses[1] < 2e-3 * M * G * L
    assert losses[0] / losses[1] == pytest.approx(2.0, rel=0.2)


def test_redundant_pins_share_the_load_and_move_as_one_pin():
    single = released(pinned_rod(wall=False), 0.3, h=1e-3)
    scene = pinned_rod(wall=False)
    scene.joints = scene.joints + [nr.Pin(0, (-L / 2, 0.0), None, (0.0, 0.0), name="again")]
    double = released(scene, 0.3, h=1e-3)
    assert double.status == "ok" and np.all(np.isfinite(double.q))
    np.testing.assert_allclose(double.q, single.q, atol=1e-12)
    for what in ("Fx", "Fy"):
        total = double.joint_forces["pivot"][what] + double.joint_forces["again"][what]
        np.testing.assert_allclose(total, single.joint_forces["pivot"][what], atol=1e-9)
        np.testing.assert_allclose(double.joint_forces["pivot"][what], double.joint_forces["again"][what],
                                   atol=1e-9)


def test_block_on_an_inclined_world_slider_accelerates_at_g_sin_alpha():
    """A slider along a world direction at angle α: s(t) = ½ g sin α t², the normal reaction
    m g cos α, the torque 0 and the angle held."""
    alpha = math.radians(30.0)
    axis = (math.cos(alpha), -math.sin(alpha))
    scene = nr.Scene([nr.RigidBody(2.0, 0.1)], gravity=G,
                     joints=[nr.Slider(0, (0.0, 0.0), None, (0.0, 0.0), axis=axis, angle=0.0, name="rail")])
    res = nr.simulate(scene, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 1.0, h=1e-3)
    s = res.q[:, 0] * axis[0] + res.q[:, 1] * axis[1]
    np.testing.assert_allclose(s, 0.5 * G * math.sin(alpha) * res.t ** 2, atol=1e-12)
    np.testing.assert_allclose(res.q[:, 0] * -axis[1] + res.q[:, 1] * axis[0], 0.0, atol=1e-14)
    np.testing.assert_allclose(res.joint_forces["rail"]["F"][1:], 2.0 * G * math.cos(alpha), rtol=1e-12)
    np.testing.assert_allclose(res.joint_forces["rail"]["M"][1:], 0.0, atol=1e-12)
    assert np.all(res.q[:, 2] == 0.0)


def test_bead_on_a_spinning_rod_keeps_angular_momentum_and_energy():
    """A free rod spinning about its pinned centre, a bead (body_a) on a slider along the rod
    (body_b's axis), no gravity: angular momentum and energy kept to O(h)."""
    rod, bead = nr.RigidBody(1.0, 0.1), nr.RigidBody(0.2, 1e-3)
    scene = nr.Scene([bead, rod], gravity=0.0, joints=[
        nr.Pin(1, (0.0, 0.0), None, (0.0, 0.0), name="hub"),
        nr.Slider(0, (0.0, 0.0), 1, (0.0, 0.0), axis=(1.0, 0.0), name="bead-on-rod")])
    q0, v0 = np.array([0.1, 0.0, 0.0, 0.0, 0.0, 0.0]), np.array([0.0, 0.3, 3.0, 0.0, 0.0, 3.0])
    res = nr.simulate(scene, q0, v0, 0.5, h=1e-4)
    x, y, vx, vy = res.q[:, 0], res.q[:, 1], res.v[:, 0], res.v[:, 1]
    momentum = 0.2 * (x * vy - y * vx) + 1e-3 * res.v[:, 2] + 0.1 * res.v[:, 5]
    # the joints' impulses have no moment about the hub at q_k; the θ-method's position update
    # changes x × v by ½ h² v_k × v_{k+1} a step: O(h) over the run (8.6e-6 measured)
    np.testing.assert_allclose(momentum, momentum[0], rtol=3e-5)
    kinetic = np.array([scene.kinetic_energy(v) for v in res.v])
    assert abs(kinetic[-1] / kinetic[0] - 1.0) < 1e-2
    assert np.hypot(x[-1], y[-1]) > 0.2  # the bead has slid out along the rod (from 0.1 m)


def test_methods_without_joints_refuse_them_in_one_line():
    for method in ("event-driven", "regularized"):
        with pytest.raises(nr.InputError, match=f"method '{method}' does not handle joints \\(joint 'pivot'\\)"):
            released(pinned_rod(), 0.1, method=method)


def test_a_qp_backend_solves_the_jointed_step_too():
    from nonsmooth_rod.solvers import available_solvers

    qp = [s for s in available_solvers() if s not in ("lemke", "pgs", "enum")]
    if not qp:
        pytest.skip("no QP backend installed")
    res = released(pinned_rod(0.5), 0.6, h=2e-3, solver=qp[0], fast=False)  # interpreted: no compile
    assert res.status == "ok"
    (impact,) = res.impacts
    assert impact.v_after[2] / impact.v_before[2] == pytest.approx(-0.5, abs=1e-4)


def pin_force_about_a_fixed_pivot(theta, mass=M, length=L, g=G):
    """The force (x, y) a fixed pivot applies to a uniform rod released at rest horizontal, at its
    angle θ (from +x, the rod swinging down: θ ≤ 0)."""
    arm, inertia = length / 2, mass * length ** 2 / 3
    rate2 = 2 * mass * g * arm * -np.sin(theta) / inertia
    accel = -mass * g * arm * np.cos(theta) / inertia
    ax = arm * (accel * -np.sin(theta) - rate2 * np.cos(theta))
    ay = arm * (accel * np.cos(theta) - rate2 * np.sin(theta))
    return mass * ax, mass * ay + mass * g


def test_pendulum_on_a_cart_holds_the_cart_until_friction_cannot_and_slips_at_the_closed_form_angle():
    """A cart on two frictional feet carries a rod pinned at its centre, released horizontal. While
    the cart sticks the rod swings about a fixed pivot, whose force R on the rod the cart feels as
    −R: the feet hold while |R_x| ≤ μs (M_cart g + R_y), and slip at the first angle where equality
    holds (brentq on the closed form)."""
    from scipy.optimize import brentq

    cart_mass, mu_s = 5.0, 0.05
    def friction_needed(theta):  # |T| / N the feet must supply to hold the cart
        fx, fy = pin_force_about_a_fixed_pivot(theta)
        return abs(fx) / (cart_mass * G + fy)

    theta_slip = brentq(lambda th: friction_needed(th) - mu_s, -0.6, -1e-3)
    law = nr.ContactLaw.of(mu_s, mu_s, 0.0)
    floor = nr.Line((0.0, 0.0), 0.0)
    half_width, half_height = 0.4, 0.1
    cart = nr.RigidBody(cart_mass, cart_mass * (4 * half_width ** 2 + 4 * half_height ** 2) / 12, name="cart")
    feet = [nr.PointOnLine(1, (side * half_width, -half_height), floor, law, name=f"foot{i}")
            for i, side in enumerate((-1, 1))]
    scene = nr.Scene([nr.RigidBody(M, M * L * L / 12, name="rod"), cart], feet, gravity=G,
                     joints=[nr.Pin(0, (-L / 2, 0.0), 1, (0.0, 0.0), name="hinge")])
    q0 = np.array([L / 2, half_height, 0.0, 0.0, half_height, 0.0])
    h = 1e-4
    res = nr.simulate(scene, q0, np.zeros(6), 0.35, h=h)
    assert res.status == "ok"
    moving = np.flatnonzero(np.abs(res.v[:, 3]) > 1e-9)
    k = moving[0]
    theta_at_slip = np.interp(res.t[k - 1], res.t, res.q[:, 2])
    assert np.max(np.abs(res.q[:k, 3])) < 1e-12  # the cart held until then
    # within the step's turn (ω h ≈ 1.9e-4 rad) and the O(h) lag of the step's mean force (measured
    # 1.4e-4 rad at h = 1e-4)
    assert theta_at_slip == pytest.approx(theta_slip, abs=5e-4)
    assert res.phases["foot0"][0].mode == "stick" and res.phases["foot0"][1].mode.startswith("slip")
