"""nonsmooth-rod: nonsmooth contact dynamics of planar rigid bodies with two-coefficient Coulomb
friction — Moreau–Jean time-stepping checked against an event-driven reference.

    import nonsmooth_rod as nr
    scene = nr.Scene([nr.RigidBody(1.0, 0.01)], [nr.DiskOnLine(0, (0.0, 0.0), nr.Line(), 0.05,
                     nr.ContactLaw.of(mu_s=0.3, mu_d=0.2))])
    result = nr.simulate(scene, q0, v0, t_end=1.0, method="moreau-jean", h=1e-3)

The engine (model, solvers, integrators, results) is at the root; the paper's rod
(`nonsmooth_rod.rod`) and the contact toys (`nonsmooth_rod.toys`) are applications of it.
"""
__version__ = "0.2.0"

from .driver import StopAtImpact, simulate
from .model.body import RigidBody
from .model.contacts import (DiskOnDisk, DiskOnLine, DiskOnSegment, Line, PointOnLine, PointOnSegment, Segment,
                             SegmentEndOnEdge, VertexOnEdge, LinearRelation)
from .model.collision import Disk, PairLaws, Polygon, Polyline, find_contacts
from .model.forces import ConstantForce, Damper, RampedForce, Spring, TabulatedForce, Torque, TorsionSpring
from .model.joints import LinearJoint, Pin, Slider
from .model.laws import ContactLaw, CoulombFriction, NewtonImpact
from .model.motion import DrivenBody, Harmonic, Prescribed, Tabulated
from .model.scene import Scene
from .results import ContactState, Event, Impact, Phase, SimulationResult, Status, Trajectory
from .solvers import ContactSolution, PlanarFrictionProblem, SolverError, solve
from .validation import InputError
from . import result_files as _result_files
from .scenefile import load_scene, simulate_scene
from .studies import fit, sweep

load = _result_files.load


def _animate(self, frames: int = 60, fps: int = 20):
    """An inline HTML animation of the run (for notebooks): bodies, lines and contact forces."""
    from .plots.animation import animate

    return animate(self, frames=frames, fps=fps)


# Files, tables and pictures are applications of a result, not part of it: results.py knows no
# file format. They are bound here, once, as the methods users expect.
SimulationResult.save = _result_files.save
SimulationResult.to_dataframe = _result_files.to_dataframe
SimulationResult.restart = _result_files.restart
SimulationResult.animate = _animate

__all__ = [
    "__version__", "simulate", "StopAtImpact", "Scene", "RigidBody", "Line", "DiskOnLine", "PointOnLine",
    "Segment", "DiskOnSegment", "PointOnSegment", "SegmentEndOnEdge", "VertexOnEdge", "LinearRelation", "LinearJoint",
    "Polygon", "Disk", "Polyline", "PairLaws", "find_contacts",
    "DiskOnDisk", "ContactLaw", "CoulombFriction", "NewtonImpact", "SimulationResult", "Status",
    "ContactState", "Phase", "Event", "Impact", "Trajectory", "solve", "PlanarFrictionProblem",
    "ContactSolution", "SolverError", "InputError", "load", "load_scene", "simulate_scene",
    "Spring", "Damper", "ConstantForce", "RampedForce", "TabulatedForce", "TorsionSpring", "Torque", "Pin",
    "Slider", "sweep", "fit",
    "Harmonic", "Tabulated", "Prescribed", "DrivenBody",
]
