"""The paper's closed-form equations for the rod (notes.md, paper eq. 24–43, signs restored).

Kept separate from the general formulation on purpose: tests check one against the other.
All functions take the RodProblem `p` and return accelerations in the paper's coordinates.
"""
from __future__ import annotations

import math


def rolling(p, theta: float, theta_dot: float):
    """Pure rolling: (θ̈, ẍ_O, N, T)."""
    M, xi, J, r, g = p.mass, p.xi, p.inertia, p.ball_radius, p.g
    c, s = math.cos(theta), math.sin(theta)
    theta_ddot = -xi * c * (g + r * theta_dot**2) / (J / M + r**2 + xi**2 + 2 * r * xi * s)
    N = M * (g + xi * theta_ddot * c - xi * theta_dot**2 * s)
    T = -M * ((r + xi * s) * theta_ddot + xi * theta_dot**2 * c)
    return theta_ddot, -r * theta_ddot, N, T


def sliding_denominator(p, theta: float, theta_dot: float, sign: float) -> float:
    """J/M + ξ cos θ · D; sliding is well posed only while this is positive (Painlevé)."""
    D = p.xi * math.cos(theta) + sign * p.mu_d * (p.xi * math.sin(theta) + p.ball_radius)
    return p.inertia / p.mass + p.xi * math.cos(theta) * D


def sliding(p, theta: float, theta_dot: float, sign: float):
    """Sliding with slip direction `sign` = sgn(v_C): (θ̈, ẍ_O, N, T)."""
    M, xi, J, r, g = p.mass, p.xi, p.inertia, p.ball_radius, p.g
    c, s = math.cos(theta), math.sin(theta)
    D = xi * c + sign * p.mu_d * (xi * s + r)
    den = J / M + xi * c * D
    theta_ddot = -D * (g - xi * theta_dot**2 * s) / den
    N = J * (g - xi * theta_dot**2 * s) / den
    T = -p.mu_d * N * sign
    xo_ddot = T / M + xi * theta_dot**2 * c + xi * theta_ddot * s
    return theta_ddot, xo_ddot, N, T
