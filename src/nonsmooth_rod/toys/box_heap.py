"""A heap of boxes dropped into a bin: every pair of shapes finds its contacts.

No closed form answers a heap; what it must show is physics — no box passes through another,
the floor or a wall (`model.collision.deepest_overlap`, separating axes, independent of the
contact kernels) — and its cost (benchmarks/bench_shapes.py, beside pymunk and MuJoCo).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.body import RigidBody
from ..model.collision import PairLaws, Polygon, find_contacts
from ..model.contacts import Line
from ..model.laws import ContactLaw
from ..model.scene import Scene
from ..model.shapes import rectangle_inertia
from ..validation import InputError, require_friction_pair, require_positive
from .common import G

COLUMN_SPACING = 1.25  # × the box's width: columns far enough apart for the tilts
LAYER_SPACING = 1.6  # × the box's height: layers far enough apart for the tilts


@dataclass(frozen=True)
class BoxHeap:
    """`n` boxes (width × height, `mass`) in layers of `columns`, each tilted at random by up to
    `tilt` (seeded by `seed`), dropped from rest into a bin (a floor and two walls); μs/μd
    everywhere, no bounce. Every pair of shapes is searched: a box may meet any other."""

    n: int = 50
    columns: int = 5
    width: float = 0.2
    height: float = 0.1
    mass: float = 1.0
    tilt: float = 0.2
    mu_s: float = 0.5
    mu_d: float = 0.4
    seed: int = 2
    g: float = G

    def __post_init__(self):
        for name in ("n", "columns"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise InputError(f"{name} must be a whole number ≥ 1, got {value!r}")
        for name in ("width", "height", "mass", "g"):
            require_positive(name, getattr(self, name))
        if not 0.0 <= self.tilt <= 0.3:
            raise InputError(f"tilt must be in [0, 0.3] rad (the layers' spacing allows no more), got {self.tilt!r}")
        require_friction_pair(self.mu_s, self.mu_d)

    def names(self) -> list[str]:
        return [f"box{k}" for k in range(self.n)]

    def shapes(self) -> dict:
        box = Polygon.rectangle(self.width, self.height)
        return {name: box for name in self.names()}

    @property
    def half_span(self) -> float:
        """Half the bin's inner width (the walls at ± this)."""
        return (self.columns / 2 + 0.3) * COLUMN_SPACING * self.width

    def obstacles(self) -> dict:
        return {"floor": Line(), "left": Line((-self.half_span, 0.0), -math.pi / 2),
                "right": Line((self.half_span, 0.0), math.pi / 2)}

    def scene(self) -> Scene:
        inertia = rectangle_inertia(self.mass, self.width, self.height)
        bodies = [RigidBody(self.mass, inertia, name=name) for name in self.names()]
        laws = PairLaws(default=ContactLaw.of(self.mu_s, self.mu_d, 0.0))
        return Scene(bodies, find_contacts(bodies, self.shapes(), self.obstacles(), laws), gravity=self.g)

    def initial_state(self):
        """Layers of `columns` boxes, odd layers shifted by a quarter column, each box tilted and
        nudged sideways at random (`seed`), at rest."""
        rng = np.random.default_rng(self.seed)
        q0 = np.zeros(3 * self.n)
        step_x, step_y = COLUMN_SPACING * self.width, LAYER_SPACING * self.height
        for k in range(self.n):
            layer, column = divmod(k, self.columns)
            shift = 0.25 * step_x if layer % 2 else -0.25 * step_x
            q0[3 * k] = (column - (self.columns - 1) / 2) * step_x + shift + rng.uniform(-0.05, 0.05) * self.width
            q0[3 * k + 1] = (0.8 + layer * LAYER_SPACING) * self.height
            q0[3 * k + 2] = rng.uniform(-self.tilt, self.tilt)
        return q0, np.zeros_like(q0)


__all__ = ["BoxHeap"]
