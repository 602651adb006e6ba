"""Many-contact scenes: a row of balls on a floor and a pyramid pile of disks.

No closed form answers these as a whole; they are the engine's scaling scenes
(benchmarks/bench_scenes.py steps the same ones in MuJoCo and PyBullet) and its stress cases
(a pile is one group of many coupled, statically indeterminate contacts). Each function returns
(scene, q0, v0).
"""
from __future__ import annotations

import math

import numpy as np

from ..model.body import RigidBody
from ..model.contacts import DiskOnDisk, DiskOnLine, Line
from ..model.laws import ContactLaw
from ..model.scene import Scene
from ..validation import InputError, require_positive

BALL_RADIUS, BALL_MASS = 0.05, 0.1


def _require_count(name: str, value, least: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < least:
        raise InputError(f"{name} must be a whole number ≥ {least}, got {value!r}")
    return int(value)


def _balls(n: int, radius: float, mass: float):
    return [RigidBody(mass, 0.4 * mass * radius**2, f"ball{i}") for i in range(n)]


def ball_row(n: int, radius: float = BALL_RADIUS, mass: float = BALL_MASS, gap: float = 1e-3,
             speed: float = 1.0, law: ContactLaw | None = None):
    """N balls on a floor, `gap` apart, the first rolling at `speed` into the others: N floor
    contacts and N − 1 ball–ball contacts (μs, μd = 0.3, 0.2, e = 0 unless `law` is given)."""
    n = _require_count("n (balls)", n, 1)
    require_positive("radius", radius)
    require_positive("mass", mass)
    law = law or ContactLaw.of(0.3, 0.2, 0.0)
    contacts = [DiskOnLine(i, (0.0, 0.0), Line(), radius, law, f"floor{i}") for i in range(n)]
    contacts += [DiskOnDisk(i + 1, i, radius, radius, law=law, name=f"{i}-{i + 1}") for i in range(n - 1)]
    q0 = np.zeros(3 * n)
    q0[0::3] = np.arange(n) * (2 * radius + gap)
    q0[1::3] = radius
    v0 = np.zeros(3 * n)
    v0[0], v0[2] = speed, -speed / radius  # rolling without slip
    return Scene(_balls(n, radius, mass), contacts), q0, v0


def pile_centres(rows: int, radius: float = BALL_RADIUS) -> list[tuple[float, float]]:
    """Centres of a pyramid of `rows` rows of touching disks on the floor y = 0, bottom row first."""
    return [((2 * c + r) * radius, radius * (1 + r * math.sqrt(3))) for r in range(rows) for c in range(rows - r)]


def _pile_index(rows: int) -> dict[tuple[int, int], int]:
    """Disk number of (row, column) in `pile_centres` order."""
    return {(r, c): k for k, (r, c) in enumerate((r, c) for r in range(rows) for c in range(rows - r))}


def pile_walls(rows: int, radius: float = BALL_RADIUS) -> tuple[Line, Line]:
    """The container's side walls: vertical lines touching the bottom row's end disks, normals inward."""
    return (Line((-radius, 0.0), -math.pi / 2), Line((2 * (rows - 1) * radius + radius, 0.0), math.pi / 2))


def disk_pile(rows: int, radius: float = BALL_RADIUS, mass: float = BALL_MASS, law: ContactLaw | None = None,
              walls: bool = True):
    """A pyramid of disks at rest on a floor, each disk on the two below it (μs, μd = 0.5, 0.4,
    e = 0 unless `law` is given), between two side walls touching the bottom row (`walls`).

    Every disk has a floor contact and, with walls, one on each wall, and every pair of disks a
    disk–disk contact: a disk that moves meets whatever it reaches (the loop's broad phase gives
    pairs out of reach no kinematics). Without walls nothing holds the bottom row together and
    the pile spreads and falls — physically, as a scene of touching disks does.
    """
    rows = _require_count("rows", rows, 1)
    require_positive("radius", radius)
    require_positive("mass", mass)
    law = law or ContactLaw.of(0.5, 0.4, 0.0)
    centres = pile_centres(rows, radius)
    n = len(centres)
    contacts = [DiskOnLine(i, (0.0, 0.0), Line(), radius, law, f"floor{i}") for i in range(n)]
    if walls:
        left, right = pile_walls(rows, radius)
        contacts += [DiskOnLine(i, (0.0, 0.0), left, radius, law, f"left{i}") for i in range(n)]
        contacts += [DiskOnLine(i, (0.0, 0.0), right, radius, law, f"right{i}") for i in range(n)]
    # upper disk first (body a), as the pile's resting contacts were always listed
    contacts += [DiskOnDisk(j, i, radius, radius, law=law, name=f"{j}/{i}") for i in range(n) for j in range(i + 1, n)]
    q0 = np.zeros(3 * n)
    q0[0::3], q0[1::3] = zip(*centres)
    return Scene(_balls(n, radius, mass), contacts), q0, np.zeros_like(q0)


def pile_resting_contacts(rows: int) -> list[str]:
    """Names of the contacts that carry the pile at rest: the bottom row's floor contacts and each
    upper disk's two contacts on the row below."""
    index = _pile_index(rows)
    names = [f"floor{index[0, c]}" for c in range(rows)]
    for (r, c), i in index.items():
        if r > 0:
            names += [f"{i}/{index[r - 1, c + k]}" for k in (0, 1)]
    return names


__all__ = ["ball_row", "disk_pile", "pile_centres", "pile_walls", "pile_resting_contacts", "BALL_RADIUS", "BALL_MASS"]
