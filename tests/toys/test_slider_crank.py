"""A slider-crank whose slider rubs its guide (after Flores, Leine & Glocker 2010): without
clearance or friction the rigid mechanism's closed form x(φ); with clearance the slider thrown
from wall to wall; energy lost only where the scheme or the contacts dissipate it."""
import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod.toys.slider_crank import SliderCrank, wall_switches

H = 1e-4


def _run(toy, t_end, h=H):
    result = nr.simulate(toy.scene(), *toy.initial_state(), t_end, "moreau-jean", h=h)
    assert result.status == "ok"
    return result


def test_without_clearance_or_friction_the_slider_follows_the_rigid_closed_form():
    toy = SliderCrank(g=0.0)  # a horizontal mechanism: the guide's walls carry only the rod's thrust
    result = _run(toy, 0.1)  # 1.76 turns of the crank (it slows while it speeds the slider up)
    phi = result.q[:, 2]
    assert phi[-1] - phi[0] > 3 * np.pi
    assert np.max(np.abs(result.q[:, 6] - toy.slider_position(phi))) < 1e-8  # m, of a 0.1 m stroke
    assert np.max(np.abs(result.q[:, 7:9])) < 1e-8  # the slider stays level on the guide's axis
    assert len(wall_switches(result)) >= 2  # the thrust passes from one wall to the other, each turn


@pytest.mark.parametrize("mu", [0.0, 0.1])
def test_without_clearance_the_unloaded_corners_stay_on_their_wall_through_the_load_switches(mu):
    """Rigid guide, gravity on, 5 rev/s: the rod's thrust moves from one wall to the other, and the
    corners on the unloaded wall stay at zero gap — the joints' position projection holds the
    contacts that touch without load too (it held only the loaded ones: 2.2e-6 m after 4 switches)."""
    toy = SliderCrank(mu=mu, crank_speed=2 * np.pi * 5)
    result = _run(toy, 0.4)
    assert len(wall_switches(result)) >= 2
    scene = toy.scene()
    gaps = np.array([[c.kinematics(q, np.zeros_like(q), q.size).gap for c in scene.contacts] for q in result.q[::20]])
    assert np.max(np.abs(gaps)) < 1e-9  # 8e-11 m measured, of a 5 cm slider


def test_with_clearance_the_slider_is_thrown_from_wall_to_wall():
    toy = SliderCrank(clearance=1e-3, mu=0.1)
    result = _run(toy, 0.2)
    switches = wall_switches(result)
    walls = [wall for _, wall in switches]
    assert len(walls) >= 6 and all(a != b for a, b in zip(walls, walls[1:]))  # alternating
    y = result.q[:, 7]
    # between the walls: the slider's corners reach each wall and never pass it (step's overshoot)
    half_travel = 0.5 * toy.clearance
    assert np.max(y) > 0.9 * half_travel and np.min(y) < -0.9 * half_travel
    corners = np.abs(y) + 0.5 * toy.slider_width * np.abs(np.sin(result.q[:, 8]))
    corner_speed = np.abs(result.v[:, 7]) + 0.5 * toy.slider_width * np.abs(result.v[:, 8])
    assert np.max(corners) < half_travel + np.max(corner_speed) * H  # a corner lands within its step


def test_the_frictionless_rigid_mechanism_loses_energy_only_at_the_scheme_s_first_order():
    """No friction, no clearance, no torque: the energy is constant but for Moreau–Jean's
    first-order dissipation at the joints (docs/joints.md, "Accuracy"): the loss halves with h."""
    toy = SliderCrank(g=0.0)
    losses = []
    for h in (2 * H, H):
        energy = toy.energy(_run(toy, 0.05, h))
        assert np.all(np.diff(energy) <= 1e-12 * energy[0])  # never gains
        losses.append(energy[0] - energy[-1])
    assert 0 < losses[1] < 0.05 * toy.energy_at_start
    assert losses[0] / losses[1] == pytest.approx(2.0, rel=0.2)


def test_friction_in_the_guide_takes_energy_from_the_mechanism():
    toys = [SliderCrank(clearance=1e-3, g=0.0, mu=mu) for mu in (0.0, 0.3)]
    free, rubbing = (toy.energy(_run(toy, 0.05)) for toy in toys)
    assert free[0] == rubbing[0] and free[-1] - rubbing[-1] > 1e-3 * free[0]


@pytest.mark.parametrize("field, value", [("rod_length", 0.04), ("clearance", -1e-3), ("slider_mass", 0.0)])
def test_bad_parameters_are_refused_naming_the_field(field, value):
    with pytest.raises(nr.InputError, match=field):
        SliderCrank(**{field: value})


def test_the_example_scene_file_is_the_toy_with_clearance():
    from pathlib import Path

    sf = nr.load_scene(Path(__file__).resolve().parents[2] / "examples" / "scenes" / "slider_crank.toml")
    toy = SliderCrank(clearance=1e-3, mu=0.1)
    q0, v0 = toy.initial_state()
    assert sf.q0 == pytest.approx(q0, abs=1e-14) and sf.v0 == pytest.approx(v0, abs=1e-12)
    from_file = nr.simulate(sf.scene, sf.q0, sf.v0, 0.05, "moreau-jean", h=H)
    assert np.max(np.abs(from_file.q - _run(toy, 0.05).q)) < 1e-12
