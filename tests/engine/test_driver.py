"""The one driver, nr.simulate: methods by name, options passed through, stop conditions,
start time, sampling — checked against closed forms — and every bad argument refused by name."""
import math

import numpy as np
import pytest

from nonsmooth_rod.validation import InputError

import nonsmooth_rod as nr

G = 9.81


def thrown_disk(mu_s=0.4, mu_d=0.3, radius=0.1):
    disk = nr.RigidBody(1.0, 0.5 * radius**2, name="disk")
    rim = nr.DiskOnLine(0, (0.0, 0.0), nr.Line(), radius, nr.ContactLaw.of(mu_s, mu_d), name="floor")
    return nr.Scene([disk], [rim], gravity=G)


def dropped_ball(height=1.0, radius=0.05, restitution=0.5):
    ball = nr.RigidBody(1.0, 0.4 * radius**2, name="ball")
    contact = nr.DiskOnLine(0, (0.0, 0.0), nr.Line(), radius, nr.ContactLaw.of(0.0, 0.0, restitution),
                            name="floor")
    return nr.Scene([ball], [contact], gravity=G), [0.0, height + radius, 0.0], [0.0, 0.0, 0.0]


@pytest.mark.parametrize("method, tol", [("moreau-jean", 1e-3), ("event-driven", 1e-9)])
def test_a_disk_thrown_without_spin_rolls_from_the_closed_form_time(method, tol):
    v0, mu_d = 2.0, 0.3
    run = nr.simulate(thrown_disk(mu_d=mu_d), [0.0, 0.1, 0.0], [v0, 0.0, 0.0], 0.5, method=method)
    assert run.success and run.status == nr.Status.OK and run.method == method
    assert [p.mode for p in run.phases["floor"]] == ["slip+", "stick"]
    assert abs(run.phases["floor"][1].t_start - v0 / (3 * mu_d * G)) <= tol
    assert run.v[-1, 0] == pytest.approx(2 * v0 / 3, rel=1e-9)
    assert isinstance(run.phases["floor"][1].t_start, float)  # plain floats, not numpy scalars


def test_stop_at_the_first_impact_of_a_named_contact():
    scene, q0, v0 = dropped_ball()
    for stop in ("floor", nr.StopAtImpact("floor")):
        run = nr.simulate(scene, q0, v0, 5.0, method="event-driven", stop=stop)
        assert run.success
        assert [i.t for i in run.impacts] == pytest.approx([math.sqrt(2 / G)], abs=1e-12)
        assert run.t[-1] == pytest.approx(math.sqrt(2 / G), abs=1e-12)


def test_a_callable_stop_ends_the_run_where_it_first_holds():
    scene, q0, v0 = dropped_ball(height=1.0)
    h = 1e-3
    run = nr.simulate(scene, q0, v0, 5.0, h=h, stop=lambda t, q, v: q[1] < 0.55)  # fallen 0.5 m
    assert run.status == "stopped" and run.success
    assert run.q[-1, 1] < 0.55 <= run.q[-2, 1]
    assert run.t[-1] == pytest.approx(math.sqrt(2 * 0.5 / G), abs=2 * h)
    assert run.events[-1].kind == "stop"


def test_start_time_shifts_the_run_and_time_dependent_forces_see_absolute_time():
    # a block pushed by a force that switches on at t = 1.2 s, started at t0 = 1 s
    block = nr.RigidBody(1.0, 1.0 / 6.0, name="block")
    law = nr.ContactLaw.of(0.5, 0.5)
    corners = [nr.PointOnLine(0, (-0.5, -0.05), nr.Line(), law, "left"),
               nr.PointOnLine(0, (0.5, -0.05), nr.Line(), law, "right")]
    push = 2 * 0.5 * G  # twice what μs holds: a = (2 − 1) μ g = μ g

    def force(t, q, v):
        fx = push if t >= 1.2 else 0.0
        return np.array([fx, 0.0, 0.05 * fx])  # applied at the bottom face: no pitching

    scene = nr.Scene([block], corners, applied_force=force)
    run = nr.simulate(scene, [0.0, 0.05, 0.0], [0.0, 0.0, 0.0], 1.6, method="moreau-jean", t0=1.0, h=1e-3)
    assert run.t[0] == 1.0 and run.t[-1] == pytest.approx(1.6)
    assert run.phases["left"][0].mode == "stick" and run.phases["left"][0].t_start == 1.0
    assert run.phases["left"][1].t_start == pytest.approx(1.2, abs=2e-3)
    assert run.v[-1, 0] == pytest.approx(0.5 * G * 0.4, rel=1e-2)


def test_save_every_keeps_one_sample_per_interval():
    scene, q0, v0 = dropped_ball()
    full = nr.simulate(scene, q0, v0, 0.3, h=1e-3)
    thin = nr.simulate(scene, q0, v0, 0.3, h=1e-3, save_every=0.05)
    np.testing.assert_allclose(thin.t, np.linspace(0.0, 0.3, 7), rtol=0, atol=1e-12)
    assert thin.t[-1] == full.t[-1]
    np.testing.assert_array_equal(thin.q[-1], full.q[-1])


@pytest.mark.parametrize("change, fragment", [
    (dict(q0=[0.0, 1.0]), "q0 must hold 3 numbers"),
    (dict(q0=None), "q0 must be a sequence"),
    (dict(v0=[0.0, float("nan"), 0.0]), "v0 must be finite"),
    (dict(v0="abc"), "v0 must be a sequence"),
    (dict(t_end=0.0), "t_end must be later than t0"),
    (dict(t_end=float("inf")), "t_end must be finite"),
    (dict(method="rk4"), "unknown method 'rk4'"),
    (dict(options={"h": 1e-3, "stepsize": 1}), "unknown option 'stepsize'"),
    (dict(options={"h": -1.0}), "h (step size) must be positive"),
    (dict(options={"solver": "magic"}), "unknown solver 'magic'"),
    (dict(options={"stop": "ceiling"}), "no contact named 'ceiling'"),
    (dict(options={"stop": 3}), "stop must be a contact name"),
    (dict(t_end=1e12, options={"h": 1e-4}), "use a larger h"),
    (dict(method="event-driven", t_end=1e6, options={"output_dt": 1e-12}), "coarser output_dt"),
    (dict(options={"save_every": 0.0}), "save_every must be positive"),
])
def test_bad_arguments_are_refused_by_name(change, fragment):
    scene, q0, v0 = dropped_ball()
    args = dict(q0=q0, v0=v0, t_end=0.1, method="moreau-jean", options={})
    args.update(change)
    with pytest.raises(nr.InputError) as err:
        nr.simulate(scene, args["q0"], args["v0"], args["t_end"], method=args["method"], **args["options"])
    assert fragment in str(err.value) and "\n" not in str(err.value)


def test_a_method_refuses_contacts_it_does_not_handle_before_running():
    balls = [nr.RigidBody(1.0, 0.001, name=f"b{i}") for i in range(2)]
    scene = nr.Scene(balls, [nr.DiskOnDisk(0, 1, 0.05, 0.05, name="ab")], gravity=0.0)
    with pytest.raises(nr.InputError, match="does not handle DiskOnDisk"):
        nr.simulate(scene, [0, 0, 0, 0.2, 0, 0], [1, 0, 0, 0, 0, 0], 1.0, method="event-driven")
    run = nr.simulate(scene, [0, 0, 0, 0.2, 0, 0], [1, 0, 0, 0, 0, 0], 0.2, method="moreau-jean", h=1e-3)
    # e = 0, equal masses: a perfectly plastic impact, both move on at half the speed
    assert run.v[-1, [0, 3]] == pytest.approx([0.5, 0.5], rel=1e-12)
    assert [i.contact for i in run.impacts] == ["ab"]


def test_resume_is_refused_by_a_method_that_restarts_from_the_state():
    import nonsmooth_rod as nr
    from nonsmooth_rod import toys

    ball = toys.BouncingBall()
    first = nr.simulate(ball.scene(), *ball.initial_state(), 0.05, h=1e-3)
    with pytest.raises(InputError, match="resume: only a Moreau–Jean run continues from an end state"):
        nr.simulate(ball.scene(), first.trajectory.q[-1], first.trajectory.v[-1], 0.1, method="event-driven",
                    t0=0.05, resume=first.end_state)
