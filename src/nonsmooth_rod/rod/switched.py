"""The paper's own formulation of the rod: switched equations, no event location.

Alaci et al. integrate pure rolling until the sampled T/N first leaves [−μs, μs], then the sliding
equations with T = −μd N sgn(v_C) from that sample on, and read the end of the motion off the
sample where the axis is horizontal. This module does exactly that — the sign of the slip velocity
is evaluated inside the right-hand side, the integrator is a fixed-step RK4 or an adaptive scipy
method, and nothing locates the switches — so the study can show what such a scheme does where
the slip velocity reverses:

* where sliding is consistent both ways (|T/N| needed for rolling > μd) it passes through zero,
  and it never tests whether the contact should stick again (with μs ≥ |T/N| it should);
* where neither direction is consistent (|T/N| < μd, a Filippov sliding motion on v_C = 0) the
  sign flips every step: a fixed step chatters about v_C = 0, an adaptive step shrinks
  towards zero (step-size collapse or the time limit).

Only the rod's equations are used (notes.md, eq. 24 with signs restored; model.rod_closed_form).
The end of the run (ball B touches the plane, θ = 0 for equal balls) is interpolated within the
last step, so the impact time is not limited to the step grid.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.integrate import BDF, DOP853, LSODA, RK23, RK45, Radau
from scipy.optimize import brentq

from . import closed_form as cf
from ..results import Event, Impact, SimulationResult, Trajectory, phases_from_intervals
from ..validation import InputError, require_nonnegative, require_positive

ADAPTIVE = {"RK45": RK45, "DOP853": DOP853, "Radau": Radau, "BDF": BDF, "LSODA": LSODA, "RK23": RK23}
SWITCHED_INTEGRATORS = ("rk4",) + tuple(ADAPTIVE)


@dataclass
class SwitchedOptions:
    integrator: str = "rk4"  # fixed-step classic Runge–Kutta, or an adaptive scipy method
    h: float = 1e-4  # step of rk4 (and the first step of the adaptive methods)
    rtol: float = 1e-6
    atol: float = 1e-9
    output_dt: float = 1e-3
    stop_at_impact: bool = True  # stop when the axis is horizontal (ball B touches)
    time_limit: float | None = None  # wall-clock seconds; then status "time-limit"
    max_steps: int = 5_000_000
    min_phase: float = 0.0  # keep every sign flip: the chatter is what this method shows

    def __post_init__(self):
        require_positive("h (step size)", self.h)
        require_positive("rtol", self.rtol)
        require_positive("atol", self.atol)
        require_positive("output_dt", self.output_dt)
        require_nonnegative("min_phase", self.min_phase)
        if self.integrator not in SWITCHED_INTEGRATORS:
            raise InputError(f"unknown integrator '{self.integrator}' for the switched formulation; "
                             f"choose from: {', '.join(SWITCHED_INTEGRATORS)}")
        if self.time_limit is not None:
            require_positive("time_limit", self.time_limit)


class _Stop(Exception):
    def __init__(self, status, message):
        self.status, self.message = status, message


class SwitchedRod:
    """Rolling, then sliding with sgn(v_C) inside the right-hand side, without event location."""

    name = "switched"

    def __init__(self, options: SwitchedOptions | None = None):
        self.options = options or SwitchedOptions()

    # y = (θ, θ̇, x_O, ẋ_O)
    def _accelerations(self, y, rolling: bool):
        p = self._p
        if rolling:
            return cf.rolling(p, y[0], y[1])
        v_c = y[3] + p.ball_radius * y[1]
        s = 1.0 if v_c > 0.0 else (-1.0 if v_c < 0.0 else self._s0)
        if cf.sliding_denominator(p, y[0], y[1], s) <= 0.0:
            raise _Stop("painleve", f"sliding equations lose consistency (J/M + ξ cos θ·D ≤ 0) at θ = {y[0]:.6g}")
        return cf.sliding(p, y[0], y[1], s)

    def _rhs(self, t, y):
        self._nfev += 1
        if self._deadline is not None and self._nfev % 64 == 0 and time.perf_counter() > self._deadline:
            raise _Stop("time-limit", f"wall-clock limit of {self.options.time_limit:g} s reached at t = {t:.9g} s")
        th_dd, xo_dd, _, _ = self._accelerations(y, self._rolling)
        return np.array([y[1], th_dd, y[3], xo_dd])

    def _rk4(self, t, y, h):
        k1 = self._rhs(t, y)
        k2 = self._rhs(t + h / 2, y + h / 2 * k1)
        k3 = self._rhs(t + h / 2, y + h / 2 * k2)
        k4 = self._rhs(t + h, y + h * k3)
        return y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)

    def run(self, problem, t_end: float) -> SimulationResult:
        require_positive("t_end", t_end)
        o = self.options
        p = self._p = problem
        self._nfev = 0
        wall0, cpu0 = time.perf_counter(), time.process_time()
        self._deadline = None if o.time_limit is None else wall0 + o.time_limit
        y = np.array([p.theta0, 0.0, 0.0, 0.0])
        _, _, N0, T0 = cf.rolling(p, p.theta0, 0.0)
        self._rolling = abs(T0) <= p.mu_s * N0
        self._s0 = -math.copysign(1.0, T0)
        ts, ys, modes = [0.0], [y.copy()], []
        start_mode = "stick" if self._rolling else ("slip+" if self._s0 > 0 else "slip-")
        events: list[Event] = [Event(0.0, "start", "A", {"mode": start_mode})]
        impacts: list[Impact] = []
        status, message = "ok", f"reached t_end = {t_end:g} s"
        t, steps, reversals, t_hit = 0.0, 0, 0, None
        last_sign = 0.0
        solver = None
        try:
            while t < t_end - 1e-15:
                if steps >= o.max_steps:
                    raise _Stop("too-many-steps", f"more than {o.max_steps} steps before t = {t:.9g} s")
                if o.integrator == "rk4":
                    h = min(o.h, t_end - t)
                    y_new = self._rk4(t, y, h)
                    t_new = t + h
                    dense = None
                else:
                    if solver is None:
                        solver = ADAPTIVE[o.integrator](self._rhs, t, y, t_end, rtol=o.rtol, atol=o.atol,
                                                        first_step=min(o.h, t_end))
                    msg = solver.step()
                    if solver.status == "failed":
                        raise _Stop("step-size-collapse", f"{o.integrator} failed at t = {solver.t:.9g} s: {msg}")
                    t_new, y_new = solver.t, solver.y.copy()
                    dense = solver.dense_output
                steps += 1
                if not np.all(np.isfinite(y_new)):
                    raise _Stop("nan", f"non-finite state at t = {t_new:.9g} s")
                # The axis reaches the horizontal within this step: interpolate θ = 0.
                if o.stop_at_impact and y_new[0] <= 0.0 < y[0]:
                    if dense is not None:
                        d = dense()
                        t_hit = brentq(lambda tt: d(tt)[0], t, t_new, xtol=1e-14)
                        y_hit = d(t_hit)
                    else:
                        t_hit, y_hit = self._hermite_root(t, y, t_new, y_new)
                    mode = self._mode(y_new)
                    ts.append(t_hit)
                    ys.append(y_hit)
                    modes.append(mode)
                    t = t_hit
                    status, message = "ok", "stopped when the axis became horizontal (ball B touches)"
                    break
                mode = self._mode(y_new)
                if not self._rolling:
                    sign = 1.0 if mode == "slip+" else -1.0
                    if last_sign and sign != last_sign:
                        reversals += 1
                    last_sign = sign
                t, y = t_new, y_new
                ts.append(t)
                ys.append(y.copy())
                modes.append(mode)
                # The paper's test, at the sample only: rolling ends where |T/N| > μs.
                if self._rolling:
                    _, _, N, T = cf.rolling(p, y[0], y[1])
                    if N < 0.0:
                        raise _Stop("liftoff", f"N < 0 at t = {t:.9g} s: ball A would leave the plane")
                    if abs(T) > p.mu_s * N:
                        self._rolling = False
                        self._s0 = -math.copysign(1.0, T)
                        events.append(Event(t, "stick-slip", "A", {"to": "slip+" if self._s0 > 0 else "slip-"}))
                        if solver is not None:  # restart the adaptive method on the new equations
                            solver = ADAPTIVE[o.integrator](self._rhs, t, y, t_end, rtol=o.rtol, atol=o.atol,
                                                            first_step=min(o.h, t_end - t))
                else:
                    _, _, N, _ = cf.sliding(p, y[0], y[1], last_sign)
                    if N < 0.0:
                        raise _Stop("liftoff", f"N < 0 at t = {t:.9g} s: ball A would leave the plane")
        except _Stop as stop:
            status, message = stop.status, stop.message
            events.append(Event(t, status, "", {"message": message}))
        cpu = time.process_time() - cpu0
        nfev = self._nfev
        ts_arr = np.array(ts)
        ys_arr = np.array(ys).reshape(len(ts), 4)
        if t_hit is not None:
            impacts.append(self._impact(t_hit, ys_arr[-1]))
            events.append(Event(t_hit, "impact", "B", {"model": "none (the formulation stops here)"}))
        phases = {}
        if modes:
            phases["A"] = phases_from_intervals(ts_arr, modes, o.min_phase)
            phases["B"] = phases_from_intervals(ts_arr, ["open"] * len(modes))
        traj = self._trajectory(ts_arr, ys_arr, [start_mode] + modes)
        h_arr = np.diff(ts_arr) if len(ts_arr) > 1 else np.array([np.nan])
        stats = {"nfev": nfev, "steps": steps, "reversals": reversals, "min_step": float(np.min(h_arr)),
                 "integrator": o.integrator, "h": o.h, "rtol": o.rtol, "t_final": float(t),
                 "wall_time_s": time.perf_counter() - wall0}
        return SimulationResult(self.name, status, message, traj, ["A", "B"], events, impacts, phases,
                                steps=steps, cpu_time_s=cpu, stats=stats)

    def _mode(self, y) -> str:
        if self._rolling:
            return "stick"
        v_c = y[3] + self._p.ball_radius * y[1]
        s = 1.0 if v_c > 0.0 else (-1.0 if v_c < 0.0 else self._s0)
        return "slip+" if s > 0 else "slip-"

    @staticmethod
    def _hermite_root(t0, y0, t1, y1):
        """θ = 0 on the cubic Hermite interpolant of (θ, θ̇) over one RK4 step; other states linear."""
        h = t1 - t0

        def theta(tt):
            s = (tt - t0) / h
            h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
            h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
            return h00 * y0[0] + h10 * h * y0[1] + h01 * y1[0] + h11 * h * y1[1]

        t_hit = brentq(theta, t0, t1, xtol=1e-15)
        w = (t_hit - t0) / h
        y_hit = (1 - w) * np.asarray(y0) + w * np.asarray(y1)
        y_hit[0] = 0.0
        return t_hit, y_hit

    # ------------------------------------------------------------------ output
    def _com(self, y):
        """Scene coordinates (centre of mass) from (θ, θ̇, x_O, ẋ_O)."""
        p = self._p
        th, om, xo, xo_dot = y[..., 0], y[..., 1], y[..., 2], y[..., 3]
        c, s = np.cos(th), np.sin(th)
        q = np.stack([xo + p.xi * c, p.ball_radius + p.xi * s, th], axis=-1)
        v = np.stack([xo_dot - p.xi * s * om, p.xi * c * om, om], axis=-1)
        return q, v

    def _trajectory(self, ts, ys, modes):
        p = self._p
        keep = self._output_indices(ts)
        ts, ys = ts[keep], ys[keep]
        modes = [modes[k] for k in keep]
        q, v = self._com(ys)
        a = np.full_like(q, np.nan)
        N = np.zeros((len(ts), 2))
        T = np.zeros((len(ts), 2))
        for k, (y, mode) in enumerate(zip(ys, modes)):
            if mode == "stick":
                th_dd, xo_dd, n, tt = cf.rolling(p, y[0], y[1])
            else:
                th_dd, xo_dd, n, tt = cf.sliding(p, y[0], y[1], 1.0 if mode == "slip+" else -1.0)
            c, s = math.cos(y[0]), math.sin(y[0])
            a[k] = (xo_dd - p.xi * (c * y[1] ** 2 + s * th_dd), p.xi * (c * th_dd - s * y[1] ** 2), th_dd)
            N[k, 0], T[k, 0] = n, tt
        mode_arr = np.array([[m, "open"] for m in modes], dtype=object).reshape(len(ts), 2)
        return Trajectory(ts, q, v, a, N, T, mode_arr)

    def _output_indices(self, ts):
        """Step points thinned to about one per output_dt (first and last always kept)."""
        dt = self.options.output_dt
        bins = np.floor(ts / dt + 1e-9)
        keep = np.nonzero(np.diff(bins, prepend=-1.0) > 0)[0].tolist()
        if keep[-1] != len(ts) - 1:
            keep.append(len(ts) - 1)
        return np.array(keep, dtype=int)

    def _impact(self, t_hit, y):
        q, v = self._com(y)
        return Impact(t_hit, "B", q, v, v.copy(), np.zeros(2), np.zeros(2))
