"""A scene: bodies, their contacts, gravity and any other applied force."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from ..validation import InputError, quoted, require_finite, require_name, require_point
from .body import RigidBody

AppliedForce = Callable[[float, np.ndarray, np.ndarray], np.ndarray]


def gravity_vector(gravity) -> tuple[float, float]:
    """(gx, gy) of a scene's `gravity`: a number g ≥ 0 means (0, −g); a pair is the vector."""
    if isinstance(gravity, (list, tuple, np.ndarray)):
        return require_point("gravity", gravity)
    g = require_finite("g", gravity)
    if g < 0:
        raise InputError(f"g must be non-negative (or give the vector (gx, gy)), got {quoted(gravity)}")
    return (0.0, -g)


@dataclass
class Scene:
    """Planar rigid bodies with contacts.

    q and v stack (x, y, θ) and (ẋ, ẏ, θ̇) of every body's centre of mass. `applied_force`,
    if given, returns the generalised force (forces on the centre of mass, torque) besides gravity.
    """

    bodies: Sequence[RigidBody]
    contacts: Sequence = ()
    gravity: float | tuple[float, float] = 9.81  # g downward (−y), or the vector (gx, gy)
    applied_force: AppliedForce | None = None
    forces: Sequence = ()  # model.forces: Spring, Damper, ConstantForce, RampedForce, TabulatedForce
    driven: Sequence = ()  # model.motion.DrivenBody: bodies whose placement is prescribed in time
    joints: Sequence = ()  # model.joints: Pin, Slider

    def __post_init__(self):
        self.gravity_vector = gravity_vector(self.gravity)
        if not self.bodies:
            raise InputError("a scene needs at least one body")
        self.bodies = list(self.bodies)
        self.contacts = list(self.contacts)
        from .forces import FORCE_TYPES  # here: forces.py imports the jit decorator

        self.forces = list(self.forces)
        for i, force in enumerate(self.forces):
            if not isinstance(force, FORCE_TYPES):
                raise InputError(f"forces[{i}] must be a Spring, Damper, ConstantForce, RampedForce, "
                                 f"TabulatedForce or TorsionSpring, got {type(force).__name__}")
        self.joints = list(self.joints)
        self._check_references()
        self._check_driven()
        self._check_joints()
        self.mass_diagonal = np.concatenate([b.mass_matrix_diagonal for b in self.bodies])
        self.inverse_mass_diagonal = 1.0 / self.mass_diagonal
        self.weight = np.zeros(self.n_dof)
        self.weight[0::3] = self.gravity_vector[0] * self.mass_diagonal[0::3]
        self.weight[1::3] = self.gravity_vector[1] * self.mass_diagonal[0::3]

    def _check_references(self) -> None:
        """Every contact names bodies that exist; contact names are unique (phases are keyed by them)."""
        if self.applied_force is not None and not callable(self.applied_force):
            raise InputError(f"applied_force must be a callable (t, q, v) -> force, got {self.applied_force!r}")
        for body in self.bodies:
            if not isinstance(body, RigidBody):
                raise InputError(f"scene bodies must be RigidBody, got {type(body).__name__}")
            require_name("a body's name", body.name)
        seen = set()
        for contact in self.contacts:
            if not hasattr(contact, "bodies") or not hasattr(contact, "kinematics"):
                from .contacts import RELATION_NAMES

                raise InputError(f"scene contacts must be contact relations ({', '.join(RELATION_NAMES)}), "
                                 f"got {type(contact).__name__}")
            for body in contact.bodies:
                if body >= len(self.bodies):
                    raise InputError(f"contact {contact.name!r} refers to body {body}, but the scene has "
                                     f"{len(self.bodies)} bodies (0 to {len(self.bodies) - 1})")
            require_name("a contact's name", contact.name)  # it heads CSV columns: no newline in it
            if contact.name in seen:
                raise InputError(f"two contacts are named {contact.name!r}: contact names must be unique")
            seen.add(contact.name)
        for i, force in enumerate(self.forces):
            require_name(f"forces[{i}] name", force.name)
            for attr in ("body", "body_a", "body_b"):
                body = getattr(force, attr, None)
                if body is not None and body >= len(self.bodies):
                    raise InputError(f"forces[{i}] ({force.name!r}) {attr} refers to body {body}, but the scene "
                                     f"has {len(self.bodies)} bodies")

    def _check_driven(self) -> None:
        from .motion import DrivenBody

        self.driven = list(self.driven)
        seen = set()
        for i, d in enumerate(self.driven):
            if not isinstance(d, DrivenBody):
                raise InputError(f"driven[{i}] must be a DrivenBody(body, motion), got {type(d).__name__}")
            if d.body >= len(self.bodies) or d.body in seen:
                raise InputError(f"driven[{i}]: body {d.body} is beyond the scene's {len(self.bodies)} bodies "
                                 f"or driven twice")
            seen.add(d.body)

    def driven_things(self) -> list[str]:
        """Names of what moves by a prescribed motion: driven obstacles' contacts and driven bodies."""
        names = [f"contact {c.name!r}" for c in self.contacts if getattr(c, "obstacle_motion", None) is not None]
        return names + [f"body {self.bodies[d.body].name!r}" for d in self.driven]

    def _check_joints(self) -> None:
        """Joints are Pin, Slider or LinearJoint on bodies that exist, with unique names."""
        from .joints import JOINT_TYPES

        seen = set()
        for i, joint in enumerate(self.joints):
            if not isinstance(joint, JOINT_TYPES):
                raise InputError(f"joints[{i}] must be a Pin, a Slider or a LinearJoint, got {type(joint).__name__}")
            require_name(f"joints[{i}] name", joint.name)
            if joint.name in seen:
                raise InputError(f"two joints are named {joint.name!r}: joint names must be unique")
            seen.add(joint.name)
            for attr in ("body_a", "body_b"):
                body = getattr(joint, attr)
                if body is not None and body >= len(self.bodies):
                    raise InputError(f"joint {joint.name!r} {attr} refers to body {body}, but the scene has "
                                     f"{len(self.bodies)} bodies")

    def forces_vary_in_time(self) -> bool:
        """True when the applied force may change while the state does not (a Python
        `applied_force`, a RampedForce or a TabulatedForce) or an obstacle or body is driven:
        a body at rest need not stay so."""
        from .forces import RampedForce, TabulatedForce

        return self.applied_force is not None or any(isinstance(f, (RampedForce, TabulatedForce))
                                                     for f in self.forces) or bool(self.driven_things())

    @property
    def n_dof(self) -> int:
        return 3 * len(self.bodies)

    def force(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Gravity + the `forces` + the `applied_force` callable at (t, q, v)."""
        total = self.weight
        for force in self.forces:
            total = total + force.generalised_force(t, q, v, self.n_dof)
        if self.applied_force is not None:
            total = total + self.applied(t, q, v)
        return total

    def applied(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The `applied_force` callable at (t, q, v), checked: n_dof finite numbers."""
        force = np.asarray(self.applied_force(t, q, v), dtype=float)
        if force.shape != self.weight.shape:
            raise InputError(f"applied_force must return {self.n_dof} numbers (fx, fy, torque per body), "
                             f"got shape {force.shape} at t = {t:g} s")
        return force

    def kinematics(self, q: np.ndarray, v: np.ndarray):
        q_list, v_list = np.asarray(q, dtype=float).tolist(), np.asarray(v, dtype=float).tolist()  # once for all
        return [c.kinematics(q_list, v_list, self.n_dof) for c in self.contacts]

    def kinetic_energy(self, v: np.ndarray) -> float:
        return 0.5 * float(np.dot(self.mass_diagonal * v, v))

    def potential_energy(self, q: np.ndarray) -> float:
        """−Σ m g·x over the bodies' centres of mass (m g y for gravity g downward)."""
        gx, gy = self.gravity_vector
        m = self.mass_diagonal[0::3]
        return -(gx * float(np.dot(m, q[0::3])) + gy * float(np.dot(m, q[1::3])))

    def energy(self, q: np.ndarray, v: np.ndarray) -> float:
        """Kinetic + gravitational energy (applied forces are not included)."""
        return self.kinetic_energy(v) + self.potential_energy(q)
