"""Housner's rocking block: a slender block rocking on its corners."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.body import RigidBody, rotate
from ..model.contacts import Line
from ..model.laws import ContactLaw
from ..model.scene import Scene
from ..results import SimulationResult
from ..validation import require_friction_pair, require_in_range, require_positive
from .common import G, _corners, _rectangle_inertia


@dataclass(frozen=True)
class RockingBlock:
    """Housner's rocking block: a uniform rectangle (half-width b, half-height c) tilted by
    `tilt` onto its left corner and released on a rigid floor (e = 0, friction high enough
    to prevent sliding).

    Slenderness α = atan(b/c), R = √(b² + c²). Rocking about a corner conserves energy; each
    impact (the other corner lands, the old one lifts off) conserves the angular momentum about
    the landing corner, so ω⁺/ω⁻ = 1 − (3/2) sin² α (Housner 1963). The first impact comes at
    |ω| = √(3 g/(2R) (cos(α − tilt) − cos α)), and every impact multiplies |ω| by the ratio.
    """

    half_width: float = 0.1
    half_height: float = 0.3
    tilt: float = math.radians(10.0)
    mu: float = 1.0
    mass: float = 1.0
    g: float = G

    def __post_init__(self):
        for name in ("half_width", "half_height", "mass", "g"):
            require_positive(name, getattr(self, name))
        require_in_range("tilt", self.tilt, 0.0, self.slenderness, open_lo=True, open_hi=True)
        require_friction_pair(self.mu, self.mu)

    @property
    def slenderness(self) -> float:
        return math.atan2(self.half_width, self.half_height)

    @property
    def size(self) -> float:
        """R: distance from the centre of mass to a corner."""
        return math.hypot(self.half_width, self.half_height)

    @property
    def ratio(self) -> float:
        return 1.0 - 1.5 * math.sin(self.slenderness) ** 2

    @property
    def first_impact_rate(self) -> float:
        """|θ̇| just before the first impact."""
        a, R = self.slenderness, self.size
        return math.sqrt(1.5 * self.g / R * (math.cos(a - self.tilt) - math.cos(a)))

    def impact_rates(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """|θ̇| before and after each of the first n impacts."""
        before = self.first_impact_rate * self.ratio ** np.arange(n)
        return before, before * self.ratio

    def scene(self) -> Scene:
        w, hgt = 2 * self.half_width, 2 * self.half_height
        body = RigidBody(self.mass, _rectangle_inertia(self.mass, w, hgt), name="block")
        law = ContactLaw.of(self.mu, self.mu, 0.0)
        return Scene([body], _corners(0, w, hgt, Line(), law), gravity=self.g)

    def initial_state(self):
        # Pivot (left corner) at the origin; the centre of mass sits at rotate(tilt, (b, c)).
        cx, cy = rotate(self.tilt, (self.half_width, self.half_height))
        return np.array([cx, cy, self.tilt]), np.zeros(3)


def impact_rate_pairs(result: SimulationResult, *, extrapolate: bool = False) -> list[tuple[float, float, float]]:
    """(t, θ̇ before, θ̇ after) of body 0 at each impact of a run.

    Moreau–Jean's post-impact velocity is the end-of-step velocity, one step of gravity after
    the impact. With `extrapolate`, the next step's change of θ̇ (pure rocking by then) carries
    it back to the impact time, which removes that O(h) part of the error (the Jacobians are
    still taken at the step's start, |θ̇| h away from the impact configuration).
    """
    out = []
    tr = result.trajectory
    for imp in result.impacts:
        before, after = float(imp.v_before[2]), float(imp.v_after[2])
        if extrapolate and result.method == "moreau-jean":
            k = np.flatnonzero(np.all(tr.v == imp.v_after, axis=1))
            if k.size and k[0] + 1 < len(tr.t):
                k = int(k[0])
                rate = (tr.v[k + 1, 2] - tr.v[k, 2]) / (tr.t[k + 1] - tr.t[k])
                after -= rate * (tr.t[k] - imp.t)
        out.append((float(imp.t), before, after))
    return out
