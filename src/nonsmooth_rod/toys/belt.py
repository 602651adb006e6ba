"""Stick–slip of a spring-held block on a moving belt."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.contacts import Line
from ..model.forces import Spring
from ..model.scene import Scene
from ..results import SimulationResult
from ..validation import InputError, require_friction_pair, require_positive
from .common import G, _block_scene


@dataclass(frozen=True)
class BeltOscillator:
    """A block on a belt moving at `belt_speed`, held by a spring (stiffness k) to a fixed
    anchor: the classic stick–slip oscillator.

    The block starts riding the belt with the spring relaxed. It sticks until the spring force
    reaches μs N (x = μs N/k), then slips with friction μd N, oscillating about x_d = μd N/k
    until its velocity matches the belt again at x = x_d − y0, y0 = (μs − μd) N/k, and sticks:
    stick time 2 y0 / v_b, slip time (2π − 2 atan(ω y0 / v_b)) / ω, ω = √(k/m).
    The spring acts along the belt's surface (see PushedBlock: no pitching, equal corner loads);
    it is a `Spring` (data), so the whole run is one compiled call.
    """

    belt_speed: float = 0.1
    stiffness: float = 100.0
    mu_s: float = 0.6
    mu_d: float = 0.4
    width: float = 0.2
    height: float = 0.05
    mass: float = 1.0
    g: float = G

    def __post_init__(self):
        require_friction_pair(self.mu_s, self.mu_d)
        for name in ("belt_speed", "stiffness", "width", "height", "mass", "g"):
            require_positive(name, getattr(self, name))
        if self.mu_s == self.mu_d:
            raise InputError("the belt oscillator needs mu_s > mu_d to stick and slip")

    @property
    def line(self) -> Line:
        return Line((0.0, 0.0), 0.0, self.belt_speed)

    def scene(self) -> Scene:
        # a zero-length spring from the middle of the block's bottom face to the anchor at the
        # origin of the belt's surface: −k x along the belt while the block lies flat on it
        spring = Spring(0, (0.0, -self.height / 2), None, (0.0, 0.0), stiffness=self.stiffness, name="spring")
        return _block_scene(self, [spring])

    def initial_state(self):
        return np.array([0.0, self.height / 2, 0.0]), np.array([self.belt_speed, 0.0, 0.0])

    @property
    def normal_force(self) -> float:
        return self.mass * self.g

    @property
    def omega(self) -> float:
        return math.sqrt(self.stiffness / self.mass)

    @property
    def slip_amplitude(self) -> float:
        """y0 = (μs − μd) N / k: the offset of both stick ends from the slip centre μd N / k."""
        return (self.mu_s - self.mu_d) * self.normal_force / self.stiffness

    @property
    def first_slip_time(self) -> float:
        return self.mu_s * self.normal_force / self.stiffness / self.belt_speed

    @property
    def stick_time(self) -> float:
        return 2 * self.slip_amplitude / self.belt_speed

    @property
    def slip_time(self) -> float:
        w = self.omega
        return (2 * math.pi - 2 * math.atan(w * self.slip_amplitude / self.belt_speed)) / w

    @property
    def period(self) -> float:
        return self.stick_time + self.slip_time

    @property
    def slip_onset_position(self) -> float:
        return self.mu_s * self.normal_force / self.stiffness

    @property
    def restick_position(self) -> float:
        return (2 * self.mu_d - self.mu_s) * self.normal_force / self.stiffness

    def limit_cycle(self, n: int = 400) -> tuple[np.ndarray, np.ndarray]:
        """(x, ẋ) around the closed limit cycle: the slip arc, then the stick segment."""
        w, y0, vb = self.omega, self.slip_amplitude, self.belt_speed
        tau = np.linspace(0.0, self.slip_time, n)
        xd = self.mu_d * self.normal_force / self.stiffness
        x = xd + y0 * np.cos(w * tau) + vb / w * np.sin(w * tau)
        xdot = -y0 * w * np.sin(w * tau) + vb * np.cos(w * tau)
        x = np.concatenate([x, [self.slip_onset_position]])
        xdot = np.concatenate([xdot, [vb]])
        return x, xdot


def stick_slip_phases(result: SimulationResult, min_duration: float = 0.0) -> list[tuple[str, float, float]]:
    """(mode, start, end) of the block's stick and slip phases, read from both corners: the
    block sticks while both corners stick and slips while both slip."""
    tr = result.trajectory
    modes = tr.modes
    words = []
    for row in modes:
        states = set(row)
        if states == {"stick"}:
            words.append("stick")
        elif states <= {"slip+", "slip-"}:
            words.append("slip")
        else:
            words.append("mixed")
    phases: list[list] = []
    for k in range(1, len(tr.t)):
        w = words[k]
        if phases and phases[-1][0] == w:
            phases[-1][2] = tr.t[k]
        else:
            phases.append([w, tr.t[k - 1], tr.t[k]])
    return [tuple(p) for p in phases if p[2] - p[1] >= min_duration]
