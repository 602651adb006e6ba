"""Compiled fast path of Moreau–Jean for small scenes (numba).

Same algorithm, step for step, as `moreau_jean.MoreauJean` with the Lemke solver: contact
kinematics of disks/points on lines, the activation rule with its margin, the gap-keeping law
of persistent contacts, the two-coefficient sign iteration of `onestep.solve_two_coefficient`,
Lemke on the lifted LCP (the very kernel of `solvers.lemke`), and the impact-time root.
The whole run is one compiled call: no Python per step. Tests hold it to the general path.

Eligible scenes: disk/point-on-line contacts only, gravity as the only applied force, solver
"lemke". Anything else runs on the general path.
"""
from __future__ import annotations

import math

import numpy as np

try:
    import numba
except ImportError:  # pragma: no cover - numba is an optional accelerator
    numba = None

from .. import _jit
from ..model.contacts import DiskOnLine
from ..solvers.sticking import prefer_sticking
from ..solvers.lemke import CONE, INTERVAL, RESIDUAL_TOL, SOLVED, _default_max_pivots

if numba is not None:
    from ..solvers.lemke import _lemke_friction_kernel_jit

AVAILABLE = numba is not None

# Per-contact parameter columns of the packed contact table.
(C_BODY, C_OFF_X, C_OFF_Y, C_RADIUS, C_PX, C_PY, C_NX, C_NY, C_TX, C_TY, C_SURF, C_MU_S, C_MU_D,
 C_REST) = range(14)
N_COLUMNS = 14

# Run status codes.
RUN_OK, RUN_SOLVER_FAILED, RUN_NONFINITE = 0, 1, 2
STATE_OPEN, STATE_STICK, STATE_SLIP_PLUS, STATE_SLIP_MINUS = 0, 1, 2, 3


def eligible(scene, solver: str) -> bool:
    # prefer_sticking is compiled only when _jit is enabled (NONSMOOTH_ROD_NO_JIT unset)
    return (AVAILABLE and _jit.ENABLED and solver == "lemke" and scene.applied_force is None
            and all(type(c) is DiskOnLine for c in scene.contacts) and len(scene.contacts) <= 8)


def pack_contacts(scene) -> np.ndarray:
    table = np.zeros((len(scene.contacts), N_COLUMNS))
    for i, c in enumerate(scene.contacts):
        n, t = c.line.normal, c.line.tangent
        table[i] = (c.body, c.offset[0], c.offset[1], c.radius, c.line.point[0], c.line.point[1],
                    n[0], n[1], t[0], t[1], c.line.velocity, c.law.friction.mu_s, c.law.friction.mu_d,
                    c.law.impact.restitution)
    return table


def _kinematics(table, i, q, v, H_N, H_T):
    """gap, drift_N of contact i; fills the rows H_N, H_T (zeroed by the caller)."""
    b = int(table[i, C_BODY])
    j = 3 * b
    th = q[j + 2]
    c, s = math.cos(th), math.sin(th)
    ox, oy = table[i, C_OFF_X], table[i, C_OFF_Y]
    dx, dy = c * ox - s * oy, s * ox + c * oy
    nx, ny, tx, ty = table[i, C_NX], table[i, C_NY], table[i, C_TX], table[i, C_TY]
    r = table[i, C_RADIUS]
    rho_x, rho_y = dx - r * nx, dy - r * ny
    gap = nx * (q[j] + dx - table[i, C_PX]) + ny * (q[j + 1] + dy - table[i, C_PY]) - r
    H_N[j], H_N[j + 1], H_N[j + 2] = nx, ny, rho_x * ny - rho_y * nx
    H_T[j], H_T[j + 1], H_T[j + 2] = tx, ty, rho_x * ty - rho_y * tx
    om = v[j + 2]
    drift_N = -om * om * (dx * nx + dy * ny)
    return gap, drift_N


def _dot(a, b):
    s = 0.0
    for k in range(a.shape[0]):
        s += a[k] * b[k]
    return s


def _seen(tried, n_tried, guess):
    for tt in range(n_tried):
        same = True
        for jj in range(guess.shape[0]):
            if tried[tt, jj] != guess[jj]:
                same = False
        if same:
            return True
    return False


def _attempt(W, qv, mu_s, mu_d, guess, v_tol):
    """One solve of the step with slip-sign guess `guess`, classified as onestep.classify."""
    na = guess.shape[0]
    m = 2 * na
    lo = np.empty(na)
    hi = np.empty(na)
    for jj in range(na):
        shift = (mu_s[jj] - mu_d[jj]) * guess[jj]
        lo[jj] = shift - mu_s[jj]
        hi[jj] = shift + mu_s[jj]
    # As solvers.lemke.lemke_friction: the interval LCP, and the cone LCP if that one fails
    # (ray, pivot limit, or a residual above tolerance).
    accepted = False
    p, u, residual, kstat, pivots, norms = _lemke_friction_kernel_jit(
        W, qv, lo, hi, _default_max_pivots(3 * na), INTERVAL)
    scale = norms[2] if norms[2] > 0.0 else 1.0
    accepted = kstat == SOLVED and residual <= RESIDUAL_TOL * scale
    if not accepted:
        p, u, residual, kstat, pivots, norms = _lemke_friction_kernel_jit(
            W, qv, lo, hi, _default_max_pivots(4 * na), CONE)
        scale = norms[2] if norms[2] > 0.0 else 1.0
        accepted = kstat == SOLVED and residual <= RESIDUAL_TOL * scale
    st = np.zeros(na, dtype=np.int8)
    new_guess = guess.copy()
    if not accepted:
        return False, p, u, st, False, new_guess
    v_tol = max(v_tol, 10.0 * residual)  # as onestep: within the solver's accuracy is zero
    scale_p = 1e-300
    for r_ in range(m):
        scale_p = max(scale_p, abs(p[r_]))
    p_tol = 1e-12 * scale_p
    ok_all = True
    for jj in range(na):
        pn, pt, ut = p[2 * jj], p[2 * jj + 1], u[2 * jj + 1]
        if pn <= p_tol:
            st[jj] = STATE_OPEN
        elif ut > v_tol:
            st[jj] = STATE_SLIP_PLUS
            if guess[jj] != 1.0:
                ok_all = False
                new_guess[jj] = 0.0 if guess[jj] != 0.0 else 1.0
        elif ut < -v_tol:
            st[jj] = STATE_SLIP_MINUS
            if guess[jj] != -1.0:
                ok_all = False
                new_guess[jj] = 0.0 if guess[jj] != 0.0 else -1.0
        else:
            st[jj] = STATE_STICK
            if abs(pt) > mu_s[jj] * pn * (1 + 1e-9) + p_tol:
                ok_all = False
                if guess[jj] != 0.0:
                    new_guess[jj] = 0.0
                else:
                    new_guess[jj] = -1.0 if pt > 0 else (1.0 if pt < 0 else 0.0)
    return True, p, u, st, ok_all, new_guess


def _run(q0, v0, minv, force, table, h, theta, gamma, n_steps, stop_index, ACTIVATION_ROUNDOFF, GAP_ROUNDOFF_ULPS):
    n_dof = q0.shape[0]
    nc = table.shape[0]
    q = np.empty((n_steps + 1, n_dof))
    v = np.empty((n_steps + 1, n_dof))
    pN = np.zeros((n_steps, nc))
    pT = np.zeros((n_steps, nc))
    states = np.zeros((n_steps, nc), dtype=np.int8)
    # Every closing impact: time, step and contact, in order.
    impact_t = np.empty(n_steps)
    impact_step = np.empty(n_steps, dtype=np.int64)
    impact_contact = np.empty(n_steps, dtype=np.int64)
    n_impacts = 0
    q[0] = q0
    v[0] = v0
    slip_sign = np.zeros(nc)
    was_closed = np.zeros(nc, dtype=np.bool_)
    closed_now = np.zeros(nc, dtype=np.bool_)
    H_N = np.zeros((nc, n_dof))
    H_T = np.zeros((nc, n_dof))
    gaps = np.zeros(nc)
    drifts = np.zeros(nc)
    v_free = np.empty(n_dof)
    a_free = minv * force
    active = np.empty(nc, dtype=np.int64)
    status = RUN_OK
    fail_step = -1
    solves_total = 0
    inconsistent_total = 0
    t_stop = np.nan
    k = 0
    done = 0
    for k in range(n_steps):
        t = k * h
        qk = q[k]
        vk = v[k]
        for d in range(n_dof):
            v_free[d] = vk[d] + h * a_free[d]
        na = 0
        for i in range(nc):
            H_N[i, :] = 0.0
            H_T[i, :] = 0.0
            gaps[i], drifts[i] = _kinematics(table, i, qk, vk, H_N[i], H_T[i])
            predicted = gaps[i] + gamma * h * _dot(H_N[i], vk)
            margin = ACTIVATION_ROUNDOFF
            if was_closed[i]:
                margin = max(margin, h * h * (abs(drifts[i]) + abs(_dot(H_N[i], a_free))))
            if predicted <= margin:
                active[na] = i
                na += 1
        v_next = v_free.copy()
        for i in range(nc):
            closed_now[i] = False
        if na > 0:
            m = 2 * na
            gap_roundoff = 1.0
            for d in range(n_dof):
                gap_roundoff = max(gap_roundoff, abs(qk[d]))
            gap_roundoff *= GAP_ROUNDOFF_ULPS * 2.220446049250313e-16
            H = np.empty((m, n_dof))
            qv = np.empty(m)
            guess = np.empty(na)
            closing = np.zeros(na)
            mu_s = np.empty(na)
            mu_d = np.empty(na)
            for jj in range(na):
                i = active[jj]
                H[2 * jj] = H_N[i]
                H[2 * jj + 1] = H_T[i]
                if was_closed[i]:
                    # as moreau_jean._gap_to_close: a gap of position round-off is no gap
                    closing[jj] = (gaps[i] if gaps[i] > gap_roundoff else 0.0) / h
                    qv[2 * jj] = _dot(H_N[i], v_free) + closing[jj]
                    guess[jj] = slip_sign[i]
                else:
                    u_n_k = _dot(H_N[i], vk)
                    qv[2 * jj] = _dot(H_N[i], v_free) + table[i, C_REST] * min(u_n_k, 0.0)
                    u_t_k = _dot(H_T[i], vk) - table[i, C_SURF]
                    guess[jj] = 0.0 if abs(u_t_k) < 1e-12 else math.copysign(1.0, u_t_k)
                qv[2 * jj + 1] = _dot(H_T[i], v_free) - table[i, C_SURF]
                mu_s[jj] = table[i, C_MU_S]
                mu_d[jj] = table[i, C_MU_D]
            W = np.empty((m, m))
            for r_ in range(m):
                for c_ in range(m):
                    s = 0.0
                    for d in range(n_dof):
                        s += H[r_, d] * minv[d] * H[c_, d]
                    W[r_, c_] = s
            scale_v = 1e-12
            for r_ in range(m):
                scale_v = max(scale_v, abs(qv[r_]))
            v_tol = 1e-9 * scale_v
            start_guess = guess.copy()
            tried = np.empty((7, na))
            n_tried = 0
            consistent = False
            solved, p, u, st, ok_all, new_guess = False, np.zeros(m), np.zeros(m), np.zeros(na, np.int8), False, guess
            for attempt in range(6):
                tried[n_tried] = guess
                n_tried += 1
                solved, p, u, st, ok_all, new_guess = _attempt(W, qv, mu_s, mu_d, guess, v_tol)
                solves_total += 1
                if not solved or ok_all:
                    consistent = ok_all
                    break
                if _seen(tried, n_tried, new_guess):
                    break
                guess = new_guess
            if solved and not consistent:
                zero = np.zeros(na)
                if not _seen(tried, n_tried, zero):
                    # Cycling among sign guesses: the ordinary μs problem, as the general path.
                    solved, p, u, st, ok_all, new_guess = _attempt(W, qv, mu_s, mu_d, zero, v_tol)
                    solves_total += 1
            if not solved:
                status = RUN_SOLVER_FAILED
                fail_step = k
                break
            if not consistent:
                inconsistent_total += 1
            else:  # hold what μs can hold (solvers.sticking), as solve_two_coefficient
                codes = st.astype(np.int64)
                if prefer_sticking(W, qv, mu_s, mu_d, start_guess, v_tol, closing, p, u, codes):
                    for jj in range(na):
                        st[jj] = codes[jj]
            for d in range(n_dof):
                acc = 0.0
                for r_ in range(m):
                    acc += H[r_, d] * p[r_]
                v_next[d] = v_free[d] + minv[d] * acc
            for jj in range(na):
                i = active[jj]
                pN[k, i] = p[2 * jj]
                pT[k, i] = p[2 * jj + 1]
                states[k, i] = st[jj]
                if st[jj] == STATE_SLIP_PLUS:
                    slip_sign[i] = 1.0
                elif st[jj] == STATE_SLIP_MINUS:
                    slip_sign[i] = -1.0
                else:
                    slip_sign[i] = 0.0
                closed_now[i] = p[2 * jj] > 0.0
        for d in range(n_dof):
            v[k + 1, d] = v_next[d]
            q[k + 1, d] = qk[d] + h * ((1.0 - theta) * vk[d] + theta * v_next[d])
        for i in range(nc):
            if closed_now[i] and not was_closed[i]:
                u_before = _dot(H_N[i], vk)
                if u_before < -1e-9:
                    t_hit = t + _crossing_offset(gaps[i], u_before, _dot(H_N[i], a_free) + drifts[i], h)
                    impact_t[n_impacts] = t_hit
                    impact_step[n_impacts] = k
                    impact_contact[n_impacts] = i
                    n_impacts += 1
                    if i == stop_index and math.isnan(t_stop):
                        t_stop = t_hit
        for i in range(nc):
            was_closed[i] = closed_now[i]
        finite = True
        for d in range(n_dof):
            if not (math.isfinite(v[k + 1, d]) and math.isfinite(q[k + 1, d])):
                finite = False
        if not finite:
            status = RUN_NONFINITE
            fail_step = k + 1
            break
        done = k + 1
        if not math.isnan(t_stop):
            break
    return (q, v, pN, pT, states, done, status, fail_step, impact_t[:n_impacts], impact_step[:n_impacts],
            impact_contact[:n_impacts], t_stop, solves_total, inconsistent_total)


def _crossing_offset(g, u, a, h):
    """Root of g + u τ + ½ a τ² nearest 0 within [−h, 2h] (as MoreauJean._crossing_time)."""
    best = np.nan
    r1 = np.nan
    r2 = np.nan
    if abs(a) > 1e-14:
        disc = u * u - 2.0 * a * g
        if disc >= 0.0:
            sq = math.sqrt(disc)
            r1 = (-u - sq) / a
            r2 = (-u + sq) / a
    elif u != 0.0:
        r1 = -g / u
    for r in (r1, r2):
        if not math.isnan(r) and -h <= r <= 2 * h:
            if math.isnan(best) or abs(r) < abs(best):
                best = r
    if math.isnan(best):
        return 0.0
    return best


if AVAILABLE:
    _default_max_pivots = numba.njit(cache=True)(_default_max_pivots)
    _seen = numba.njit(cache=True)(_seen)
    _attempt = numba.njit(cache=True)(_attempt)
    _kinematics = numba.njit(cache=True)(_kinematics)
    _dot = numba.njit(cache=True)(_dot)
    _crossing_offset = numba.njit(cache=True)(_crossing_offset)
    _run_jit = numba.njit(cache=True)(_run)


def run_compiled(scene, q0, v0, h, theta, gamma, n_steps, stop_index):
    """Run the compiled loop; returns the tuple of arrays of `_run`."""
    from .moreau_jean import ACTIVATION_ROUNDOFF, GAP_ROUNDOFF_ULPS
    table = pack_contacts(scene)
    force = scene.force(0.0, np.asarray(q0, float), np.asarray(v0, float))
    return _run_jit(np.asarray(q0, float), np.asarray(v0, float), scene.inverse_mass_diagonal, force, table,
                    float(h), float(theta), float(gamma), int(n_steps), int(stop_index), ACTIVATION_ROUNDOFF,
                    GAP_ROUNDOFF_ULPS)
