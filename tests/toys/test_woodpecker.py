"""Glocker's woodpecker toy: the published three-coordinate model against Siconos' reference run,
and the toy's planar scene (sleeve, carriage, bird; a slider and two pins) against that model
with the exact geometry, both integrated independently (toys/woodpecker_reduced.py); the same
scene linearised as published (geometry="linearised": LinearRelation contacts with the published
rows, a LinearJoint hinge) against Siconos' run and the linearised model."""
import math

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod.toys.woodpecker import Woodpecker, limit_cycle
from nonsmooth_rod.toys.woodpecker_reduced import SICONOS, run_reduced

H = 1e-4
T_END = 0.45  # three beak impacts: two whole cycles


def _reduced_cycle(linear):
    t, q, _, closings = run_reduced(Woodpecker(), T_END, H, linear)
    times, names = [c[0] for c in closings], [c[1] for c in closings]
    return limit_cycle(None, times, names, np.interp(times, t, q[:, 0]))


@pytest.fixture(scope="module")
def toy_cycle():
    toy = Woodpecker()
    result = nr.simulate(toy.scene(), *toy.initial_state(), T_END, "moreau-jean", h=H)
    assert result.status == "ok"
    return result, limit_cycle(result)


def test_the_published_model_reproduces_siconos_reference_run():
    """Reads the published parameters right: Siconos' run (h = 2e-5) within this run's step."""
    cycle = _reduced_cycle(linear=True)
    assert cycle.beak_times[:2] == pytest.approx(SICONOS["beak_times"], abs=3 * H)
    siconos_period = SICONOS["beak_times"][1] - SICONOS["beak_times"][0]
    siconos_drop = SICONOS["heights"][0] - SICONOS["heights"][1]
    assert cycle.periods == pytest.approx(siconos_period, rel=2e-3)  # 0.1462 against 0.14606 s
    assert cycle.descents == pytest.approx(siconos_drop, rel=1e-2)  # 19.6 against 19.48 mm
    assert all(seq == SICONOS["sequence"] for seq in cycle.sequences)


def test_the_toy_limit_cycle_is_the_exact_geometry_model_s(toy_cycle):
    result, cycle = toy_cycle
    reference = _reduced_cycle(linear=False)
    assert len(cycle.periods) == len(reference.periods) == 2
    # two first-order schemes at one step: 0.4 to 0.8 % apart in period (each within 0.5 % of its h → 0)
    assert cycle.periods == pytest.approx(reference.periods, rel=1.5e-2)
    assert cycle.descents == pytest.approx(reference.descents, rel=6e-2)  # 2 to 4 % apart
    assert cycle.sequences == reference.sequences == [["beak", "lower", "lower"]] * 2


def test_each_cycle_jams_slides_sticks_and_frees_the_sleeve_before_the_beak_hits(toy_cycle):
    """The lower edge lands (e = 0) after the beak's impact, slides down, sticks while the bird
    swings, slides again and lets go before the next impact; the upper edge never touches
    (exact geometry: the sleeve turns to 0.092 rad after the impact, short of its 0.1009 rad jam)."""
    result, cycle = toy_cycle
    lower = [p for p in result.phases["lower"] if cycle.beak_times[0] <= p.t_start < cycle.beak_times[-1]]
    assert [p.mode for p in lower] == ["slip+", "stick", "slip+", "open"] * 2  # slip+: down the pole
    assert [p.mode for p in result.phases["upper"]] == ["open"]
    sleeve_angle = Woodpecker.coordinates(result)[:, 1]
    # an edge lands (e = 0) within the step it reaches the pole: |φ_M| beyond the jam by ≤ |φ̇_M| h
    assert np.max(np.abs(sleeve_angle)) < Woodpecker().jam_angle + 30.0 * H


def test_while_the_sleeve_sticks_the_bird_swings_about_a_fixed_hinge(toy_cycle):
    """(J_S + m_S l_G²) φ̈_S = −c (φ_S − φ_M) − m_S g l_G cos φ_S while y and φ_M hold."""
    result, cycle = toy_cycle
    toy = Woodpecker()
    stick = next(p for p in result.phases["lower"] if p.mode == "stick" and p.t_start > cycle.beak_times[0])
    inside = (result.t > stick.t_start + 0.002) & (result.t < stick.t_end - 0.002)
    y, phi_m, phi_s = Woodpecker.coordinates(result)[inside].T
    assert np.ptp(y) < 1e-12 and np.ptp(phi_m) < 1e-12
    inertia = toy.bird_inertia + toy.bird_mass * toy.bird_offset ** 2
    closed_form = (-toy.spring_stiffness * (phi_s - phi_m)
                   - toy.bird_mass * toy.g * toy.bird_offset * np.cos(phi_s)) / inertia
    # θ = ½: each step's change of φ̇_S is h times the mean of the accelerations at its two ends,
    # up to the joints' first-order lag (docs/joints.md, "Accuracy"): 2.7e-3 of the peak at h = 1e-4
    measured = np.diff(result.v[inside, 8]) / np.diff(result.t[inside])
    expected = 0.5 * (closed_form[1:] + closed_form[:-1])
    assert np.max(np.abs(measured - expected)) < 50 * H * np.max(np.abs(closed_form))


# At h = 1e-4 the linearised toy's cycles alternate between 0.1444 and 0.1467 s (a second landing of
# the lower edge, taken or not: a step-sized event); from h = 5e-5 every cycle has Siconos' closings
# (0.1455/0.1462 s; 0.1457–0.1459 s at 2e-5: benchmarks/bench_woodpecker.py).
H_LINEARISED = 5e-5


@pytest.fixture(scope="module")
def linearised_run():
    toy = Woodpecker(geometry="linearised")
    result = nr.simulate(toy.scene(), *toy.initial_state(), T_END, "moreau-jean", h=H_LINEARISED)
    assert result.status == "ok"
    return result, limit_cycle(result)


def test_the_engine_runs_the_published_model_to_siconos_limit_cycle(linearised_run, toy_cycle):
    """Every cycle within 1 % of the period of Siconos' run (0.14606 s; 0.4 % measured) with its
    closings, and of the three-coordinate linearised model's (two first-order schemes); the beak's
    impacts within 1 ms of Siconos' (0.7 ms measured)."""
    result, cycle = linearised_run
    siconos_period = SICONOS["beak_times"][1] - SICONOS["beak_times"][0]
    siconos_drop = SICONOS["heights"][0] - SICONOS["heights"][1]
    reference = _reduced_cycle(linear=True)
    assert len(cycle.periods) == len(reference.periods) == 2
    assert cycle.beak_times[:2] == pytest.approx(SICONOS["beak_times"], abs=1e-3)
    assert cycle.periods == pytest.approx(siconos_period, rel=1e-2)
    assert cycle.periods == pytest.approx(reference.periods, rel=1e-2)
    assert cycle.sequences == [SICONOS["sequence"]] * 2
    assert cycle.descents == pytest.approx(siconos_drop, rel=3e-2)  # 19.0 and 19.7 against 19.48 mm
    assert np.all(cycle.periods > 1.08 * toy_cycle[1].periods)  # the exact geometry's: 11 % shorter


def test_the_linearised_toy_holds_its_linear_hinge_and_the_bird_never_moves_sideways(linearised_run):
    """The LinearJoint keeps y_bird = y + l_M φ_M + l_G φ_S to round-off; nothing pushes the bird
    sideways (the published mass matrix has no horizontal motion of it)."""
    result, _ = linearised_run
    toy = Woodpecker(geometry="linearised")
    y, phi_m, phi_s = Woodpecker.coordinates(result).T
    bird_y = result.q[:, 3 * 2 + 1]
    scale = np.max(np.abs(result.q))
    assert np.max(np.abs(bird_y - y - toy.hinge_offset * phi_m - toy.bird_offset * phi_s)) < 1e-14 * scale * 100
    assert np.ptp(result.q[:, 6]) == 0.0 and np.max(np.abs(result.v[:, 6])) == 0.0


def test_the_jam_angle_is_where_the_lower_edge_meets_the_pole():
    toy = Woodpecker()
    a = toy.jam_angle
    x = toy.sleeve_radius * math.cos(a) - toy.sleeve_half_height * math.sin(a)
    assert x == pytest.approx(toy.pole_radius, abs=1e-15)
    assert a < (toy.sleeve_radius - toy.pole_radius) / toy.sleeve_half_height  # the linearised 0.1034


@pytest.mark.parametrize("field, value", [("sleeve_radius", 0.002), ("bird_mass", 0.0), ("mu", -0.1),
                                          ("start", (0.0, 0.1)), ("geometry", "linear")])
def test_bad_parameters_are_refused_naming_the_field(field, value):
    with pytest.raises(nr.InputError, match=field):
        Woodpecker(**{field: value})


@pytest.mark.parametrize("name, geometry", [("woodpecker", "exact"), ("woodpecker_linearised", "linearised")])
def test_the_example_scene_file_is_the_toy(name, geometry):
    from pathlib import Path

    sf = nr.load_scene(Path(__file__).resolve().parents[2] / "examples" / "scenes" / f"{name}.toml")
    toy = Woodpecker(geometry=geometry)
    q0, v0 = toy.initial_state()
    assert sf.q0 == pytest.approx(q0, abs=1e-15) and sf.v0 == pytest.approx(v0, abs=1e-15)
    from_file = nr.simulate(sf.scene, sf.q0, sf.v0, 0.1, "moreau-jean", h=H)
    from_toy = nr.simulate(toy.scene(), q0, v0, 0.1, "moreau-jean", h=H)
    assert from_file.contact_names == from_toy.contact_names == ["beak", "lower", "upper"]
    assert np.max(np.abs(from_file.q - from_toy.q)) < 1e-12
