"""One entry point for the paper's rod: `simulate(problem, method=...)` → RodRun.

The rod is posed as a general Scene (one body, disk contacts A and B with the floor) and run by
any integrator; this module only translates the general result into the paper's coordinates
(x_O, θ, N and T at ball A) and the summary every method shares.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from .problem import RodProblem
from ..result_files import ROD_SUMMARY_SCHEMA
from ..results import Phase, SimulationResult
from .hypotheses import RollingHypothesis, rolling_hypothesis
from ..solvers.registry import DEFAULT_SOLVER
from ..validation import InputError, require_positive

METHODS = ("event-driven", "moreau-jean", "regularized", "switched", "hybrid")
TRAJECTORY_COLUMNS = ("t", "theta", "theta_dot", "theta_ddot", "x_O", "x_O_dot", "x_O_ddot", "N", "T", "mode")
SUMMARY_SCHEMA = ROD_SUMMARY_SCHEMA
MAX_DURATION = 10.0  # s; without --t-end the run stops at ball B's impact, well before this


@dataclass
class RodRun:
    """A run in the paper's coordinates. `table` and `rolling` are computed when first asked
    for: a sweep point needs neither, and the rolling hypothesis (an ODE solve) would cost
    ten times the Moreau–Jean run itself."""

    problem: RodProblem
    method: str
    result: SimulationResult
    phases: list[Phase]
    impact: dict | None
    settings: dict = field(default_factory=dict)

    @functools.cached_property
    def table(self) -> dict:
        """TRAJECTORY_COLUMNS → arrays."""
        return rod_table(self.problem, self.result)

    @functools.cached_property
    def rolling(self) -> RollingHypothesis:
        return rolling_hypothesis(self.problem)

    @property
    def status(self) -> str:
        return self.result.status

    def summary(self) -> dict:
        r = self.result
        return {
            "schema": SUMMARY_SCHEMA,
            "params": self.problem.as_params(),
            "method": self.method,
            "settings": self.settings,
            "phases": [ph.as_dict() for ph in self.phases],
            "impact": self.impact,
            "rolling_hypothesis": {k: self.rolling.as_dict()[k] for k in ("T_over_N_max", "t_r1", "t_r2")}
            | {"t_max": self.rolling.t_max, "T_over_N_initial": self.rolling.T_over_N_initial},
            "status": r.status,
            "message": r.message,
            "steps": int(r.steps),
            "cpu_time_s": float(r.cpu_time_s),
            "events": [{"t": e.t, "kind": e.kind, "contact": e.contact} for e in r.events],
            "stats": {k: (float(v) if isinstance(v, (int, float, np.floating, np.integer)) else v)
                      for k, v in r.stats.items()},
        }


def rod_table(problem: RodProblem, result: SimulationResult) -> dict:
    """The paper's columns for ball A from the scene's centre-of-mass trajectory."""
    tr = result.trajectory
    (xo, _, th), (xo_dot, _, om) = problem.ball_a_coordinates(tr.q, tr.v)
    th_dd = tr.a[:, 2]
    xo_dd = tr.a[:, 0] + problem.xi * np.cos(th) * om**2 + problem.xi * np.sin(th) * th_dd
    modes = np.where(tr.modes[:, 0] == "open", "flight", tr.modes[:, 0]).astype(object)
    return {"t": tr.t, "theta": th, "theta_dot": om, "theta_ddot": th_dd, "x_O": xo, "x_O_dot": xo_dot,
            "x_O_ddot": xo_dd, "N": tr.normal_force[:, 0], "T": tr.tangential_force[:, 0], "mode": modes}


def _impact_of_b(problem: RodProblem, result: SimulationResult) -> dict | None:
    for imp in result.impacts:
        if imp.contact == "B":
            (xo, _, th), (xo_dot, _, om) = problem.ball_a_coordinates(imp.q, imp.v_before)
            (_, _, _), (xo_dot_after, _, om_after) = problem.ball_a_coordinates(imp.q, imp.v_after)
            return {"t": float(imp.t), "theta": float(th), "theta_dot": float(om), "x_O": float(xo),
                    "x_O_dot": float(xo_dot), "theta_dot_after": float(om_after),
                    "x_O_dot_after": float(xo_dot_after),
                    "normal_impulse_B": float(imp.normal_impulse[1]),
                    "tangential_impulse_B": float(imp.tangential_impulse[1])}
    return None


def simulate(problem: RodProblem | None = None, method: str = "event-driven", *, t_end: float | None = None,
             h: float | None = None, solver: str = DEFAULT_SOLVER, tol: float | None = None, theta: float = 0.5,
             min_phase: float | None = None,
             rtol: float | None = None, output_dt: float = 1e-3, epsilon: float = 1e-4,
             friction_curve: str = "stribeck", ode_method: str | None = None, atol: float | None = None,
             stiffness: float | None = None, damping: float | None = None,
             time_limit: float | None = None, max_step: float | None = None, order: int = 4) -> RodRun:
    """Simulate the paper's rod. Without `t_end` the run stops at ball B's impact.

    The rod is a Scene run by `nonsmooth_rod.simulate` (the "switched" baseline excepted: it
    integrates the paper's own equations of the rod). `rtol` defaults per method (event-driven
    1e-12, regularized and switched 1e-6). The baselines: "regularized" (friction curve
    `friction_curve` of width `epsilon`, penalty contact of `stiffness`/`damping`, scipy
    `ode_method`, atol default rtol·1e-3) and "switched" (the paper's sgn(v_C) equations,
    `ode_method` "rk4" with step h or an adaptive scipy method); h defaults to 1e-4 s, and with
    `tol` (Moreau–Jean's error control, integrators/adaptive.py) it is the first and largest step
    (default 1e-2 s); `time_limit` (wall seconds)
    stops either with status "time-limit"; `max_step` caps the event-driven step. "hybrid":
    Runge–Kutta steps of h (default 1e-2 s) of `order` in each smooth mode (integrators/hybrid.py).
    """
    problem = problem or RodProblem.paper()
    if method not in METHODS:
        raise InputError(f"unknown method '{method}'; choose from: {', '.join(METHODS)}")
    if t_end is not None:
        require_positive("t_end", t_end)
    duration = MAX_DURATION if t_end is None else t_end
    options, settings = _method_options(method, locals())
    if method == "switched":  # the paper's equations of the rod itself, not a scene
        from .switched import SwitchedOptions, SwitchedRod

        result = SwitchedRod(SwitchedOptions(**options)).run(problem, duration)
    else:
        from ..driver import simulate as simulate_scene

        q0, v0 = problem.initial_state()
        result = simulate_scene(problem.scene(), q0, v0, duration, method,
                                stop=None if t_end is not None else "B", **options)
    if t_end is None and result.status == "ok" and not any(i.contact == "B" for i in result.impacts):
        result.set_status("no-impact", f"ball B did not strike the plane within {MAX_DURATION:g} s")
    phases = result.phases.get("A", [])
    phases = [Phase("flight" if p.mode == "open" else p.mode, p.t_start, p.t_end) for p in phases]
    return RodRun(problem, method, result, phases, _impact_of_b(problem, result), settings)


def _method_options(method: str, a: dict) -> tuple[dict, dict]:
    """The method's options from simulate()'s arguments, and the settings the summary records."""
    if method == "moreau-jean":
        from ..integrators.moreau_jean import MoreauJeanOptions

        options = {"h": a["h"], "theta": a["theta"], "solver": a["solver"], "min_phase": a["min_phase"]}
        if a["tol"] is not None:
            options["tol"] = a["tol"]
        resolved = MoreauJeanOptions(**options)
        return options, dict(options, h=resolved.h, min_phase=resolved.min_phase)
    if method == "hybrid" and a["tol"] is None:
        options = {"h": 1e-2 if a["h"] is None else a["h"], "order": a["order"]}
        return options, dict(options)
    if a["tol"] is not None:
        raise InputError(f"tol is Moreau–Jean's error control; method '{method}' has rtol and atol")
    a = dict(a, h=1e-4 if a["h"] is None else a["h"])
    rtol = (1e-12 if method == "event-driven" else 1e-6) if a["rtol"] is None else a["rtol"]
    require_positive("rtol", rtol)
    atol = (rtol if method == "event-driven" else rtol * 1e-3) if a["atol"] is None else a["atol"]
    if method == "event-driven":
        options = {"rtol": rtol, "atol": atol, "output_dt": a["output_dt"]}
        if a["max_step"] is not None:
            options["max_step"] = a["max_step"]
        return options, dict(options)
    if method == "switched":
        options = {"integrator": a["ode_method"] or "rk4", "h": a["h"], "rtol": rtol, "atol": atol,
                   "output_dt": a["output_dt"], "time_limit": a["time_limit"]}
        return options, {"integrator": options["integrator"], "h": a["h"], "rtol": rtol}
    options = {"epsilon": a["epsilon"], "friction_curve": a["friction_curve"], "ode_method": a["ode_method"] or "RK45",
               "rtol": rtol, "atol": atol, "output_dt": a["output_dt"], "time_limit": a["time_limit"]}
    options.update({k: a[k] for k in ("stiffness", "damping", "min_phase") if a[k] is not None})
    from ..integrators.regularized import RegularizedOptions

    o = RegularizedOptions(**options)
    settings = {k: getattr(o, k) for k in ("epsilon", "friction_curve", "ode_method", "rtol", "atol", "contact_model",
                                           "stiffness", "damping", "stick_velocity", "min_phase")}
    return options, settings


def scenario(phases: list[Phase]) -> str:
    """The paper's scenario of a run from ball A's phase sequence (the regime map's classes)."""
    modes = [p.mode for p in phases]
    if not modes:
        return "failed"
    if modes[0] != "stick":
        return "slide-at-start"
    if len(modes) == 1:
        return "roll-to-impact"
    return {"slip-": "roll-until-r1", "slip+": "roll-until-r2"}.get(modes[1], f"roll-then-{modes[1]}")
