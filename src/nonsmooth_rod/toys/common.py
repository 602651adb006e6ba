"""What every toy shares: running one, building blocks, reading results, saving figures."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..io import atomic_path
from ..model.body import RigidBody
from ..model.contacts import Line, PointOnLine
from ..model.laws import ContactLaw
from ..model.scene import Scene
from ..model.shapes import rectangle_inertia as _rectangle_inertia
from ..results import SimulationResult
from ..solvers.registry import DEFAULT_SOLVER
from ..validation import InputError

G = 9.81


def run(toy, method: str = "moreau-jean", t_end: float = 1.0, *, h: float = 1e-3, theta: float = 0.5,
        solver: str = DEFAULT_SOLVER, rtol: float = 1e-12, output_dt: float = 1e-3,
        zeno_interval: float = 1e-9, fast: bool = True) -> SimulationResult:
    """Run a toy from its initial state through `nonsmooth_rod.simulate`: Moreau–Jean
    ("moreau-jean", step h, θ, one-step solver; `fast` allows its compiled loop) or the
    event-driven reference ("event-driven", tolerance rtol, samples every output_dt)."""
    from ..driver import simulate

    q0, v0 = toy.initial_state()
    if method == "moreau-jean":
        options = dict(h=h, theta=theta, solver=solver, fast=fast)
    elif method == "event-driven":
        options = dict(rtol=rtol, atol=rtol, output_dt=output_dt, zeno_interval=zeno_interval)
    else:
        raise InputError(f"unknown method '{method}'; choose moreau-jean or event-driven")
    return simulate(toy.scene(), q0, v0, t_end, method, **options)


def _corners(body: int, width: float, height: float, line: Line, law: ContactLaw):
    """The two bottom corners of a width × height rectangle, as point contacts on `line`."""
    a, b = width / 2, height / 2
    return [PointOnLine(body, (-a, -b), line, law, name="left"),
            PointOnLine(body, (a, -b), line, law, name="right")]


def _block_scene(toy, forces=()) -> Scene:
    """A toy's width × height block on its `line`, both bottom corners with its μs/μd, e = 0, and
    `forces` (model.forces: data the compiled loop evaluates, no Python callback)."""
    body = RigidBody(toy.mass, _rectangle_inertia(toy.mass, toy.width, toy.height), name="block")
    law = ContactLaw.of(toy.mu_s, toy.mu_d, 0.0)
    return Scene([body], _corners(0, toy.width, toy.height, toy.line, law), gravity=toy.g,
                 forces=forces)


def _slope_coordinate(result: SimulationResult, angle: float, body: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Position and velocity of a body's centre of mass along a line of inclination `angle`."""
    t = (math.cos(angle), math.sin(angle))
    q, v = result.trajectory.q, result.trajectory.v
    i = 3 * body
    s = q[:, i] * t[0] + q[:, i + 1] * t[1]
    ds = v[:, i] * t[0] + v[:, i + 1] * t[1]
    return s - s[0], ds


def first_slip_time(result: SimulationResult, contacts=None) -> float | None:
    """Start of the first phase in which any of `contacts` (default all) slips; None if never."""
    names = contacts or result.contact_names
    starts = [ph.t_start for name in names for ph in result.phases.get(name, [])
              if ph.mode in ("slip+", "slip-")]
    return min(starts) if starts else None




def save_figure(fig, out_dir, name: str) -> "Path":
    """Write a matplotlib figure to out_dir/name.png atomically and close it; returns the path."""
    import matplotlib.pyplot as plt

    path = Path(out_dir) / f"{name}.png"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    plt.close(fig)
    return path


def example_parser(description: str):
    """The command line every toy example shares: `--out DIR` for its figure."""
    import argparse

    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--out", default="results/examples",
                        help="folder for the figure (default: ./results/examples)")
    return parser
