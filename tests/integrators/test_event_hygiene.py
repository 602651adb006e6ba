"""Moreau–Jean's events: an impact is a contact that closes with approaching velocity, and phase
boundaries are located inside the step."""
import math

import numpy as np
import pytest
from scipy.integrate import quad

from nonsmooth_rod import _jit
from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import Line, PointOnLine
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.model.scene import Scene
from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.rod.simulation import simulate

G, L, PHI0 = 9.81, 1.0, math.radians(60.0)


def _ladder():
    """A uniform rod against the wall x = 0 and the floor y = 0, frictionless, released at 60°."""
    law = ContactLaw.of(0.0, 0.0)
    wall = Line((0.0, 0.0), -math.pi / 2)  # normal +x
    contacts = [PointOnLine(0, (L / 2, 0.0), wall, law, "top"), PointOnLine(0, (-L / 2, 0.0), Line(), law, "bottom")]
    q0 = np.array([L / 2 * math.cos(PHI0), L / 2 * math.sin(PHI0), math.pi - PHI0])
    return Scene([RigidBody(1.0, L * L / 12)], contacts, gravity=G), q0


def _ladder_liftoff_time():
    """The top leaves the wall when sin φ = (2/3) sin φ0; until then φ̇² = (3g/L)(sin φ0 − sin φ)."""
    phi1 = math.asin(2.0 / 3.0 * math.sin(PHI0))
    return quad(lambda p: 1.0 / math.sqrt(3 * G / L * (math.sin(PHI0) - math.sin(p))), phi1, PHI0, limit=200)[0]


@pytest.mark.parametrize("h", [1e-3, 1e-4])
def test_frictionless_ladder_leaves_the_wall_once_without_impacts(h):
    scene, q0 = _ladder()
    run = MoreauJean(MoreauJeanOptions(h=h)).run(scene, q0, np.zeros(3), 0.5)
    assert run.status == "ok"
    assert run.impacts == [] and not [e for e in run.events if e.kind == "impact"]
    top = run.phases["top"]
    assert [p.mode for p in top] == ["slip+", "open"]  # the wall's tangent points down: slip+
    assert abs(top[1].t_start - _ladder_liftoff_time()) <= h
    assert [p.mode for p in run.phases["bottom"]] == ["slip+"]
    liftoffs = [e for e in run.events if e.kind == "liftoff"]
    assert len(liftoffs) == 1 and liftoffs[0].detail["located"] == "interpolated"


REFERENCE = {}


@pytest.mark.parametrize("case", [1, 2, 3])
def test_rod_phase_boundaries_and_impact_within_one_step(case):
    if case not in REFERENCE:
        REFERENCE[case] = simulate(RodProblem.paper(case))
    ref, h = REFERENCE[case], 1e-3
    run = simulate(RodProblem.paper(case), "moreau-jean", h=h)
    assert run.result.stats["compiled"] == _jit.ENABLED
    assert [p.mode for p in run.phases] == [p.mode for p in ref.phases]
    for got, want in zip(run.phases, ref.phases):
        assert abs(got.t_start - want.t_start) <= h
    assert abs(run.impact["t"] - ref.impact["t"]) <= h
    assert [i.contact for i in run.result.impacts] == ["B"]
