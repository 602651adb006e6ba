"""Integrators declare what they run (integrators/declaration.py) and the driver checks a run from
that alone: a method the driver has never heard of runs through nr.simulate — the scene's clock,
stop condition, thinning (integrators/sampling.py), refusals and the memory check — from its
declaration."""
import ast
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod import integrators
from nonsmooth_rod.integrators.declaration import NO_JOINTS, Declaration, Refusal
from nonsmooth_rod.integrators.sampling import Thinning, stop_message
from nonsmooth_rod.results import SimulationResult, Trajectory

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

G = 9.81


@dataclass
class FlightOptions:
    output_dt: float = 0.01
    stop_at_impact: str | None = None  # the driver passes impact stops as this option


class Flight:
    """Exact free flight under gravity (no contacts): q(t) = q0 + v0 t + g t²/2, on a grid."""

    name = "flight"

    def __init__(self, options):
        self.options = options

    def run(self, scene, q0, v0, t_end, *, t0=0.0, resume=None, save_every=None, stop=()):
        t = np.r_[np.arange(t0, t_end, self.options.output_dt), t_end]
        thinning = Thinning(t0, save_every, stop)
        keep = thinning.keeps(t)
        keep[-1] = True
        t = t[keep]
        g = np.tile(np.array(scene.gravity_vector + (0.0,)), len(scene.bodies))
        q = q0 + np.outer(t - t0, v0) + 0.5 * np.outer((t - t0) ** 2, g)
        v = v0 + np.outer(t - t0, g)
        held = thinning.first_stop(t, q, v)
        status = "ok" if held is None else "stopped"
        if held is not None:
            t, q, v = t[: held + 1], q[: held + 1], v[: held + 1]
        n, nc = len(t), len(scene.contacts)
        traj = Trajectory(t, q, v, np.tile(g, (n, 1)), np.zeros((n, nc)), np.zeros((n, nc)),
                          np.empty((n, nc), dtype=object))
        message = "reached t_end" if held is None else stop_message(t[-1])
        return SimulationResult(self.name, status, message, traj, [], steps=n)


def _heavy(scene, options, duration):
    return {"item": "too heavy"} if scene.bodies[0].mass > 10 else None


Flight.declares = Declaration(options=FlightOptions, contacts=(), refusals=(NO_JOINTS, Refusal(_heavy, "{method}: {item}")),
                              samples_estimate=lambda o, duration, save_every: duration / o.output_dt + 2,
                              samples_knob="a coarser output_dt")


@pytest.fixture
def flight(monkeypatch):
    monkeypatch.setitem(integrators.METHODS, "flight", ("unused", "Flight"))
    monkeypatch.setitem(integrators._CLASSES, "flight", Flight)


def ball(mass=1.0):
    return nr.Scene([nr.RigidBody(mass, 0.01, name="ball")])


def test_an_undeclared_method_runs_from_its_declaration_with_the_drivers_clock_stop_and_thinning(flight):
    q0, v0 = np.array([0.0, 10.0, 0.0]), np.array([1.0, 0.0, 0.0])
    run = nr.simulate(ball(), q0, v0, 3.0, method="flight", t0=1.0, output_dt=1e-3, save_every=0.1,
                      stop=lambda t, q, v: q[1] < 5.0)
    assert run.status == "stopped" and run.method == "flight"
    t_fall = math.sqrt(2 * 5.0 / G)  # the flight reaches y = 5 m at t0 + t_fall (absolute time)
    assert run.t[0] == 1.0 and run.q[-1, 1] < 5.0 <= run.q[-2, 1]
    assert abs(run.t[-1] - (1.0 + t_fall)) <= 0.1 + 1e-9  # the first kept sample past it
    assert np.all(np.diff(run.t[:-1]) >= 0.1 - 1e-9)  # one sample per save_every
    assert run.setup.method == "flight" and run.setup.options == {"output_dt": 1e-3} and run.setup.t0 == 1.0


def test_the_declaration_s_refusals_options_and_output_size_are_the_drivers(flight):
    with pytest.raises(nr.InputError, match="^flight: too heavy$"):
        nr.simulate(ball(mass=20.0), np.zeros(3), np.zeros(3), 1.0, method="flight")
    pinned = nr.Scene([nr.RigidBody(1.0, 0.01)], joints=[nr.Pin(0, name="p")])
    with pytest.raises(nr.InputError, match=r"^method 'flight' does not handle joints \(joint 'p'\); use moreau-jean$"):
        nr.simulate(pinned, np.zeros(3), np.zeros(3), 1.0, method="flight")
    with pytest.raises(nr.InputError, match="unknown option 'h' for method 'flight'; options: output_dt"):
        nr.simulate(ball(), np.zeros(3), np.zeros(3), 1.0, method="flight", h=1e-3)
    with pytest.raises(nr.InputError, match="GiB limit: use a coarser output_dt"):
        nr.simulate(ball(), np.zeros(3), np.zeros(3), 1e6, method="flight", output_dt=1e-6)
    disk = nr.DiskOnLine(0, (0.0, 0.0), nr.Line(), 0.1, nr.ContactLaw.of(0.5, 0.5), name="floor")
    with pytest.raises(nr.InputError, match="method 'flight' does not handle DiskOnLine contacts"):
        nr.simulate(nr.Scene([nr.RigidBody(1.0, 0.01)], [disk]), [0, 1, 0], np.zeros(3), 1.0, method="flight")


def test_every_shipped_method_declares_its_options_and_contacts():
    for method in integrators.METHODS:
        declared = integrators.integrator_class(method).declares
        assert isinstance(declared, Declaration) and "DiskOnLine" in declared.contacts
        assert declared.samples_estimate(declared.options(), 1.0, None) > 1.0


def test_the_driver_never_compares_with_a_method_name():
    """No `method == "moreau-jean"` (or `in (...)` of names) in driver.py: it reads declarations."""
    tree = ast.parse((Path(nr.__file__).parent / "driver.py").read_text())
    names = set(integrators.METHODS)
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare):
            constants = {c.value for c in ast.walk(node) if isinstance(c, ast.Constant)}
            assert not constants & names, ast.unparse(node)
