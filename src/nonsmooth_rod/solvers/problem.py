"""The one-step nonsmooth problem of a planar time-stepping scheme.

Every integrator step reduces to the same small problem on the contact impulses of the
contacts that may act in that step (ordering per contact: normal, tangential)::

    u = W p + q,          W = Hᵀ M⁻¹ H  (Delassus matrix, symmetric positive semi-definite)
    0 ≤ p_N  ⊥  u_N ≥ 0                                         (unilateral contact, Newton law)
    lo·p_N ≤ p_T ≤ hi·p_N,  u_T > 0 ⇒ p_T = lo·p_N,  u_T < 0 ⇒ p_T = hi·p_N   (friction interval)

With lo = −μ, hi = +μ this is the ordinary planar Coulomb law. The integrator shifts the
interval, lo = c − μs, hi = c + μs with c = (μs − μd)·s, to impose the two-coefficient law
(static μs, dynamic μd) exactly; see docs/friction.md. Solvers need not know why: they solve
this generic interval law, which is monotone, so it remains an ordinary LCP.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..validation import InputError


class SolverError(RuntimeError):
    """A one-step solver could not return a solution it can vouch for."""

    def __init__(self, message: str, *, context: str = ""):
        self.base_message = message
        self.context = context
        super().__init__(f"{message} ({context})" if context else message)

    def with_context(self, context: str) -> "SolverError":
        """The same error, naming where it happened (step, time, contact states)."""
        return type(self)(self.base_message, context=context)


class RayTermination(SolverError):
    """Lemke's method ended on a secondary ray: no solution found by complementary pivoting."""


class NoConvergence(SolverError):
    """An iterative solver reached its iteration limit above its tolerance."""


class InfeasibleProblem(SolverError):
    """A QP backend declared the step's problem infeasible or failed."""


@dataclass(frozen=True)
class PlanarFrictionProblem:
    """u = W p + q with per-contact unilateral normal law and friction interval [lo·p_N, hi·p_N]."""

    W: np.ndarray
    q: np.ndarray
    lo: np.ndarray
    hi: np.ndarray

    def __post_init__(self):
        # Own copies: validated once here, they cannot turn non-finite behind the solvers'
        # back when the caller reuses its arrays.
        W = _float_array("W", self.W)
        q = _float_array("q", self.q)
        lo = np.atleast_1d(_float_array("lo", self.lo))
        hi = np.atleast_1d(_float_array("hi", self.hi))
        n = q.shape[0] if q.ndim == 1 else -1
        if n % 2 or W.shape != (n, n) or lo.shape != (n // 2,) or hi.shape != (n // 2,):
            raise InputError(
                f"inconsistent problem shapes: W {W.shape}, q {q.shape}, lo {lo.shape}, hi {hi.shape}"
            )
        for name, values in (("W", W), ("q", q), ("lo", lo), ("hi", hi)):
            _require_finite(name, values)
        if np.any(lo > 0) or np.any(hi < 0):
            raise InputError("friction interval must contain 0: lo ≤ 0 ≤ hi")
        object.__setattr__(self, "W", W)
        object.__setattr__(self, "q", q)
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)

    @property
    def n_contacts(self) -> int:
        return self.q.shape[0] // 2

    @classmethod
    def coulomb(cls, W, q, mu) -> "PlanarFrictionProblem":
        """The ordinary one-coefficient Coulomb problem |p_T| ≤ μ p_N."""
        mu = np.atleast_1d(np.asarray(mu, dtype=float))
        return cls(W, q, -mu, mu)


def _float_array(name: str, values) -> np.ndarray:
    try:
        return np.array(values, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be an array of numbers, got {values!r}") from None


def _require_finite(name: str, values: np.ndarray) -> None:
    """InputError naming the argument and its first NaN/inf entry (solvers would return NaN
    or ±inf as a "solution", or fail inside numpy)."""
    if values.size and not np.isfinite(values).all():
        index = np.unravel_index(int(np.flatnonzero(~np.isfinite(values))[0]), values.shape)
        where = int(index[0]) if len(index) == 1 else tuple(int(i) for i in index)
        raise InputError(f"{name} must be finite, got {float(values[index])!r} at index {where}")


@dataclass
class ContactSolution:
    """Impulses p, local velocities u = W p + q and how the solver got there."""

    p: np.ndarray
    u: np.ndarray
    solver: str
    iterations: int = 0
    residual: float = 0.0
    info: dict = field(default_factory=dict)

    @property
    def normal_impulse(self) -> np.ndarray:
        return self.p[0::2]

    @property
    def tangential_impulse(self) -> np.ndarray:
        return self.p[1::2]

    @property
    def normal_velocity(self) -> np.ndarray:
        return self.u[0::2]

    @property
    def slip_velocity(self) -> np.ndarray:
        return self.u[1::2]


def complementarity_residual(problem: PlanarFrictionProblem, p: np.ndarray) -> float:
    """Natural-map residual of the step law, the same for every solver.

    Normal: |min(p_N, u_N)|. Tangential: distance of p_T from its projection of
    (p_T − u_T) onto [lo p_N, hi p_N] (zero exactly when the interval law holds).
    Returned as the max-norm, in impulse/velocity units of the problem.
    """
    p = np.asarray(p, dtype=float)
    u = problem.W @ p + problem.q
    pN, pT = p[0::2], p[1::2]
    uN, uT = u[0::2], u[1::2]
    r_n = np.minimum(pN, uN)
    pN_pos = np.maximum(pN, 0.0)
    proj = np.clip(pT - uT, problem.lo * pN_pos, problem.hi * pN_pos)
    r_t = pT - proj
    return float(max(np.max(np.abs(r_n), initial=0.0), np.max(np.abs(r_t), initial=0.0)))


def residual_scale(problem: PlanarFrictionProblem, p: np.ndarray, u: np.ndarray) -> float:
    """The magnitude a `complementarity_residual` is judged against: max-norm of p, u and q.

    The residual mixes impulses and velocities (it compares p_T with p_T − u_T), so its
    natural scale is the largest of both; a relative tolerance ``tol`` on a solver's result
    means ``complementarity_residual(problem, p) ≤ tol · residual_scale(problem, p, u)``.
    """
    scale = max(
        max(map(abs, np.asarray(values, dtype=float).ravel().tolist()), default=0.0)
        for values in (p, u, problem.q)
    )
    return scale if scale > 0.0 else 1.0


# A contact's state after a step, the one definition of the codes every solver and the loop use:
# open, stick, slip+ (slip velocity u_T > 0), slip− (u_T < 0); CONTACT_STATES are their names.
STATE_OPEN, STATE_STICK, STATE_SLIP_PLUS, STATE_SLIP_MINUS = range(4)
CONTACT_STATES = ("open", "stick", "slip+", "slip-")


def contact_states(problem: PlanarFrictionProblem, p, u, tol: float = 1e-9) -> list[str]:
    """Per-contact state of a solution: "open" | "stick" | "slip+" | "slip-".

    A contact is open when its normal impulse is negligible, p_N ≤ tol·P with the impulse
    scale P = max(‖p‖∞, ‖q‖∞ / max|W|) (the second term is the impulse that stops a velocity
    ‖q‖∞, so a step whose impulses are all round-off is "open" everywhere). Otherwise it slips
    when |u_T| > tol·V with V = max(‖u‖∞, ‖q‖∞) ("slip+" means u_T > 0, so p_T = lo·p_N) and
    sticks when it does not. Every solver classifies through this one function so that states
    are comparable between solvers.
    """
    # plain floats: this runs once per solve, for 1–2 contacts, where numpy calls cost more
    p = p.tolist() if isinstance(p, np.ndarray) else [float(x) for x in p]
    u = u.tolist() if isinstance(u, np.ndarray) else [float(x) for x in u]
    q_norm = max(map(abs, problem.q.tolist()), default=0.0)
    W_norm = max(map(abs, problem.W.ravel().tolist()), default=0.0)
    return classify_contacts(p, u, q_norm, W_norm, tol)


def classify_contacts(p: list, u: list, q_norm: float, W_norm: float, tol: float = 1e-9) -> list[str]:
    """`contact_states` on float lists with ‖q‖∞ and max|W| given (solvers that know them
    already skip recomputing them; the classification is the same)."""
    impulse_scale = max(max(map(abs, p), default=0.0), q_norm / W_norm if W_norm > 0.0 else 0.0)
    velocity_scale = max(max(map(abs, u), default=0.0), q_norm)
    states = []
    for i in range(len(p) // 2):
        if p[2 * i] <= tol * impulse_scale:
            states.append("open")
        elif u[2 * i + 1] > tol * velocity_scale:
            states.append("slip+")
        elif u[2 * i + 1] < -tol * velocity_scale:
            states.append("slip-")
        else:
            states.append("stick")
    return states
