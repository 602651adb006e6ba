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
naive "μd if it slid last step" rule gets wrong. See docs/friction.md.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import solvers as _solvers
from .._jit import jit, jit_borrowing, jit_inline
# The solver call point: the compiled kernels (registry.SOLVERS with a code); the QP solvers stay
# Python (solve_two_coefficient below).
from .kernels import (KERNEL_NO_CONVERGENCE, KERNEL_SOLVED, carve, carve_matrix, fits_scratch, fitting_scratch,
                      lemke_interval, pgs_block_into, solve_interval_into, solver_floats, solver_ints)
from .gauss_seidel import PGS_FLOATS
from .one_contact import one_contact_into
from ._common import interpreted, loop_array, python_body
from .problem import (CONTACT_STATES, STATE_OPEN, STATE_SLIP_MINUS, STATE_SLIP_PLUS, STATE_STICK,  # noqa: F401
                      PlanarFrictionProblem, SolverError)
from .registry import DEFAULT_SOLVER
from .delassus import blocks_to_dense, coupled_components, group_matrix
from .sticking import gather_contacts, prefer_sticking_by_group, scatter_contacts

STATE_NAMES = CONTACT_STATES  # (the codes' names, problem.py)
# What the sign iteration does after a solve that was not consistent.
NEXT_RETRY, NEXT_TRY_ZERO, NEXT_STOP = 0, 1, 2
MAX_SOLVES = 6
# Floats per contact the sign iteration carves before the solver's part (two_coefficient_into:
# the start guess, the warm start's two, lo, hi, the new guess, MAX_SOLVES + 1 tried guesses).
SIGN_ITERATION_FLOATS = 6 + MAX_SOLVES + 1


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


@jit_inline
def classify_solution(p, u, residual, mu_s, guess, velocity_tol, states, new_guess):
    """States of a step solution under slip guess `guess`; True when the guess is consistent.

    A contact is consistent when it opened, slid the way the guess said, or stuck inside the
    static cone (under any guess). An inconsistent contact's new guess: a wrong non-zero guess
    falls back to 0 (the ordinary μs problem, where sticking is tried first); only a contact that
    slides even then takes the sign it slid with (or, sticking outside the cone, the sign that
    opposes its friction). Jumping from one slip sign to the other could skip an admissible stick.
    """
    # A slip velocity within the solver's own accuracy is zero (iterative solvers leave
    # residuals of 1e-12..1e-9; Lemke's is round-off).
    v_tol = max(velocity_tol, 10.0 * residual)
    scale_p = 1e-300
    for r in range(p.shape[0]):
        scale_p = max(scale_p, abs(p[r]))
    p_tol = 1e-12 * scale_p
    consistent = True
    for j in range(guess.shape[0]):
        p_n, p_t, u_t = p[2 * j], p[2 * j + 1], u[2 * j + 1]
        implied = guess[j]
        outside_cone = False
        if p_n <= p_tol:
            states[j] = STATE_OPEN
        elif u_t > v_tol:
            states[j] = STATE_SLIP_PLUS
            implied = 1.0
        elif u_t < -v_tol:
            states[j] = STATE_SLIP_MINUS
            implied = -1.0
        else:
            states[j] = STATE_STICK
            if abs(p_t) > mu_s[j] * p_n * (1 + 1e-9) + p_tol:  # outside the static cone
                outside_cone = True
                implied = -1.0 if p_t > 0.0 else (1.0 if p_t < 0.0 else 0.0)
        new_guess[j] = guess[j]
        if outside_cone or implied != guess[j]:
            consistent = False
            new_guess[j] = 0.0 if guess[j] != 0.0 else implied
    return consistent


@jit_borrowing
def _seen(tried, n_tried, guess):
    for k in range(n_tried):
        same = True
        for j in range(guess.shape[0]):
            if tried[k, j] != guess[j]:
                same = False
        if same:
            return True
    return False


@jit_borrowing
def next_action(new_guess, tried, n_tried):
    """After an inconsistent solve: retry with new_guess, or — cycling between guesses (possible
    only with several interacting contacts) or out of solves — solve the ordinary μs problem
    once (exact for sticking; the caller counts the step as inconsistent), or stop."""
    if n_tried < tried.shape[0] - 1 and not _seen(tried, n_tried, new_guess):
        return NEXT_RETRY
    for j in range(new_guess.shape[0]):
        new_guess[j] = 0.0
    return NEXT_STOP if _seen(tried, n_tried, new_guess) else NEXT_TRY_ZERO


@jit_inline
def _interval_of(mu_s, mu_d, guess, lo, hi):
    """The friction interval [c − μs, c + μs], c = (μs − μd) s, of slip guess s."""
    for j in range(guess.shape[0]):
        shift = (mu_s[j] - mu_d[j]) * guess[j]
        lo[j] = shift - mu_s[j]
        hi[j] = shift + mu_s[j]


# Statically indeterminate holds are searched on a dense W per group of coupled contacts; a
# group larger than this (a pile of hundreds of disks) keeps the solver's split.
MAX_DENSE_HOLD = 64
# pgs steps of at most this many active contacts that Gauss–Seidel cannot finish are solved
# again by Lemke on the dense W (a rare step: its W of (2 × 256)² floats is 2 MB). With the
# limit at MAX_DENSE_HOLD, the heap of 50 boxes (toys.BoxHeap, seed 1) stopped at t = 0.261 s
# on a step of more active contacts that Gauss–Seidel could not finish.
MAX_LEMKE_FALLBACK = 256


@jit
def pgs_scratch_sizes(n_contacts):
    """(floats, int64s) two_coefficient_into takes on a block-sparse W of up to n_contacts active
    contacts: the sign iteration's, then pgs's (the stall history, one int per contact) or its
    fallback's (the dense W and Lemke's scratch, up to MAX_LEMKE_FALLBACK contacts: np.empty, so
    the pages of a fallback that never comes are never touched). What the loop's per-run scratch
    holds for pgs (moreau_jean_loop.step_scratch), whatever the active set."""
    m = min(n_contacts, MAX_LEMKE_FALLBACK)
    floats = SIGN_ITERATION_FLOATS * n_contacts + max(PGS_FLOATS, 4 * m * m + solver_floats(m))
    return floats, max(n_contacts, solver_ints(m))


def pgs_or_lemke(indptr, indices, blocks, q, lo, hi, p, u, rtol, max_iter, fallback):
    """pgs_or_lemke_into with scratch of its own, allocated here (callers outside the step): the
    loop's compiled kernel with the loop's argument types (_common.loop_array)."""
    n_floats, n_ints = pgs_scratch_sizes(lo.shape[0])
    return pgs_or_lemke_into(loop_array(indptr, np.int64), loop_array(indices, np.int64), loop_array(blocks),
                             loop_array(q), loop_array(lo), loop_array(hi), p, u, float(rtol), int(max_iter),
                             bool(fallback), np.empty(n_floats), np.empty(n_ints, dtype=np.int64))


@jit_borrowing
def pgs_or_lemke_into(indptr, indices, blocks, q, lo, hi, p, u, rtol, max_iter, fallback, floats, ints):
    """pgs on the block-sparse W; with `fallback`, a step it cannot solve with at most
    MAX_LEMKE_FALLBACK contacts is solved again by Lemke on the dense W. Gauss–Seidel can stall on a
    singular W (a pile: many coupled contacts, q a little outside W's range) just above its
    acceptance, where Lemke's pivoting is exact. Returns (status, sweeps + pivots, residual,
    1 if it fell back else 0). In the scratch (floats, ints: the solver's part of pgs_scratch_sizes
    — the dense W and Lemke's buffers of the fallback included); borrowing: it allocates nothing."""
    status, sweeps, residual = pgs_block_into(indptr, indices, blocks, q, lo, hi, p, u, rtol, max_iter, floats, ints)
    na = lo.shape[0]
    if not fallback or status != KERNEL_NO_CONVERGENCE or na > MAX_LEMKE_FALLBACK:
        return status, sweeps, residual, 0
    if floats.shape[0] < 4 * na * na + solver_floats(na) or ints.shape[0] < solver_ints(na):
        return status, sweeps, residual, 0  # (a caller's scratch without room for it: pgs's answer stands)
    W, at = carve_matrix(floats, 0, 2 * na, 2 * na)  # the whole W, dense
    blocks_to_dense(indptr, indices, blocks, W)
    status, pivots, residual = lemke_interval(W, q, lo, hi, p, u, 0.0, 0, floats[at:], ints)  # Lemke's own acceptance
    return status, sweeps + pivots, residual, 1


@jit
def _defaults(rtol, max_iter):
    """pgs runs under its default settings: a user's own tol or max_iter has no Lemke behind it."""
    return rtol <= 0.0 and max_iter <= 0


@jit_inline
def _solve(solver_code, W, indptr, indices, blocks, q, lo, hi, p, u, rtol, max_iter, floats, ints):
    """solve_interval_into on the dense W, or pgs_or_lemke_into when the block-sparse W is given
    (indptr), in the scratch floats, ints. Returns (status, iterations, residual, 1 if pgs fell back
    to Lemke else 0). A group of one contact whose answer is unique takes it in closed form
    (one_contact.py: every exact solver's answer, without Lemke's tableau): 0 iterations."""
    residual = one_contact_into(W, blocks, q, lo, hi, p, u)
    if residual >= 0.0:
        return KERNEL_SOLVED, 0, residual, 0
    if indptr.shape[0] > 0:
        return pgs_or_lemke_into(indptr, indices, blocks, q, lo, hi, p, u, rtol, max_iter, _defaults(rtol, max_iter),
                                 floats, ints)
    status, iterations, residual = solve_interval_into(solver_code, W, q, lo, hi, p, u, rtol, max_iter, floats, ints)
    return status, iterations, residual, 0


@jit
def _guess_of_states(states, guess):
    for i in range(states.shape[0]):
        guess[i] = 1.0 if states[i] == STATE_SLIP_PLUS else (-1.0 if states[i] == STATE_SLIP_MINUS else 0.0)


@jit_inline
def hold_at_rest(W, indptr, indices, blocks, q, mu_s, mu_d, start_guess, resting, velocity_tol, closing, p, u,
                 states, p_start):
    """Hold what μs can hold (sticking.prefer_sticking, group by group of coupled contacts) when a
    contact that started the step at rest — slip velocity round-off at the step's start
    (`resting` 1), slip guess 0 — does not stick; True when p, u, states were replaced. The
    common step returns at once (borrowing: it counts and allocates nothing). A contact that was
    already sliding (or grazing a rolling neighbour) keeps the solver's answer: the search costs
    milliseconds on rows of balls and has nothing to hold there. Groups of more than MAX_DENSE_HOLD
    contacts keep the solver's split. p_start: the previous step's impulses (the warm start), or empty."""
    if not hold_decision_pending(start_guess, resting, velocity_tol, closing, u, states):
        return False  # the common step, and a pile at rest with unloaded contacts: nothing to search
    return _hold_search(W, indptr, indices, blocks, q, mu_s, mu_d, start_guess, resting, velocity_tol, closing, p, u,
                        states, p_start)


@jit_borrowing
def hold_decision_pending(start_guess, resting, velocity_tol, closing, u, states):
    """Has the hold search anything to decide? It runs when a contact that started the step at rest
    does not stick, and it can only change the answer when such a contact moves: slides while
    touching (|u_T| above the slip tolerance) or lifted off (open, u_N above it, and not merely
    closing its gap) — sticking.prefer_sticking_from returns the solver's answer otherwise
    (`_resting_contacts` finds no moving candidate). A contact that touches without load (p = 0,
    u = 0 within the tolerance: the unloaded pairs of a pile at rest) and every contact that
    sticks leave nothing to decide: this test, in the step's arrays (allocates nothing), skips
    the search's set-up then — the same answer, bit for bit."""
    not_stuck, moving = False, False
    for i in range(states.shape[0]):
        if resting[i] <= 0.0 or start_guess[i] != 0.0:
            continue
        not_stuck = not_stuck or states[i] != STATE_STICK
        touching = abs(u[2 * i]) <= velocity_tol or abs(u[2 * i] - closing[i]) <= velocity_tol
        if touching:
            moving = moving or abs(u[2 * i + 1]) > velocity_tol
        else:
            moving = moving or states[i] == STATE_OPEN
    return not_stuck and moving


@jit
def _hold_search(W, indptr, indices, blocks, q, mu_s, mu_d, start_guess, resting, velocity_tol, closing, p, u,
                 states, p_start):
    """hold_at_rest's search (counted: it allocates)."""
    na = mu_s.shape[0]
    at_rest = np.empty(na)
    for i in range(na):
        at_rest[i] = start_guess[i] if resting[i] > 0.0 else 2.0  # 2: not a candidate
    return prefer_sticking_by_group(W, indptr, indices, blocks, q, mu_s, mu_d, at_rest, velocity_tol, closing, p,
                                    u, states, MAX_DENSE_HOLD, p_start)


def two_coefficient_kernel(solver_code, W, indptr, indices, blocks, q, mu_s, mu_d, guess, closing, resting, rtol,
                           max_iter, p, u, states):
    """two_coefficient_into with scratch of its own (Lemke's, or pgs's with its fallback), allocated
    here: Python runs the loop's compiled kernel with the loop's argument types (_common.loop_array;
    guess, p, u, states are filled in place: the caller's float64 and int64 arrays)."""
    na = guess.shape[0]
    n_floats, n_ints = pgs_scratch_sizes(na) if indptr.shape[0] > 0 else (solver_floats(na), solver_ints(na))
    return two_coefficient_into(int(solver_code), loop_array(W), loop_array(indptr, np.int64),
                                loop_array(indices, np.int64), loop_array(blocks), loop_array(q), loop_array(mu_s),
                                loop_array(mu_d), guess, loop_array(closing), loop_array(resting), float(rtol),
                                int(max_iter), p, u, states, np.empty(n_floats), np.empty(n_ints, dtype=np.int64))


@jit_borrowing
def two_coefficient_into(solver_code, W, indptr, indices, blocks, q, mu_s, mu_d, guess, closing, resting, rtol,
                         max_iter, p, u, states, floats, ints):
    """The exact two-coefficient law on u = W p + q, from slip guess `guess` (updated in place to
    the converged guess). W is dense (m × m), or empty with its block-sparse form (indptr,
    indices, blocks: solvers.kernels' layout) for pgs. p holds the warm start (pgs). `closing`
    (per contact): the gap-closing part g/h of q_N, which a held body may leave open; `resting`:
    1 for a contact whose slip velocity at the step's start is round-off. Once the
    sign iteration is consistent, a contact that started at rest slides only if no admissible
    impulse split holds it (hold_at_rest). floats, ints: scratch (kernel_base.solver_scratch
    for at least these contacts — the caller's fitting_scratch —, pgs_scratch_sizes' on the
    block-sparse W).
    Returns (kernel status, solves, solver iterations, consistent, pgs steps solved again by Lemke).
    Compiled without reference counting (the step's hot path): it allocates nothing."""
    na = guess.shape[0]
    start_guess, at = carve(floats, 0, na)
    p_start, at = carve(floats, at, 2 * na)  # the warm start, the previous step's split
    for j in range(na):
        start_guess[j] = guess[j]
        p_start[2 * j], p_start[2 * j + 1] = p[2 * j], p[2 * j + 1]
    lo, at = carve(floats, at, na)
    hi, at = carve(floats, at, na)
    new_guess, at = carve(floats, at, na)
    tried, at = carve_matrix(floats, at, MAX_SOLVES + 1, na)
    below = floats[at:]  # the solver's part of the scratch
    scale_v = 1e-12
    for r in range(2 * na):
        scale_v = max(scale_v, abs(q[r]))
    velocity_tol = 1e-9 * scale_v
    n_tried, iterations, fallbacks, consistent, last = 0, 0, 0, False, False
    while True:
        for j in range(na):
            tried[n_tried, j] = guess[j]
        n_tried += 1
        _interval_of(mu_s, mu_d, guess, lo, hi)
        status, its, residual, fell_back = _solve(solver_code, W, indptr, indices, blocks, q, lo, hi, p, u, rtol,
                                                  max_iter, below, ints)
        iterations += its
        fallbacks += fell_back
        if status != KERNEL_SOLVED:
            return status, n_tried, iterations, False, fallbacks
        if classify_solution(p, u, residual, mu_s, guess, velocity_tol, states, new_guess) and not last:
            consistent = True
            break
        if last:  # the ordinary μs problem after a cycle: exact for sticking, counted inconsistent
            break
        action = next_action(new_guess, tried, n_tried)
        for j in range(na):
            guess[j] = new_guess[j]
        if action == NEXT_STOP:
            break
        last = action == NEXT_TRY_ZERO
    if consistent and hold_at_rest(W, indptr, indices, blocks, q, mu_s, mu_d, start_guess, resting,
                                   max(velocity_tol, 10.0 * residual), closing, p, u, states, p_start):
        _guess_of_states(states, guess)
    return KERNEL_SOLVED, n_tried, iterations, consistent, fallbacks


# Below this many active contacts the step is solved whole: a solve's fixed cost (~1 µs for Lemke
# on one contact, 1.3 µs on two decoupled ones) outweighs what splitting saves. It is also
# enumeration.MAX_CONTACTS, so enum takes any step whose groups have at most 4 contacts.
GROUP_MIN_CONTACTS = 4


@jit_inline
def two_coefficient_by_group(solver_code, W, q, mu_s, mu_d, guess, closing, resting, rtol, max_iter, p, u, states,
                             floats, ints):
    """two_coefficient_into on a dense W one group of coupled contacts at a time: W is
    block-diagonal over the groups (contacts linked through shared bodies), so the step's
    problem is their independent problems — and Lemke's tableau (cubic) and enum's 4ⁿ modes grow
    with a group, not with the step. The sign iteration also runs per group: a cycle in one
    group no longer resets the guesses of another. Steps of at most GROUP_MIN_CONTACTS contacts
    are solved whole. floats, ints: the scratch (kernel_base.solver_scratch). The same returns
    as two_coefficient_kernel (solves, iterations and fallbacks summed; consistent when every
    group is). Borrowing for the common step (few contacts, in the scratch); the split, and a step
    beyond the scratch, go to _by_group_split, which allocates."""
    na = mu_s.shape[0]
    if na <= GROUP_MIN_CONTACTS and fits_scratch(floats, ints, na):
        empty, no_blocks = ints[:0], floats[:0].reshape((0, 2, 2))  # no sparse W (views: nothing allocated)
        return two_coefficient_into(solver_code, W, empty, empty, no_blocks, q, mu_s, mu_d, guess, closing, resting,
                                    rtol, max_iter, p, u, states, floats, ints)
    return _by_group_split(solver_code, W, q, mu_s, mu_d, guess, closing, resting, rtol, max_iter, p, u, states,
                           floats, ints)


@jit
def _by_group_split(solver_code, W, q, mu_s, mu_d, guess, closing, resting, rtol, max_iter, p, u, states, floats,
                    ints):
    """two_coefficient_by_group's split (counted: its groups' arrays are allocated)."""
    na = mu_s.shape[0]
    floats, ints = fitting_scratch(floats, ints, na)  # (the groups are smaller: it fits them too)
    empty, no_blocks = ints[:0], floats[:0].reshape((0, 2, 2))  # no sparse W (views: nothing allocated)
    if na <= GROUP_MIN_CONTACTS:
        return two_coefficient_into(solver_code, W, empty, empty, no_blocks, q, mu_s, mu_d, guess, closing, resting,
                                    rtol, max_iter, p, u, states, floats, ints)
    label = np.empty(na, dtype=np.int64)
    groups = coupled_components(empty, empty, W, label)
    if groups == 1:
        return two_coefficient_into(solver_code, W, empty, empty, no_blocks, q, mu_s, mu_d, guess, closing, resting,
                                    rtol, max_iter, p, u, states, floats, ints)
    solves, iterations, fallbacks, consistent = 0, 0, 0, True
    for g in range(groups):
        members = np.flatnonzero(label == g)
        pg, ug, states_g = gather_contacts(members, p, True), gather_contacts(members, u, True), \
            gather_contacts(members, states, False)
        guess_g = gather_contacts(members, guess, False)
        status, n_solves, its, group_consistent, fell_back = two_coefficient_into(
            solver_code, group_matrix(members, W, empty, empty, no_blocks), empty, empty, no_blocks,
            gather_contacts(members, q, True), gather_contacts(members, mu_s, False),
            gather_contacts(members, mu_d, False), guess_g, gather_contacts(members, closing, False),
            gather_contacts(members, resting, False), rtol, max_iter, pg, ug, states_g, floats, ints)
        solves, iterations, fallbacks = solves + n_solves, iterations + its, fallbacks + fell_back
        consistent = consistent and group_consistent
        scatter_contacts(members, pg, ug, states_g, p, u, states)
        for a in range(members.shape[0]):
            guess[members[a]] = guess_g[a]
        if status != KERNEL_SOLVED:
            return status, solves, iterations, False, fallbacks
    return KERNEL_SOLVED, solves, iterations, consistent, fallbacks


def solve_two_coefficient(W: np.ndarray, q: np.ndarray, mu_s: np.ndarray, mu_d: np.ndarray,
                          slip_guess: np.ndarray, solver: str = DEFAULT_SOLVER, solver_options: dict | None = None,
                          max_solves: int = MAX_SOLVES, closing: np.ndarray | None = None,
                          resting: np.ndarray | None = None) -> StepContactResult:
    """Solve u = W p + q under the exact two-coefficient law, starting from `slip_guess`, with
    any solver of solvers.solve (the same rule as two_coefficient_kernel: classify_solution and
    next_action, hold_at_rest). `closing` (per contact, default 0): the gap-closing part g/h of
    q_N, which a held body may leave open. Raises the solver's SolverError when a solve fails."""
    W, q, mu_s, mu_d = loop_array(W), loop_array(q), loop_array(mu_s), loop_array(mu_d)
    guess = np.array(slip_guess, dtype=float)
    start_guess = guess.copy()
    na = guess.shape[0]
    closing = np.zeros(na) if closing is None else loop_array(closing)
    resting = np.ones(na) if resting is None else loop_array(resting)
    classify, action_of = interpreted(classify_solution), interpreted(next_action)
    lo, hi, new_guess, states = np.empty(na), np.empty(na), np.empty(na), np.zeros(na, dtype=np.int64)
    tried = np.empty((max_solves + 1, na))
    velocity_tol = 1e-9 * max(1e-12, float(np.max(np.abs(q), initial=0.0)))
    n_tried, iterations, consistent, last = 0, 0, False, False
    while True:
        for j in range(na):
            tried[n_tried, j] = guess[j]
        n_tried += 1
        interpreted(_interval_of)(mu_s, mu_d, guess, lo, hi)
        sol = _solvers.solve(PlanarFrictionProblem(W, q, lo, hi), solver, **(solver_options or {}))
        iterations += sol.iterations
        if classify(sol.p, sol.u, sol.residual, mu_s, guess, velocity_tol, states, new_guess) and not last:
            consistent = True
            break
        if last:  # the ordinary μs problem after a cycle: exact for sticking, counted inconsistent
            break
        action = action_of(new_guess, tried, n_tried)
        guess[:] = new_guess
        if action == NEXT_STOP:
            break
        last = action == NEXT_TRY_ZERO
    p, u = np.array(sol.p, dtype=float), np.array(sol.u, dtype=float)
    empty = np.zeros(0, dtype=np.int64)
    if consistent and python_body(hold_at_rest)(W, empty, empty, np.zeros((0, 2, 2)), q, mu_s, mu_d, start_guess,
                                                resting, max(velocity_tol, 10.0 * sol.residual), closing, p, u, states,
                                                np.zeros(0)):
        interpreted(_guess_of_states)(states, guess)
    return StepContactResult(p, u, [STATE_NAMES[s] for s in states], guess.copy(), n_tried, iterations,
                             float(sol.residual), consistent)


__all__ = ["solve_two_coefficient", "two_coefficient_kernel", "two_coefficient_into", "two_coefficient_by_group", "pgs_or_lemke_into",
           "pgs_scratch_sizes", "StepContactResult",
           "classify_solution",
           "next_action", "SolverError", "STATE_NAMES"]
