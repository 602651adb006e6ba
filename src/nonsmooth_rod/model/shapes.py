"""Mass properties of the body shapes a scene file can name (SI units; planar bodies turn about
the normal to the plane, so every inertia here is the central moment about that axis)."""
from __future__ import annotations

import math

from ..validation import InputError


def disk_inertia(mass: float, radius: float) -> float:
    """Uniform disk or cylinder about its axis: m r²/2."""
    return mass * radius**2 / 2


def ball_inertia(mass: float, radius: float) -> float:
    """Solid sphere: 2/5 m r²."""
    return 0.4 * mass * radius**2


def rectangle_inertia(mass: float, width: float, height: float) -> float:
    """Uniform rectangle (or box) about the axis through its centre: m (w² + h²)/12."""
    return mass * (width**2 + height**2) / 12.0


def thin_rod_inertia(mass: float, length: float) -> float:
    """Thin uniform rod about its middle: m L²/12."""
    return mass * length**2 / 12.0


def rod_with_balls(ball_radius: float, rod_diameter: float, length: float, density: float) -> tuple[float, float]:
    """(mass, central inertia) of two equal solid balls `length` apart (centre to centre) joined by
    a solid cylinder between the ball surfaces (L − 2r long), all of one density.

    The cylinder about a transverse axis is m (3 R² + ℓ²)/12; the balls are spheres shifted by
    L/2 (Steiner). The centre of mass is in the middle. The paper's body: 0.60436 kg, 22.9838e-3 kg m².
    """
    if rod_diameter >= 2 * ball_radius:
        raise InputError(f"rod diameter {rod_diameter:g} m must be smaller than the ball diameter "
                         f"{2 * ball_radius:g} m")
    if length <= 2 * ball_radius:
        raise InputError(f"length {length:g} m between ball centres must exceed the ball diameter "
                         f"{2 * ball_radius:g} m (the balls would overlap)")
    m_ball = density * 4.0 / 3.0 * math.pi * ball_radius**3
    rod_len = length - 2 * ball_radius
    rod_r = rod_diameter / 2
    m_rod = density * math.pi * rod_r**2 * rod_len
    half = length / 2
    inertia = 2 * (ball_inertia(m_ball, ball_radius) + m_ball * half**2) + m_rod * (3 * rod_r**2 + rod_len**2) / 12
    return 2 * m_ball + m_rod, inertia
