"""solvers.one_contact: the closed form of one contact's problem is Lemke's answer, on random
problems and on the shipped scenes' one-contact steps, and it declines where the answer may not be unique."""
from __future__ import annotations

import numpy as np
import pytest

from nonsmooth_rod.solvers.kernel_base import contact_residual
from nonsmooth_rod.solvers.lemke import lemke_friction
from nonsmooth_rod.solvers.one_contact import one_contact_impulse
from nonsmooth_rod.solvers.problem import PlanarFrictionProblem


def _interpreted(function):
    return getattr(function, "py_func", function)


def _random_problem(rng):
    """A one-contact problem as a step makes it: W = J M⁻¹ Jᵀ of a random planar body's contact
    (normal and tangent rows), q of any sign, an interval of a slip guess (lo ≤ hi)."""
    minv = np.diag([1.0 / rng.uniform(0.1, 10.0)] * 2 + [1.0 / rng.uniform(0.01, 1.0)])
    angle, lever = rng.uniform(0, 2 * np.pi), rng.uniform(0.0, 1.0) * rng.uniform(-1, 1, 2)
    n, t = np.array([np.cos(angle), np.sin(angle)]), np.array([-np.sin(angle), np.cos(angle)])
    cross = lambda d: lever[0] * d[1] - lever[1] * d[0]  # noqa: E731
    J = np.array([[*n, cross(n)], [*t, cross(t)]])
    W = J @ minv @ J.T
    q = rng.normal(size=2) * 10.0 ** rng.uniform(-3, 1)
    mu_s = rng.uniform(0.0, 1.5)
    mu_d = rng.uniform(0.0, mu_s)
    shift = (mu_s - mu_d) * rng.choice([-1.0, 0.0, 1.0])
    return W, q, shift - mu_s, shift + mu_s


@pytest.mark.parametrize("compiled", [True, False])
def test_random_problems_get_lemkes_answer(compiled):
    solve = one_contact_impulse if compiled else _interpreted(one_contact_impulse)
    rng = np.random.default_rng(25)
    taken, modes = 0, set()
    for _ in range(2000):
        W, q, lo, hi = _random_problem(rng)
        found, p_n, p_t = solve(W[0, 0], W[0, 1], W[1, 0], W[1, 1], q[0], q[1], lo, hi)
        if not found:
            continue
        taken += 1
        reference = lemke_friction(PlanarFrictionProblem(W, q, np.array([lo]), np.array([hi])))
        p = np.array([p_n, p_t])
        scale = max(np.max(np.abs(q)), np.max(np.abs(reference.p)), 1e-300)
        np.testing.assert_allclose(p, reference.p, rtol=0, atol=1e-12 * scale)
        u = W @ p + q
        assert contact_residual(np.array([lo]), np.array([hi]), p, u) <= 1e-13 * scale
        modes.add("open" if p_n == 0 else ("slip" if p_t in (lo * p_n, hi * p_n) else "stick"))
    assert taken > 1500 and modes == {"open", "stick", "slip"}


@pytest.mark.parametrize("a, b, lo, hi", [
    (1.0, 2.0, -0.8, 0.8),   # Painlevé: a + b lo < 0, an open and a closed answer
    (1.0, -2.0, -0.8, 0.8),  # the same at the other edge of the cone
])
def test_declines_where_answers_may_be_several(a, b, lo, hi):
    found, _, _ = _interpreted(one_contact_impulse)(a, b, b, 5.0, 1.0, -1.0, lo, hi)
    assert not found


def test_declines_singular_and_nonfinite():
    solve = _interpreted(one_contact_impulse)
    assert not solve(1.0, 1.0, 1.0, 1.0, -1.0, 0.0, -0.5, 0.5)[0]  # det = 0: stick split not unique
    assert not solve(1.0, 0.0, 0.0, 1.0, np.nan, 0.0, -0.5, 0.5)[0]
    assert not solve(0.0, 0.0, 0.0, 1.0, -1.0, 0.0, -0.5, 0.5)[0]  # no normal stiffness


def _scene_problems(scene, q0, v0, h, t_end):
    """One-contact step problems of a shipped scene along its run: at each kept state, for each
    contact within reach of its obstacle, W = (H_N; H_T) M⁻¹ (H_N; H_T)ᵀ and q = H v_free − w
    (v_free = v + h M⁻¹ f with the weight), under each slip guess's interval."""
    import nonsmooth_rod as nr
    from nonsmooth_rod.model.packing import pack_scene

    packed = pack_scene(scene)
    run = nr.simulate(scene, q0, v0, t_end, method="moreau-jean", h=h, solver="lemke")
    n_dof = packed.minv.shape[0]
    for q, v in zip(run.trajectory.q[::5], run.trajectory.v[::5]):
        v_free = v + h * packed.minv * packed.weight
        for contact in scene.contacts:
            kin = contact.kinematics(q, v, n_dof)
            if not kin.gap < 1e-3:
                continue
            H = np.array([kin.H_N, kin.H_T])
            W = H @ np.diag(packed.minv) @ H.T
            q_step = H @ v_free - np.array([kin.normal_velocity, kin.surface_velocity])
            mu_s, mu_d = contact.law.friction.mu_s, contact.law.friction.mu_d
            for guess in (-1.0, 0.0, 1.0):
                shift = (mu_s - mu_d) * guess
                yield W, q_step, shift - mu_s, shift + mu_s


def _shipped_scenes():
    from nonsmooth_rod import toys
    from nonsmooth_rod.rod.problem import RodProblem

    rod = RodProblem.paper(2)
    yield "rod", rod.scene(), *rod.initial_state(), 1e-3, 0.3
    for name in ("BouncingBall", "DiskOnIncline", "PainleveRod", "BlockOnIncline", "PushedBlock", "RockingBlock",
                 "BeltOscillator"):
        toy = getattr(toys, name)()
        yield name, toy.scene(), *toy.initial_state(), 1e-3, 0.2


def test_shipped_scenes_one_contact_problems_get_lemkes_answer():
    """The rod's and the toys' own contact problems (their W and q along their runs, every slip
    guess): the closed form, where it answers, is Lemke's answer to round-off."""
    taken = 0
    for name, scene, q0, v0, h, t_end in _shipped_scenes():
        for W, q, lo, hi in _scene_problems(scene, q0, v0, h, t_end):
            found, p_n, p_t = one_contact_impulse(W[0, 0], W[0, 1], W[1, 0], W[1, 1], q[0], q[1], lo, hi)
            if not found:
                continue
            taken += 1
            reference = lemke_friction(PlanarFrictionProblem(W, q, np.array([lo]), np.array([hi])))
            scale = max(np.max(np.abs(q)), np.max(np.abs(reference.p)), 1e-300)
            np.testing.assert_allclose([p_n, p_t], reference.p, rtol=0, atol=1e-12 * scale, err_msg=name)
    assert taken > 100


@pytest.mark.parametrize("solver", ["lemke", "pgs"])
def test_the_step_takes_the_closed_form_for_one_contact(solver):
    """A disk rolling down an incline (one contact, every step solved): no step reaches the
    solver, which would count its pivots or sweeps (its physics: tests/toys/test_incline.py)."""
    import nonsmooth_rod as nr
    from nonsmooth_rod import toys

    toy = toys.DiskOnIncline()
    run = nr.simulate(toy.scene(), *toy.initial_state(), 0.2, method="moreau-jean", h=1e-3, solver=solver)
    assert run.status == "ok" and run.stats["solves"] >= 200
    assert run.stats["solver_iterations"] == 0
