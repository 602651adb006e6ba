"""Nonsmooth contact laws: Newton impact and two-coefficient Coulomb friction."""
from __future__ import annotations

from dataclasses import dataclass

from ..validation import require_friction_pair, require_in_range


@dataclass(frozen=True)
class NewtonImpact:
    """Newton's restitution law at velocity level: u_N⁺ = −e u_N⁻ when the contact is closed."""

    restitution: float = 0.0

    def __post_init__(self):
        require_in_range("restitution", self.restitution, 0.0, 1.0)


@dataclass(frozen=True)
class CoulombFriction:
    """Coulomb friction with a static (stick) and a dynamic (slip) coefficient, 0 ≤ μd ≤ μs.

    Sticking holds any |T| ≤ μs N; sliding feels T = −μd N sgn(v_T).
    """

    mu_s: float
    mu_d: float | None = None

    def __post_init__(self):
        mu_d = self.mu_s if self.mu_d is None else self.mu_d
        mu_s, mu_d = require_friction_pair(self.mu_s, mu_d)
        object.__setattr__(self, "mu_s", mu_s)
        object.__setattr__(self, "mu_d", mu_d)

    @property
    def frictionless(self) -> bool:
        return self.mu_s == 0.0


@dataclass(frozen=True)
class ContactLaw:
    """What a contact obeys: an impact law normally, a friction law tangentially."""

    impact: NewtonImpact = NewtonImpact()
    friction: CoulombFriction = CoulombFriction(0.0, 0.0)

    @classmethod
    def of(cls, mu_s: float = 0.0, mu_d: float | None = None, restitution: float = 0.0) -> "ContactLaw":
        return cls(NewtonImpact(restitution), CoulombFriction(mu_s, mu_d))
