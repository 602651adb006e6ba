"""Planar rigid bodies.

Generalised coordinates of a body are those of its centre of mass and its angle,
q = (x, y, θ), so the mass matrix diag(m, m, J) is constant — the property Moreau–Jean
relies on (no Coriolis terms, no mass-matrix update per step).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..validation import require_finite, require_positive


@dataclass(frozen=True)
class RigidBody:
    """A planar rigid body: mass m, central moment of inertia J (about the normal to the plane)."""

    mass: float
    inertia: float
    name: str = "body"

    def __post_init__(self):
        require_positive(f"{self.name} mass", self.mass)
        require_positive(f"{self.name} inertia", self.inertia)

    @property
    def mass_matrix_diagonal(self) -> np.ndarray:
        return np.array([self.mass, self.mass, self.inertia])


def rotate(theta: float, vec) -> tuple[float, float]:
    """Body-frame vector → world frame at angle θ."""
    c, s = math.cos(theta), math.sin(theta)
    return (c * vec[0] - s * vec[1], s * vec[0] + c * vec[1])


def cross2(a, b) -> float:
    """z-component of the planar cross product a × b."""
    return a[0] * b[1] - a[1] * b[0]


__all__ = ["RigidBody", "rotate", "cross2", "require_finite"]
