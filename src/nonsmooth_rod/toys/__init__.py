"""Planar contact toys built from the general parts, each with its closed-form answer.

Every toy is a small frozen dataclass holding its physical parameters (SI units, angles in
radians) with

* ``scene()``          — the `Scene` (bodies, contacts, laws, applied forces),
* ``initial_state()``  — (q0, v0), centre-of-mass coordinates (x, y, θ) of every body,
* closed-form answers  — methods named after what they return (``impact_times``,
  ``slope_acceleration``, ``stick_time`` ...),
* measurement helpers — `ball_height`, `rest_time`, `slope_motion`, `first_slip_time`,
  `stick_slip_phases`, `impact_rate_pairs`, `ball_velocities` read the same quantities off a
  `SimulationResult`, so that tests and examples compare like with like.

`run(toy, method, t_end, ...)` runs any toy with Moreau–Jean or the event-driven reference.
The closed forms are those of shared/design/nonsmooth-notes.md ("Closed forms for tests");
docs/toys.md states the measured agreement of each toy.

Conventions: an incline is `Line(angle=α)`, rising to the right; "along the slope" means
along its tangent (cos α, sin α), so a block sliding down has a negative slope velocity.
A block is a rectangle touching its support by its two bottom corners (`PointOnLine`).
"""
from .belt import BeltOscillator, stick_slip_phases
from .blocks import BlockOnIncline, PushedBlock, slope_motion
from .bouncing_ball import BouncingBall, ball_height, rest_time
from .collisions import BallRow, ball_velocities
from .common import example_parser, first_slip_time, run, save_figure
from .box_heap import BoxHeap
from .disk import DiskOnIncline
from .dominoes import Dominoes
from .indeterminate import DiskPyramid, Ladder, WedgedRod
from .painleve import PainleveRod
from .rocking_block import RockingBlock, impact_rate_pairs
from .shaken import BallOnShakenPlate, ShakenBlock
from .slider_crank import SliderCrank, wall_switches
from .woodpecker import LimitCycle, Woodpecker, limit_cycle

__all__ = [
    "run", "BouncingBall", "BlockOnIncline", "PushedBlock", "DiskOnIncline", "BeltOscillator",
    "RockingBlock", "PainleveRod", "BallRow", "ball_height", "rest_time", "slope_motion",
    "first_slip_time", "stick_slip_phases", "impact_rate_pairs", "ball_velocities", "save_figure",
    "example_parser", "Ladder", "WedgedRod", "DiskPyramid", "ShakenBlock", "BallOnShakenPlate",
    "Woodpecker", "LimitCycle", "limit_cycle", "SliderCrank", "wall_switches", "Dominoes", "BoxHeap",
]
