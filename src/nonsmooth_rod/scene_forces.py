"""Applied forces of a scene file, built by kind name: the one place that maps the file's
`kind = "spring" | "damper" | "torsion-spring" | "constant" | "torque" | "ramped" | "tabulated"` to
the force classes of `nonsmooth_rod.model.forces`, which the compiled engine evaluates as data."""
from __future__ import annotations

from .model.forces import ConstantForce, Damper, RampedForce, Spring, TabulatedForce, Torque, TorsionSpring
from .model.scene import Scene

FORCE_CLASSES = {"spring": Spring, "damper": Damper, "constant": ConstantForce, "ramped": RampedForce,
                 "tabulated": TabulatedForce, "torsion-spring": TorsionSpring, "torque": Torque}
FORCE_KINDS = tuple(FORCE_CLASSES)


def build_force(kind: str, **fields):
    """A force of `kind` (one of FORCE_KINDS) from the constructor's keyword fields."""
    return FORCE_CLASSES[kind](**fields)


def make_scene(bodies, contacts, gravity, forces=(), driven=(), joints=()) -> Scene:
    """A Scene with its applied forces and joints as data (and its driven bodies, model/motion.py)."""
    return Scene(bodies, contacts, gravity=gravity, forces=list(forces), driven=list(driven), joints=list(joints))
