"""LinearRelation (model/contacts.py; Siconos' LagrangianLinearTIR): a contact whose gap is
g0 + w_N·q with constant rows — its kernel, the same motion as the geometric contact it writes
linearly (a block sliding on a floor, a ball bouncing), the closed forms, and bad input in one line."""
import math

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod.model.contacts import LinearRelation
from nonsmooth_rod.model.packing import pack_contacts
from nonsmooth_rod.validation import InputError

G = 9.81


def test_the_gap_is_affine_in_q_and_the_rows_are_the_given_constants():
    contact = LinearRelation({2: (0.5, -1.0, 0.25), 0: (0.0, 2.0, 0.0)}, 0.3, {0: (1.0, 0.0, 0.1)}, name="lin")
    rng = np.random.default_rng(5)
    for _ in range(5):
        q, v = rng.normal(size=9), rng.normal(size=9)
        k = contact.kinematics(q, v, 9)
        assert k.gap == pytest.approx(0.3 + 2.0 * q[1] + 0.5 * q[6] - q[7] + 0.25 * q[8], abs=1e-15)
        assert k.H_N.tolist() == [0.0, 2.0, 0.0, 0, 0, 0, 0.5, -1.0, 0.25]
        assert k.H_T.tolist() == [1.0, 0.0, 0.1, 0, 0, 0, 0, 0, 0]
        assert (k.drift_N, k.drift_T) == (0.0, 0.0)
    assert contact.bodies == (0, 2)


def _block(contacts):
    b = 0.1
    return nr.Scene([nr.RigidBody(1.0, (4 * b * b + 4 * 0.05 ** 2) / 12, name="block")], contacts, gravity=G)


def test_a_block_on_a_floor_as_linear_relations_moves_as_with_line_contacts():
    """The corners (±b, −h) on the floor y = 0, written linearly about θ = 0: gap y − h ± b θ,
    tangent ẋ + h θ̇. The block slides without turning, so both scenes are the same to round-off,
    and it stops at the closed form v0²/(2 μd g)."""
    law, b, h, v0 = nr.ContactLaw.of(0.4, 0.3, 0.0), 0.1, 0.05, 1.0
    geometric = [nr.PointOnLine(0, (s * b, -h), nr.Line(), law, name=f"c{s:+d}") for s in (-1, 1)]
    linear = [LinearRelation({0: (0.0, 1.0, s * b)}, -h, {0: (1.0, 0.0, h)}, law, name=f"c{s:+d}") for s in (-1, 1)]
    runs = [nr.simulate(_block(c), [0.0, h, 0.0], [v0, 0.0, 0.0], 0.45, h=1e-3) for c in (geometric, linear)]
    assert np.max(np.abs(runs[0].q - runs[1].q)) < 1e-14
    assert np.max(np.abs(runs[0].trajectory.normal_force - runs[1].trajectory.normal_force)) < 1e-12
    # the stop falls inside a step: within the deceleration's μd g h² (2.4e-7 m measured)
    assert runs[1].q[-1, 0] == pytest.approx(v0 ** 2 / (2 * 0.3 * G), abs=0.3 * G * 1e-3 ** 2)
    assert [p.mode for p in runs[1].phases["c+1"]][:2] == ["slip+", "stick"]


def test_a_ball_bounces_on_a_linear_relation_at_its_restitution():
    """A ball of radius r dropped from height H onto the relation g = y − r: it lands at
    √(2(H − r)/g), leaves at e times its landing speed (exact: the step's impact law) and rises to
    e²(H − r); the same run as the ball on a floor line."""
    r, height, e, h = 0.05, 1.0, 0.8, 1e-4
    law = nr.ContactLaw.of(0.0, 0.0, e)
    ball = [nr.RigidBody(0.2, 0.2 * r * r / 2, name="ball")]
    floor = nr.Scene(ball, [nr.DiskOnLine(0, (0.0, 0.0), nr.Line(), r, law, name="floor")], gravity=G)
    linear = nr.Scene(ball, [LinearRelation({0: (0.0, 1.0, 0.0)}, -r, None, law, name="floor")], gravity=G)
    runs = [nr.simulate(s, [0.0, height, 0.0], [0.0, 0.0, 0.0], 1.0, h=h) for s in (floor, linear)]
    assert np.max(np.abs(runs[0].q - runs[1].q)) < 1e-13
    result = runs[1]
    (impact, *_) = result.impacts
    assert impact.t == pytest.approx(math.sqrt(2 * (height - r) / G), abs=h)
    k = int(np.argmin(result.v[:, 1]))  # the start of the landing step: Newton's law acts on its velocity
    assert result.v[k + 1, 1] == pytest.approx(-e * result.v[k, 1], rel=1e-12)
    assert result.v[k, 1] == pytest.approx(-math.sqrt(2 * G * (height - r)), abs=G * h)
    apex = result.q[result.t > impact.t, 1].max() - r
    assert apex == pytest.approx(e * e * (height - r), rel=5e-3)  # within the landing step's O(h)


def test_a_constant_tangent_velocity_drags_a_resting_block_like_a_belt():
    """tangent_velocity is the surface's speed along the tangent row, as a belt's: a block at rest on
    it accelerates at μd g up to that speed."""
    law, speed = nr.ContactLaw.of(0.5, 0.5, 0.0), 0.3
    belt = LinearRelation({0: (0.0, 1.0, 0.0)}, 0.0, {0: (1.0, 0.0, 0.0)}, law, name="belt", tangent_velocity=speed)
    scene = nr.Scene([nr.RigidBody(1.0, 0.01)], [belt], gravity=G)
    result = nr.simulate(scene, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 0.2, h=1e-4)
    t_catch = speed / (0.5 * G)
    early = result.t < 0.9 * t_catch
    assert result.v[early, 0] == pytest.approx(0.5 * G * result.t[early], abs=1e-12)
    assert result.v[-1, 0] == pytest.approx(speed, abs=1e-12)


@pytest.mark.parametrize("kwargs, message", [
    ({"normal": {0: (0.0, 0.0, 0.0)}}, "normal row is zero"),
    ({"normal": {0: (0.0, 1.0)}}, r"normal\[0\] must be 3 numbers"),
    ({"normal": {-1: (0.0, 1.0, 0.0)}}, "normal body"),
    ({"normal": {0: (0.0, 1.0, 0.0)}, "tangent": {1: (1.0, 0.0, 0.0)}, "gap0": math.nan}, "gap0"),
    ({"normal": {0: (0.0, 1.0, 0.0), 1: (0, 1, 0), 2: (0, 1, 0)}}, "at most two bodies"),
    ({"normal": {0: (0.0, 1.0, 0.0)}, "law": nr.ContactLaw.of(0.3, 0.3, 0.0)}, "needs a non-zero tangent row"),
])
def test_bad_linear_relations_are_refused_in_one_line(kwargs, message):
    with pytest.raises(InputError, match=message) as err:
        LinearRelation(**{"name": "lin"} | kwargs)
    assert "\n" not in str(err.value) and "'lin'" in str(err.value)


def test_an_unknown_body_and_the_event_driven_method_are_refused_in_one_line():
    contact = LinearRelation({3: (0.0, 1.0, 0.0)}, 0.0, name="lin")
    with pytest.raises(InputError, match="contact 'lin' refers to body 3, but the scene has 1 bodies"):
        nr.Scene([nr.RigidBody(1.0, 0.01)], [contact])
    with pytest.raises(InputError, match="lin: body index beyond the scene's 1 bodies"):
        pack_contacts([contact], 1)
    scene = nr.Scene([nr.RigidBody(1.0, 0.01)], [LinearRelation({0: (0.0, 1.0, 0.0)}, 0.0, name="lin")])
    with pytest.raises(InputError, match="LinearRelation") as err:
        nr.simulate(scene, [0.0, 1.0, 0.0], [0.0, 0.0, 0.0], 0.1, "event-driven")
    assert "\n" not in str(err.value)
