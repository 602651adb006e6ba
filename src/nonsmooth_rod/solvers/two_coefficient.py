"""Two-coefficient Coulomb friction as a sequence of ordinary one-step problems.

The exact law (sgn(0) = 0) splits as  T ∈ −μs N Sign(v_T) + (μs − μd) N sgn(v_T): a monotone
Coulomb part with μs plus a single-valued part. For a guessed slip sign s of each contact
the single-valued part is the shift c = (μs − μd) s of the friction interval,

    p_T ∈ [(c − μs) p_N, (c + μs) p_N],

which keeps the step an ordinary LCP (PlanarFrictionProblem). The guess is then checked against
the slip velocity the step produced, and the step is solved again with the corrected signs
(a wrong slip sign first falls back to 0, the ordinary μs problem, and only then to the sign
the contact slid with) until the impulses obey the exact law at the end-of-step velocity:

    u_T > 0 ⇒ p_T = −μd p_N,   u_T < 0 ⇒ p_T = +μd p_N,   u_T = 0 ⇒ |p_T| ≤ μs p_N.

Because stick is accepted under any guess whenever |p_T| ≤ μs p_N, a sliding contact that comes
to rest re-sticks in the very step in which μs can hold it, whatever h is: this is what the
naive "μd if it slid last step" rule gets wrong. Once consistent, a contact that started the step
at rest and slides is held instead if any admissible impulse split of the step can hold it
(sticking.prefer_sticking: statically indeterminate contacts). See docs/friction.md.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import solvers as _solvers
from .problem import PlanarFrictionProblem, SolverError
from .sticking import STATE_OPEN, STATE_SLIP_MINUS, STATE_SLIP_PLUS, STATE_STICK, prefer_sticking


@dataclass
class StepContactResult:
    p: np.ndarray
    u: np.ndarray
    states: list[str]  # per contact: open / stick / slip+ / slip-
    slip_signs: np.ndarray  # the converged guess s per contact (0, ±1)
    solves: int
    iterations: int
    residual: float
    consistent: bool


def classify(p: np.ndarray, u: np.ndarray, mu_s: np.ndarray, velocity_tol: float,
             impulse_tol: float) -> tuple[list[str], np.ndarray, np.ndarray]:
    """Contact states of a step solution, the slip signs they imply, and their consistency."""
    n = len(mu_s)
    states = []
    signs = np.zeros(n)
    consistent = np.ones(n, dtype=bool)
    for i in range(n):
        pN, pT, uT = p[2 * i], p[2 * i + 1], u[2 * i + 1]
        if pN <= impulse_tol:
            states.append("open")
            continue
        if uT > velocity_tol:
            states.append("slip+")
            signs[i] = 1.0
        elif uT < -velocity_tol:
            states.append("slip-")
            signs[i] = -1.0
        else:
            states.append("stick")
            # Sticking is admissible only inside the static cone; otherwise the contact slips
            # against the friction it could not supply.
            if abs(pT) > mu_s[i] * pN * (1 + 1e-9) + impulse_tol:
                consistent[i] = False
                signs[i] = -np.sign(pT)
    return states, signs, consistent


_STATE_CODES = {"open": STATE_OPEN, "stick": STATE_STICK, "slip+": STATE_SLIP_PLUS, "slip-": STATE_SLIP_MINUS}
_STATE_NAMES = ("open", "stick", "slip+", "slip-")


def _hold_what_mu_s_can_hold(W, q, mu_s, mu_d, start_guess, velocity_tol, closing,
                             result: StepContactResult) -> None:
    """A contact that started at rest slides only if no admissible split holds it (sticking.py):
    replace `result` by the solution that holds the most of them, when the step has one."""
    if not any(s != "stick" and g == 0.0 for s, g in zip(result.states, start_guess)):
        return  # no contact that started at rest moves: nothing to hold (the common step)
    closing = np.zeros(len(mu_s)) if closing is None else np.asarray(closing, dtype=float)
    codes = np.array([_STATE_CODES[s] for s in result.states], dtype=np.int64)
    p, u = np.array(result.p, dtype=float), np.array(result.u, dtype=float)
    if prefer_sticking(np.ascontiguousarray(W, dtype=float), np.ascontiguousarray(q, dtype=float), mu_s, mu_d,
                       np.array(start_guess, dtype=float), float(velocity_tol), closing, p, u, codes):
        result.p, result.u = p, u
        result.states = [_STATE_NAMES[c] for c in codes]
        result.slip_signs = np.where(codes == STATE_SLIP_PLUS, 1.0, np.where(codes == STATE_SLIP_MINUS, -1.0, 0.0))


def solve_two_coefficient(W: np.ndarray, q: np.ndarray, mu_s: np.ndarray, mu_d: np.ndarray,
                          slip_guess: np.ndarray, solver: str = "lemke", solver_options: dict | None = None,
                          max_solves: int = 6, closing: np.ndarray | None = None) -> StepContactResult:
    """Solve u = W p + q under the exact two-coefficient law, starting from `slip_guess`.

    `closing` (per contact, default 0): the gap-closing velocity g/h included in q_N, which a
    held statically indeterminate body may leave unclosed (sticking.prefer_sticking)."""
    mu_s = np.asarray(mu_s, dtype=float)
    mu_d = np.asarray(mu_d, dtype=float)
    guess = np.array(slip_guess, dtype=float)
    scale_v = max(1e-12, float(np.max(np.abs(q))))
    velocity_tol = 1e-9 * scale_v
    tried = set()
    iterations = 0
    best = None
    for solves in range(1, max_solves + 1):
        key = tuple(guess)
        tried.add(key)
        shift = (mu_s - mu_d) * guess
        problem = PlanarFrictionProblem(W, q, shift - mu_s, shift + mu_s)
        sol = _solvers.solve(problem, solver, **(solver_options or {}))
        iterations += sol.iterations
        p, u = sol.p, sol.u
        scale_p = max(1e-300, float(np.max(np.abs(p))))
        # A slip velocity within the solver's own accuracy is zero (iterative and QP
        # solvers leave residuals of 1e-12..1e-9; Lemke's is round-off).
        step_velocity_tol = max(velocity_tol, 10.0 * sol.residual)
        states, implied, ok = classify(p, u, mu_s, step_velocity_tol, 1e-12 * scale_p)
        # A guess is consistent for a contact when the step slid the way the guess said, or
        # stuck inside the static cone (any guess), or opened.
        for i, st in enumerate(states):
            if st in ("slip+", "slip-") and implied[i] != guess[i]:
                ok[i] = False
        best = StepContactResult(p, u, states, guess.copy(), solves, iterations, sol.residual, bool(ok.all()))
        if ok.all():
            _hold_what_mu_s_can_hold(W, q, mu_s, mu_d, slip_guess, step_velocity_tol, closing, best)
            return best
        # A wrong non-zero guess falls back to 0 (the ordinary μs problem, where sticking is
        # tried first); only a contact that slides even then takes the sign it slid with.
        # Jumping straight from one slip sign to the other could skip an admissible stick.
        new_guess = guess.copy()
        for i in range(len(guess)):
            if not ok[i]:
                new_guess[i] = 0.0 if guess[i] != 0.0 else implied[i]
        if tuple(new_guess) in tried:
            break
        guess = new_guess
    # Cycling between guesses (possible only with several interacting contacts): keep the
    # ordinary μs solution, which is exact for sticking, and let the caller count it.
    if best is not None and not best.consistent:
        zero = np.zeros_like(guess)
        if tuple(zero) not in tried:
            problem = PlanarFrictionProblem(W, q, -mu_s, mu_s)
            sol = _solvers.solve(problem, solver, **(solver_options or {}))
            states, implied, _ = classify(sol.p, sol.u, mu_s, max(velocity_tol, 10.0 * sol.residual),
                                          1e-12 * max(1e-300, np.max(np.abs(sol.p))))
            best = StepContactResult(sol.p, sol.u, states, zero, best.solves + 1,
                                     iterations + sol.iterations, sol.residual, False)
    return best


__all__ = ["solve_two_coefficient", "StepContactResult", "classify", "SolverError"]
