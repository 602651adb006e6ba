"""A hostile user's scenes and arguments through the library: every one refused where it is made,
with the project's own one-line InputError naming the argument — never run on garbage, never a raw
numpy/numba/scipy exception (issue 17's battery)."""
import math

import numpy as np
import pytest

import nonsmooth_rod as nr

LAW = nr.ContactLaw.of(0.3, 0.2)


def one_ball(**contact):
    args = dict(body=0, offset=(0.0, 0.0), line=nr.Line(), radius=0.05, law=LAW, name="floor")
    args.update(contact)
    return nr.Scene([nr.RigidBody(1.0, 1e-3)], [nr.DiskOnLine(**args)])


def refused(fragment, make):
    with pytest.raises(nr.InputError) as err:
        make()
    message = str(err.value)
    assert fragment in message and "\n" not in message, message


@pytest.mark.parametrize("fragment, make", [
    ("refers to body 1", lambda: one_ball(body=1)),
    ("body must be a whole number", lambda: one_ball(body=1.5)),
    ("body must be a whole number", lambda: one_ball(body=True)),
    ("body must be non-negative", lambda: one_ball(body=-1)),
    ("offset x must be finite", lambda: one_ball(offset=(math.nan, 0.0))),
    ("offset must be two numbers", lambda: one_ball(offset=(0.0,))),
    ("radius must be finite", lambda: one_ball(radius=math.inf)),
    ("radius must be non-negative", lambda: one_ball(radius=-0.1)),
    ("line must be a Line", lambda: one_ball(line=(0.0, 0.0))),
    ("law must be a ContactLaw", lambda: one_ball(law=0.3)),
    ("line point must be two numbers", lambda: nr.Line(point=(1.0,))),
    ("line point x must be finite", lambda: nr.Line(point=(math.nan, 0.0))),
    ("line angle must be finite", lambda: nr.Line(angle=math.inf)),
    ("exceeds mu_s", lambda: nr.ContactLaw.of(0.2, 0.3)),
    ("restitution must lie in", lambda: nr.ContactLaw.of(0.2, 0.1, restitution=1.5)),
    ("mass must be positive", lambda: nr.RigidBody(-1.0, 1.0)),
    ("inertia must be finite", lambda: nr.RigidBody(1.0, math.nan)),
    ("a contact name must be a non-empty string", lambda: one_ball(name="")),
    ("two contacts are named 'c'", lambda: nr.Scene(
        [nr.RigidBody(1.0, 1.0)],
        [nr.PointOnLine(0, (0.0, 0.0), nr.Line(), LAW, "c"), nr.PointOnLine(0, (1.0, 0.0), nr.Line(), LAW, "c")])),
    ("refers to body 2", lambda: nr.Scene(
        [nr.RigidBody(1.0, 1.0), nr.RigidBody(1.0, 1.0)], [nr.DiskOnDisk(0, 2, 0.1, 0.1)])),
    ("joins two different bodies", lambda: nr.DiskOnDisk(1, 1, 0.1, 0.1)),
    ("scene bodies must be RigidBody", lambda: nr.Scene([1.0])),
    ("scene contacts must be contact relations", lambda: nr.Scene([nr.RigidBody(1.0, 1.0)], ["floor"])),
    ("applied_force must be a callable", lambda: nr.Scene([nr.RigidBody(1.0, 1.0)], applied_force=3.0)),
    ("a scene needs at least one body", lambda: nr.Scene([])),
    ("g must be finite", lambda: nr.Scene([nr.RigidBody(1.0, 1.0)], gravity=math.nan)),
])
def test_a_malformed_scene_is_refused_where_it_is_made(fragment, make):
    refused(fragment, make)


@pytest.mark.parametrize("method", ["moreau-jean", "event-driven"])
@pytest.mark.parametrize("fragment, q0, v0", [
    ("q0 must hold 3 numbers", [0.0, 0.05], [0.0, 0.0, 0.0]),
    ("v0 must hold 3 numbers", [0.0, 0.05, 0.0], [0.0] * 4),
    ("q0 must be a sequence", None, [0.0, 0.0, 0.0]),
    ("v0 must be finite", [0.0, 0.05, 0.0], [0.0, math.nan, 0.0]),
    ("q0 must be finite", [0.0, math.inf, 0.0], [0.0, 0.0, 0.0]),
])
def test_a_bad_initial_state_is_refused_by_name(method, fragment, q0, v0):
    refused(fragment, lambda: nr.simulate(one_ball(), q0, v0, 0.1, method=method))


def test_an_applied_force_of_the_wrong_shape_is_named():
    scene = nr.Scene([nr.RigidBody(1.0, 1.0)], applied_force=lambda t, q, v: np.zeros(2))
    refused("applied_force must return 3 numbers", lambda: nr.simulate(scene, [0, 1, 0], [0, 0, 0], 0.01))


@pytest.mark.parametrize("fragment, method, t_end, options", [
    ("use a larger h", "moreau-jean", 1e12, {"h": 1e-4}),
    ("coarser output_dt", "event-driven", 1.0, {"output_dt": 1e-12}),
])
def test_a_run_whose_output_cannot_fit_is_refused_before_it_allocates(fragment, method, t_end, options):
    refused(fragment, lambda: nr.simulate(one_ball(), [0, 0.05, 0], [0, 0, 0], t_end, method=method, **options))


@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_solvers_refuse_non_finite_data(bad):
    W = np.array([[2.0, 0.0], [0.0, 2.0]])
    refused("must be finite", lambda: nr.solve(nr.PlanarFrictionProblem.coulomb(W, [-1.0, bad], 0.3)))
    refused("must be finite", lambda: nr.solvers.lcp.lemke(np.array([[1.0, bad], [0.0, 1.0]]), np.array([-1.0, 1.0])))
    refused("unknown solver", lambda: nr.solve(nr.PlanarFrictionProblem.coulomb(W, [-1.0, 0.0], 0.3), "magic"))
