"""Applied forces of a scene file, built by kind name: the one place that knows the force classes.

The force classes (Spring, Damper, ConstantForce, RampedForce, TabulatedForce) belong to
`nonsmooth_rod.model.forces` (API.md). Until that module is in this branch, small stand-ins with
the same constructor signatures and `generalised_force(t, q, v, n_dof)` are used, and the scene
gets them as one `applied_force` callable. Delete `_StandIn*` once model/forces.py has landed.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from .model.body import cross2, rotate
from .model.scene import Scene

try:  # the engine's force classes, once merged
    from .model import forces as _forces
except ImportError:  # pragma: no cover - depends on the merge state
    _forces = None

FORCE_KINDS = ("spring", "damper", "constant", "ramped", "tabulated")


def _world_point(q, v, body, point):
    """World position and velocity of a body-frame point (relative to the centre of mass)."""
    i = 3 * body
    d = rotate(q[i + 2], point)
    om = v[i + 2]
    return (q[i] + d[0], q[i + 1] + d[1]), (v[i] - om * d[1], v[i + 1] + om * d[0]), d


def _apply(f, body, lever, force, torque=0.0):
    i = 3 * body
    f[i] += force[0]
    f[i + 1] += force[1]
    f[i + 2] += cross2(lever, force) + torque


@dataclass(frozen=True)
class _StandInSpring:
    body_a: int
    point_a: tuple = (0.0, 0.0)
    body_b: int | None = None
    point_b: tuple = (0.0, 0.0)
    stiffness: float = 0.0
    rest_length: float = 0.0
    damping: float = 0.0
    name: str = "spring"

    def generalised_force(self, t, q, v, n_dof):
        f = np.zeros(n_dof)
        pa, va, la = _world_point(q, v, self.body_a, self.point_a)
        if self.body_b is None:
            pb, vb, lb = tuple(self.point_b), (0.0, 0.0), None
        else:
            pb, vb, lb = _world_point(q, v, self.body_b, self.point_b)
        dx, dy = pb[0] - pa[0], pb[1] - pa[1]
        length = math.hypot(dx, dy)
        if length == 0.0:
            return f
        e = (dx / length, dy / length)  # from a towards b
        rate = (vb[0] - va[0]) * e[0] + (vb[1] - va[1]) * e[1]  # dℓ/dt
        tension = self.stiffness * (length - self.rest_length) + self.damping * rate
        _apply(f, self.body_a, la, (tension * e[0], tension * e[1]))
        if lb is not None:
            _apply(f, self.body_b, lb, (-tension * e[0], -tension * e[1]))
        return f


def _stand_in_damper(body_a, point_a=(0.0, 0.0), body_b=None, point_b=(0.0, 0.0), damping=0.0, name="damper"):
    return _StandInSpring(body_a, point_a, body_b, point_b, 0.0, 0.0, damping, name)


@dataclass(frozen=True)
class _StandInRamped:
    body: int
    force: tuple = (0.0, 0.0)
    torque: float = 0.0
    point: tuple = (0.0, 0.0)
    t_start: float = -math.inf
    t_full: float = -math.inf
    name: str = "ramp"

    def scale(self, t):
        if t >= self.t_full:
            return 1.0
        return min(max((t - self.t_start) / (self.t_full - self.t_start), 0.0), 1.0)

    def generalised_force(self, t, q, v, n_dof):
        f = np.zeros(n_dof)
        s = self.scale(t)
        lever = rotate(q[3 * self.body + 2], self.point)
        _apply(f, self.body, lever, (s * self.force[0], s * self.force[1]), s * self.torque)
        return f


def _stand_in_constant(body, force=(0.0, 0.0), torque=0.0, point=(0.0, 0.0), name="force"):
    return _StandInRamped(body, tuple(force), torque, tuple(point), name=name)


@dataclass(frozen=True)
class _StandInTabulated:
    body: int
    times: tuple = ()
    forces: tuple = ()
    torques: tuple | None = None
    point: tuple = (0.0, 0.0)
    name: str = "table"

    def generalised_force(self, t, q, v, n_dof):
        f = np.zeros(n_dof)
        ts = np.asarray(self.times, dtype=float)
        table = np.asarray(self.forces, dtype=float).reshape(-1, 2)
        force = (float(np.interp(t, ts, table[:, 0])), float(np.interp(t, ts, table[:, 1])))
        torque = 0.0 if self.torques is None else float(np.interp(t, ts, np.asarray(self.torques, float)))
        _apply(f, self.body, rotate(q[3 * self.body + 2], self.point), force, torque)
        return f


def _classes() -> dict:
    if _forces is not None:
        return {"spring": _forces.Spring, "damper": _forces.Damper, "constant": _forces.ConstantForce,
                "ramped": _forces.RampedForce, "tabulated": _forces.TabulatedForce}
    return {"spring": _StandInSpring, "damper": _stand_in_damper, "constant": _stand_in_constant,
            "ramped": _StandInRamped, "tabulated": _StandInTabulated}


def build_force(kind: str, **fields):
    """A force of `kind` (one of FORCE_KINDS) from the constructor's keyword fields."""
    return _classes()[kind](**fields)


def make_scene(bodies, contacts, gravity: float, forces=()) -> Scene:
    """A Scene with applied forces as data (`forces=`) where Scene takes them, else as one callable."""
    forces = list(forces)
    if any(f.name == "forces" for f in dataclasses.fields(Scene)):
        return Scene(bodies, contacts, gravity=gravity, forces=forces)
    if not forces:
        return Scene(bodies, contacts, gravity=gravity)
    n_dof = 3 * len(bodies)

    def applied(t, q, v):
        return sum(f.generalised_force(t, q, v, n_dof) for f in forces)

    applied.forces = forces  # keep them findable (drawing, summaries)
    return Scene(bodies, contacts, gravity=gravity, applied_force=applied)
