"""QP-based step solvers through qpsolvers (optional extra ``nonsmooth-rod[qp]``).

Tresca fixed point (solver name = the backend, e.g. "osqp"): for a FIXED friction bound b
the step law is the KKT system of the convex QP

    min ½ pᵀW p + qᵀp   s.t.  p_N ≥ 0,  lo·b ≤ p_T ≤ hi·b          (Tresca friction)

(gradient W p + q = u: u_T > 0 pushes p_T to its lower bound, u_T < 0 to its upper one).
Coulomb friction is its fixed point b = p_N: start from b = 0 (frictionless step), set
b ← max(p_N, 0) and repeat until p_N changes by less than tol · scale. This converges when
the normal–tangential coupling is weak (e.g. one contact with |lo·W_NT| < W_NN, |hi·W_NT| <
W_NN: the map b ↦ p_N is then a contraction), not in general.

Convex relaxation (name + "-relaxed"), a single QP with the friction cone as linear
constraints (Anitescu's cone complementarity problem):

    min ½ pᵀW p + qᵀp   s.t.  p_N ≥ 0,  p_T − lo·p_N ≥ 0,  hi·p_N − p_T ≥ 0.

Its KKT conditions are the step law except for the normal velocity: with multipliers α (for
p_T ≥ lo p_N) and γ (for p_T ≤ hi p_N), u_T = α − γ and u_N = λ − lo·α + hi·γ, so a sliding
contact gets a spurious separation velocity u_N = −lo·u_T (u_T > 0) or hi·|u_T| (u_T < 0)
while still pushing (p_N > 0). This artefact is the known price of the convexification; the
relaxed solver is checked against its own law (`relaxed_residual`), not the step law.

W is used as given (positive semi-definite is fine for OSQP and Clarabel); only backends that
demand a positive-definite P get W + 1e-12·max|W|·I.
"""
from __future__ import annotations

import warnings

import numpy as np

from ._common import make_solution, relative_floor
from .problem import (
    InfeasibleProblem,
    NoConvergence,
    PlanarFrictionProblem,
    complementarity_residual,
)

# Tight defaults: the QP solutions are compared with exact solvers to ~1e-7 and must pass the
# final residual check. Users may override any of them through **backend_options.
#
# OSQP polishing is off by default: OSQP 1.x prints "Polishing not needed - no active set
# detected at optimal point" from C on stdout, whatever `verbose` says, for every QP without
# active constraints (a sticking contact), and at eps 1e-10 polishing made no measurable
# difference (max deviation from Lemke 2.35e-9 with and without, over 300 random steps).
# Pass polish=True (or polishing=True) to turn it on.
BACKEND_DEFAULTS = {
    "osqp": dict(eps_abs=1e-10, eps_rel=1e-10, max_iter=100000, polish=False, verbose=False),
    "clarabel": dict(tol_gap_abs=1e-10, tol_gap_rel=1e-10, tol_feas=1e-10, verbose=False),
}
# Backends that need a positive-definite Hessian (tiny documented regularisation, see module).
POSITIVE_DEFINITE_BACKENDS = {"quadprog", "qpswift", "hpipm"}
REGULARISATION = 1e-12

RELAXED_SUFFIX = "-relaxed"
# contact_states tolerance for QP solutions (accurate to ~1e-9 relative, not to round-off).
STATE_TOL = 1e-6


_BACKENDS: list | None = None


def installed_backends() -> list[str]:
    """QP backends qpsolvers reports installed ([] if qpsolvers itself is missing); probed once
    per process (a failed import is not cached by Python and cost ~60 µs on every call)."""
    global _BACKENDS
    if _BACKENDS is None:
        try:
            import qpsolvers
        except ImportError:
            _BACKENDS = []
        else:
            _BACKENDS = list(qpsolvers.available_solvers)
    return list(_BACKENDS)


def _backend_options(backend: str, overrides: dict) -> dict:
    options = dict(BACKEND_DEFAULTS.get(backend, {}))
    options.update(overrides)
    if backend == "osqp" and "polish" in options:
        import osqp

        # OSQP 1.0 renamed "polish" to "polishing" (the old name warns).
        if not str(getattr(osqp, "__version__", "1")).startswith("0."):
            options["polishing"] = options.pop("polish")
    return options


def _solve_qp(backend, P, c, G, h, A, b, options, initvals, what: str) -> np.ndarray:
    """One QP through qpsolvers; InfeasibleProblem (naming ``what``) unless it is solved."""
    import qpsolvers
    import scipy.sparse as sparse

    if backend in POSITIVE_DEFINITE_BACKENDS:
        P = P + REGULARISATION * max(float(np.max(np.abs(P))), 1e-300) * np.eye(P.shape[0])
    if backend in qpsolvers.sparse_solvers and backend not in qpsolvers.dense_solvers:
        P, G = sparse.csc_matrix(P), sparse.csc_matrix(G)
        A = sparse.csc_matrix(A) if A is not None else None
    problem = qpsolvers.Problem(P, c, G, h, A, b)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            solution = qpsolvers.solve_problem(problem, solver=backend, initvals=initvals, **options)
        except Exception as error:  # backend-specific failures (ProblemError, panics, ...)
            raise InfeasibleProblem(f"{backend}: {what} failed: {error}") from error
    if solution.x is None or not np.all(np.isfinite(solution.x)) or not (
        solution.found or _nearly_solved(backend, solution)
    ):
        status = "; ".join(str(w.message) for w in caught) or "no solution found"
        raise InfeasibleProblem(f"{backend}: {what} not solved ({status})")
    return np.asarray(solution.x, dtype=float)


def _nearly_solved(backend: str, solution) -> bool:
    """Did the backend stop just short of its (tight) tolerances? Such a point is kept: the
    final residual check of the caller decides whether it is good enough."""
    status = str((solution.extras or {}).get("status", ""))
    if backend == "clarabel":
        return status.endswith("AlmostSolved")
    if backend == "osqp":
        info = (solution.extras or {}).get("info")
        return getattr(info, "status", "") == "solved inaccurate"
    return False


def _tresca_constraints(problem: PlanarFrictionProblem, bound: np.ndarray):
    """(G, h, A, b): G p ≤ h for p_N ≥ 0 and p_T ∈ [lo·b, hi·b]; where the interval has
    collapsed (b = 0 on the first iteration, or lo = hi) the row becomes A p = b instead."""
    n = 2 * problem.n_contacts
    inequalities = []  # (column, coefficient, right-hand side)
    equalities = []  # (column, right-hand side)
    for i in range(problem.n_contacts):
        N, T = 2 * i, 2 * i + 1
        inequalities.append((N, -1.0, 0.0))
        low, high = problem.lo[i] * bound[i], problem.hi[i] * bound[i]
        if high > low:
            inequalities += [(T, 1.0, high), (T, -1.0, -low)]
        else:
            equalities.append((T, low))
    G = np.zeros((len(inequalities), n))
    for row, (column, coefficient, _) in enumerate(inequalities):
        G[row, column] = coefficient
    h = np.array([rhs for _, _, rhs in inequalities])
    if not equalities:
        return G, h, None, None
    A = np.zeros((len(equalities), n))
    for row, (column, _) in enumerate(equalities):
        A[row, column] = 1.0
    return G, h, A, np.array([rhs for _, rhs in equalities])


def _relaxed_constraints(problem: PlanarFrictionProblem):
    """G p ≤ h for p_N ≥ 0, p_T − lo p_N ≥ 0, hi p_N − p_T ≥ 0 (all contacts)."""
    n_c = problem.n_contacts
    G = np.zeros((3 * n_c, 2 * n_c))
    for i in range(n_c):
        N, T = 2 * i, 2 * i + 1
        G[3 * i, N] = -1.0
        G[3 * i + 1, N], G[3 * i + 1, T] = problem.lo[i], -1.0
        G[3 * i + 2, N], G[3 * i + 2, T] = -problem.hi[i], 1.0
    return G, np.zeros(3 * n_c)


def relaxed_residual(problem: PlanarFrictionProblem, p) -> float:
    """Residual of the relaxed (cone complementarity) law that the "-relaxed" QP solves.

    It is the common residual with u_N replaced by the normal velocity net of the relaxation's
    artefact, ũ_N = u_N + lo·max(u_T, 0) − hi·max(−u_T, 0).
    """
    p = np.asarray(p, dtype=float)
    u = problem.W @ p + problem.q
    u_t = u[1::2]
    shifted = u.copy()
    shifted[0::2] += problem.lo * np.maximum(u_t, 0.0) - problem.hi * np.maximum(-u_t, 0.0)
    # complementarity_residual with q shifted so that W p + q' = ũ
    return complementarity_residual(
        PlanarFrictionProblem(problem.W, problem.q + (shifted - u), problem.lo, problem.hi), p
    )


def _normalised(problem: PlanarFrictionProblem):
    """(problem with W / max|W| and q / max|q|, factor back to impulses).

    The backends' tolerances are absolute, so they act on O(1) data; the step law is
    invariant under this scaling: p = p̃ · max|q| / max|W| and u = ũ · max|q|.
    """
    W_norm = float(np.max(np.abs(problem.W))) or 1.0
    q_norm = float(np.max(np.abs(problem.q))) or 1.0
    scaled = PlanarFrictionProblem(problem.W / W_norm, problem.q / q_norm, problem.lo, problem.hi)
    return scaled, q_norm / W_norm


def _nothing_pushes(problem: PlanarFrictionProblem) -> bool:
    """q_N ≥ 0 everywhere: p = 0 solves the step (no contact needs to push). Handled exactly
    rather than by a QP, whose interior-point answer would be 0 only to its tolerance."""
    return bool(np.all(problem.q[0::2] >= 0.0))


def _check(problem, p, check_tol, what, residual_of=complementarity_residual):
    u = problem.W @ p + problem.q
    scale = relative_floor(p.tolist(), u.tolist(), problem.q.tolist())
    residual = residual_of(problem, p)
    if not residual <= check_tol * scale:
        raise NoConvergence(f"{what}: residual {residual:.3e} > check_tol {check_tol:.0e} × scale {scale:.3e}")
    return u, residual


def _polish_active_set(problem: PlanarFrictionProblem, p: np.ndarray) -> np.ndarray:
    """Re-solve exactly the linear system of the contact modes the QP solution shows.

    Interior-point and ADMM backends stop at ~1e-9 relative accuracy, and less on degenerate
    steps (a contact sliding exactly at an end of its interval, as at break-away). Reading the
    active set off the approximate solution and solving that mode's equations exactly (as the
    enumeration solver does for every mode) removes the error; the polished point is kept
    only if it satisfies the law better.
    """
    import itertools

    from .enumeration import _solve_modes
    from .problem import STATE_OPEN, STATE_SLIP_MINUS, STATE_SLIP_PLUS, STATE_STICK

    u = problem.W @ p + problem.q
    p_scale = max(float(np.max(np.abs(p))), 1e-300)
    # Per contact the modes the approximate point is near: open, or stick / slip the way u_T
    # points (near-degenerate steps sit between the two); every combination is solved exactly
    # and the one obeying the law best is kept.
    choices = []
    for i in range(problem.n_contacts):
        if p[2 * i] <= 1e-9 * p_scale:
            choices.append([STATE_OPEN])
        else:
            choices.append([STATE_STICK, STATE_SLIP_PLUS if u[2 * i + 1] >= 0.0 else STATE_SLIP_MINUS])
    modes = np.array(list(itertools.product(*choices)))
    candidates = _solve_modes(problem, modes, 1e-12)
    best, best_residual = p, complementarity_residual(problem, p)
    for candidate in candidates:
        if np.all(np.isfinite(candidate)):
            residual = complementarity_residual(problem, candidate)
            if residual < best_residual:
                best, best_residual = candidate, residual
    return best


def _polish_relaxed(problem: PlanarFrictionProblem, p: np.ndarray) -> np.ndarray:
    """The relaxed QP's active set, re-solved exactly (see _polish_active_set).

    Its KKT conditions per contact: open (p = 0); inside the cone (u_N = u_T = 0); or on an
    edge p_T = e p_N (e = lo or hi) with u_N + e u_T = 0 — the relaxation's spurious normal
    velocity u_N = −e u_T.
    """
    import itertools

    W, q = problem.W, problem.q
    n = q.shape[0]
    u = W @ p + q
    p_scale = max(float(np.max(np.abs(p))), 1e-300)
    choices = []
    for i in range(problem.n_contacts):
        if p[2 * i] <= 1e-9 * p_scale:
            choices.append(["open"])
        else:
            choices.append(["inside", "lo" if u[2 * i + 1] >= 0.0 else "hi"])
    best, best_residual = p, relaxed_residual(problem, p)
    for modes in itertools.product(*choices):
        A = np.zeros((n, n))
        b = np.zeros(n)
        for i, mode in enumerate(modes):
            N, T = 2 * i, 2 * i + 1
            if mode == "open":
                A[N, N] = A[T, T] = 1.0
            elif mode == "inside":
                A[N], A[T], b[N], b[T] = W[N], W[T], -q[N], -q[T]
            else:
                edge = problem.lo[i] if mode == "lo" else problem.hi[i]
                A[N], b[N] = W[N] + edge * W[T], -(q[N] + edge * q[T])
                A[T, T], A[T, N] = 1.0, -edge
        candidate = np.linalg.lstsq(A, b, rcond=1e-12)[0]
        residual = relaxed_residual(problem, candidate)
        if np.all(np.isfinite(candidate)) and residual < best_residual:
            best, best_residual = candidate, residual
    return best


def tresca_fixed_point(
    problem: PlanarFrictionProblem,
    *,
    backend: str = "osqp",
    tol: float = 1e-9,
    max_iter: int = 100,
    check_tol: float = 1e-7,
    **backend_options,
):
    """Coulomb step as the fixed point of Tresca QPs (module docstring); ContactSolution.

    ``tol``: stop when max|p_N − b| ≤ tol · residual_scale (of the normalised problem, see
    `_normalised`). ``max_iter``: QP solves before NoConvergence. ``check_tol``: the final
    solution must have complementarity_residual ≤ check_tol · residual_scale (QP accuracy),
    else NoConvergence. A QP the backend cannot solve raises InfeasibleProblem.
    iterations = QP solves (0 when q_N ≥ 0 and p = 0 is returned directly).
    """
    if _nothing_pushes(problem):
        return make_solution(problem, np.zeros_like(problem.q), problem.q.copy(), backend, 0, 0.0)
    options = _backend_options(backend, backend_options)
    scaled, to_impulse = _normalised(problem)
    W, q = scaled.W, scaled.q
    bound = np.zeros(problem.n_contacts)
    p = None
    change = np.inf
    for iteration in range(1, max_iter + 1):
        G, h, A, b = _tresca_constraints(scaled, bound)
        p = _solve_qp(backend, W, q, G, h, A, b, options, p, f"Tresca QP {iteration}")
        p_n = p[0::2]
        change = float(np.max(np.abs(p_n - bound), initial=0.0))
        bound = np.maximum(p_n, 0.0)
        scale = relative_floor(p.tolist(), (W @ p + q).tolist(), q.tolist())
        if change <= tol * scale:
            p = _polish_active_set(problem, p * to_impulse)
            u, residual = _check(
                problem, p, check_tol, f"{backend}: Tresca fixed point settled after {iteration} QPs but"
            )
            return make_solution(
                problem, p, u, backend, iteration, residual, state_tol=STATE_TOL,
                normal_change=change * to_impulse,
            )
    raise NoConvergence(
        f"{backend}: Tresca fixed point not converged after {max_iter} QPs: normal impulse still "
        f"changes by {change * to_impulse:.3e}, residual "
        f"{complementarity_residual(problem, p * to_impulse):.3e}"
    )


def relaxed_qp(
    problem: PlanarFrictionProblem,
    *,
    backend: str = "osqp",
    check_tol: float = 1e-7,
    **backend_options,
):
    """The convex relaxation as one QP (module docstring); ContactSolution named backend-relaxed.

    ``residual`` is the common (step-law) residual, which the relaxation's artefact makes
    nonzero on sliding contacts; info["relaxed_residual"] is the residual of the law it does
    solve, which must be ≤ check_tol · residual_scale (else NoConvergence). iterations = 1
    (0 when q_N ≥ 0 and p = 0 is returned directly).
    """
    name = backend + RELAXED_SUFFIX
    if _nothing_pushes(problem):
        return make_solution(problem, np.zeros_like(problem.q), problem.q.copy(), name, 0, 0.0,
                             relaxed_residual=0.0)
    options = _backend_options(backend, backend_options)
    scaled, to_impulse = _normalised(problem)
    G, h = _relaxed_constraints(scaled)
    p = _solve_qp(backend, scaled.W, scaled.q, G, h, None, None, options, None, "relaxed QP") * to_impulse
    p = _polish_relaxed(problem, p)
    u, relaxed = _check(problem, p, check_tol, f"{name}: QP solution misses the relaxed law,", relaxed_residual)
    return make_solution(
        problem, p, u, name, 1, complementarity_residual(problem, p),
        state_tol=STATE_TOL, relaxed_residual=relaxed,
    )


__all__ = ["tresca_fixed_point", "relaxed_qp", "relaxed_residual", "installed_backends"]
