"""The paper's two limiting hypotheses for the rod, from its closed-form equations.

* Pure rolling (paper Fig. 9/14a): the T/N a rolling contact would need, its maximum (the
  critical friction coefficient) and the times t_r1 (T/N first rises to +μs) and t_r2
  (T/N first falls to −μs).
* Pure sliding (paper Figs. 22–24): sliding from release with μd throughout, the slip
  direction reversing whenever v_C crosses zero; never re-sticking.
Both run until the axis is horizontal (ball B touches the plane: θ = 0 for equal balls).
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from . import closed_form as cf

ROLLING_CACHE_SIZE = 512  # distinct (body, θ0, g, μs) kept; a sweep group needs one each


@dataclass
class RollingHypothesis:
    t: np.ndarray
    theta: np.ndarray
    theta_dot: np.ndarray
    T_over_N: np.ndarray
    T_over_N_max: float
    t_max: float
    T_over_N_initial: float
    t_r1: float | None
    t_r2: float | None
    t_horizontal: float

    def as_dict(self) -> dict:
        return {"T_over_N_max": self.T_over_N_max, "t_max": self.t_max,
                "T_over_N_initial": self.T_over_N_initial, "t_r1": self.t_r1, "t_r2": self.t_r2,
                "t_horizontal": self.t_horizontal}


def _ratio(p, th, om):
    _, _, N, T = cf.rolling(p, th, om)
    return T / N


def rolling_hypothesis(p, n_samples: int = 2001, rtol: float = 1e-12) -> RollingHypothesis:
    """Integrate pure rolling from rest until θ = 0 and analyse T/N.

    Cached: it depends only on the body (mass, ξ, J, r), θ0, g and μs (through t_r1, t_r2), and
    a sweep or a run summary asks for the same one many times. The result is shared between
    callers: treat its arrays as read-only."""
    key = (float(p.mass), float(p.xi), float(p.inertia), float(p.ball_radius), float(p.theta0), float(p.g),
           float(p.mu_s), int(n_samples), float(rtol))
    return _rolling_hypothesis_cached(key)


@functools.lru_cache(maxsize=ROLLING_CACHE_SIZE)
def _rolling_hypothesis_cached(key) -> RollingHypothesis:
    mass, xi, inertia, ball_radius, theta0, g, mu_s, n_samples, rtol = key
    rh = _solve_rolling(_RollingBody(mass, xi, inertia, ball_radius, theta0, g, mu_s), n_samples, rtol)
    for arr in (rh.t, rh.theta, rh.theta_dot, rh.T_over_N):
        arr.setflags(write=False)
    return rh


@dataclass(frozen=True)
class _RollingBody:
    """What the rolling equations read from a RodProblem (closed_form.rolling's attributes)."""

    mass: float
    xi: float
    inertia: float
    ball_radius: float
    theta0: float
    g: float
    mu_s: float


def _solve_rolling(p, n_samples: int, rtol: float) -> RollingHypothesis:
    from scipy.integrate import solve_ivp
    from scipy.optimize import minimize_scalar

    def rhs(t, y):
        return [y[1], cf.rolling(p, y[0], y[1])[0]]

    def horizontal(t, y):
        return y[0]
    horizontal.terminal, horizontal.direction = True, -1

    def up(t, y):
        return _ratio(p, y[0], y[1]) - p.mu_s
    up.direction = 1

    def down(t, y):
        return _ratio(p, y[0], y[1]) + p.mu_s
    down.direction = -1

    sol = solve_ivp(rhs, (0.0, 10.0), [p.theta0, 0.0], method="DOP853", rtol=rtol, atol=1e-14,
                    events=[horizontal, up, down], dense_output=True)
    if sol.t_events[0].size == 0:
        raise RuntimeError("pure rolling did not reach the horizontal within 10 s")
    t_h = float(sol.t_events[0][0])
    ts = np.linspace(0.0, t_h, n_samples)
    ys = sol.sol(ts)
    ratio = np.array([_ratio(p, a, b) for a, b in zip(ys[0], ys[1])])
    k = int(np.argmax(ratio))
    lo, hi = ts[max(k - 1, 0)], ts[min(k + 1, n_samples - 1)]
    opt = minimize_scalar(lambda tt: -_ratio(p, *sol.sol(tt)), bounds=(lo, hi), method="bounded",
                          options={"xatol": 1e-12})
    t_max = float(opt.x) if -opt.fun >= ratio[k] else float(ts[k])
    r_max = max(float(-opt.fun), float(ratio[k]))
    t_r1 = float(sol.t_events[1][0]) if sol.t_events[1].size else None
    t_r2 = float(sol.t_events[2][0]) if sol.t_events[2].size else None
    if t_r1 is not None and t_r1 > t_h:
        t_r1 = None
    if t_r2 is not None and t_r2 > t_h:
        t_r2 = None
    return RollingHypothesis(ts, ys[0], ys[1], ratio, r_max, t_max, float(ratio[0]), t_r1, t_r2, t_h)


@dataclass
class SlidingHypothesis:
    """Pure sliding with μd. Where neither slip direction is consistent (the rolling contact
    would need |T/N| < μd), the only (Filippov) solution keeps v_C = 0: those intervals are
    listed in `filippov` — the discontinuities the paper's Fig. 25 shows from μ ≈ 0.26 on."""

    t: np.ndarray
    theta: np.ndarray
    theta_dot: np.ndarray
    theta_ddot: np.ndarray
    x_O: np.ndarray
    x_O_dot: np.ndarray
    x_O_ddot: np.ndarray
    N: np.ndarray
    sign: np.ndarray  # +1 / −1 sliding, 0 on Filippov (v_C = 0) intervals
    reversals: list[float]
    filippov: list[tuple[float, float]]
    t_horizontal: float | None
    status: str


def _accelerations(p, y, sign):
    if sign == 0.0:
        th_dd, xo_dd, N, T = cf.rolling(p, y[0], y[1])
    else:
        th_dd, xo_dd, N, T = cf.sliding(p, y[0], y[1], sign)
    return th_dd, xo_dd, N, T


def _slip_direction(p, theta, theta_dot) -> float:
    """Slip sign after v_C = 0: against the rolling friction if μd cannot supply it, else 0."""
    _, _, N, T = cf.rolling(p, theta, theta_dot)
    if abs(T) <= p.mu_d * N:
        return 0.0
    return -1.0 if T > 0 else 1.0


def sliding_hypothesis(p, n_samples: int = 2001, rtol: float = 1e-12, t_max: float = 10.0) -> SlidingHypothesis:
    """Slide with μd from release, never sticking; reverse where v_C crosses zero."""
    from scipy.integrate import solve_ivp

    t, y = 0.0, np.array([p.theta0, 0.0, 0.0, 0.0])  # θ, θ̇, x_O, ẋ_O
    sign = _slip_direction(p, p.theta0, 0.0)
    segments, reversals, filippov, status, t_h = [], [], [], "ok", None
    for _ in range(200):
        def rhs(tt, yy, s=sign):
            th_dd, xo_dd, _, _ = _accelerations(p, yy, s)
            return [yy[1], th_dd, yy[3], xo_dd]

        def horizontal(tt, yy):
            return yy[0]
        horizontal.terminal, horizontal.direction = True, -1
        events = [horizontal]
        if sign != 0.0:
            def slip_zero(tt, yy, s=sign):
                return s * (yy[3] + p.ball_radius * yy[1])
            slip_zero.terminal, slip_zero.direction = True, -1

            def painleve(tt, yy, s=sign):
                return cf.sliding_denominator(p, yy[0], yy[1], s)
            painleve.terminal, painleve.direction = True, -1
            events += [slip_zero, painleve]
        else:
            def leave(tt, yy):
                _, _, N, T = cf.rolling(p, yy[0], yy[1])
                return p.mu_d * N - abs(T)
            leave.terminal, leave.direction = True, -1
            events.append(leave)
        sol = solve_ivp(rhs, (t, t_max), y.copy(), method="DOP853", rtol=rtol, atol=1e-14,
                        events=events, dense_output=True)
        # Events at the segment's own start (v_C = 0 when sliding starts) do not count.
        hits = [(te[te > t + 1e-13][0], j) for j, te in enumerate(sol.t_events) if np.any(te > t + 1e-13)]
        if not hits:
            segments.append((sol, sign, t, sol.t[-1]))
            status = "no-impact"
            t = sol.t[-1]
            break
        t_ev, j = min(hits)
        segments.append((sol, sign, t, t_ev))
        if sign == 0.0:
            filippov.append((t, t_ev))
        y = sol.sol(t_ev)
        t = t_ev
        if j == 0:
            t_h = t_ev
            break
        if sign != 0.0 and j == 2:
            status = "painleve"
            break
        if sign != 0.0:
            reversals.append(t_ev)
            sign = _slip_direction(p, y[0], y[1])
            y[3] = -p.ball_radius * y[1]  # v_C = 0 exactly at the switch
        else:
            sign = _slip_direction(p, y[0], y[1]) or (-1.0 if cf.rolling(p, y[0], y[1])[3] > 0 else 1.0)
    ts = np.linspace(0.0, t, n_samples)
    out = np.zeros((8, n_samples))
    for k, tt in enumerate(ts):
        for sol, s, a, b in segments:
            if a <= tt <= b:
                yy = sol.sol(tt)
                th_dd, xo_dd, N, _ = _accelerations(p, yy, s)
                out[:, k] = [yy[0], yy[1], th_dd, yy[2], yy[3], xo_dd, N, s]
                break
    return SlidingHypothesis(ts, *out, reversals=reversals, filippov=filippov, t_horizontal=t_h, status=status)
