"""Speed against accuracy: the work–precision study, the stability study and the failure modes.

Every method runs the paper's three cases over a range of its accuracy knob (event-driven: rtol;
Moreau–Jean: h, per one-step solver, or its error control's tol; hybrid: h of its Runge–Kutta
steps of order 4 between events; regularized: the regularisation velocity ε, per friction curve
and ODE method; switched: h of RK4 or rtol of an adaptive method). Each run is measured
against the event-driven solution at rtol = 1e-12 (the reference):

* impact_error_s — |t_B − t_B,ref|, the time of ball B's impact;
* x_O_error_m — max |x_O(t) − x_O,ref(t)| over the run's own samples up to the earlier of the two
  impacts (the reference interpolated by cubic Hermite on its 1e-4 s samples);
* phases_ok — the same sequence of ball A's modes, every boundary within PHASE_TOLERANCE;
* cpu_s — the integrator's own CPU time; work — right-hand-side evaluations (event-driven,
  hybrid, regularized, switched) or steps (Moreau–Jean).

The stability verdict of a run lists why it is not a right answer: its status (time limit,
step-size collapse, NaN, penetration, Painlevé, Zeno, solver failure, no impact), a wrong phase
sequence, creep where the reference sticks, penetration beyond PENETRATION_BOUND, energy growth.

Every run happens in a child process with a wall-clock limit (at most `workers` at once), so a
method that stalls cannot hang the study; the regularized and switched integrators also stop
themselves a little before the limit, with status "time-limit".
"""
from __future__ import annotations

import math
import multiprocessing
import time
from dataclasses import dataclass

import numpy as np

from .problem import PAPER_CASES, RodProblem
from ..results import Phase
from ..solvers.registry import DEFAULT_SOLVER, EXACT_SOLVERS
from ..validation import InputError

REFERENCE_RTOL = 1e-12
REFERENCE_DT = 1e-4  # s: the reference's samples, on which x_O errors are taken
PHASE_TOLERANCE = 2e-3  # s: a phase boundary further off than this makes the phases wrong
CREEP_BOUND = 1e-4  # m: slip of the contact point during a reference stick phase (0.1 mm)
PENETRATION_BOUND = 1e-4  # m: ADAMS's default penetration depth is 0.1 mm
ENERGY_TOLERANCE = 1e-3  # relative to M g ξ sin θ0, the energy the fall releases
METHOD_NAMES = ("event-driven", "moreau-jean", "hybrid", "regularized", "switched")
CSV_COLUMNS = ("method", "setting", "case", "knob", "cpu_s", "work", "impact_error_s", "x_O_error_m",
               "phases_ok", "status")
STABILITY_COLUMNS = ("method", "setting", "case", "knob", "finished", "right", "reasons", "status",
                     "cpu_s", "work", "impact_error_s", "x_O_error_m", "phase_boundary_error_s", "creep_m",
                     "max_penetration_m", "energy_growth_J", "message")


# ---------------------------------------------------------------------------- what to run
@dataclass(frozen=True)
class RunSpec:
    """One run: `method` with `setting` on paper case `case`, accuracy knob `knob` = `value`."""

    method: str
    setting: str
    case: int
    knob: str
    value: float
    options: tuple = ()  # further keyword arguments of rod.simulation.simulate, as pairs

    @property
    def knob_label(self) -> str:
        return f"{self.knob}={self.value:g}"

    def simulate_kwargs(self) -> dict:
        return dict(self.options) | {self.knob: self.value}


@dataclass(frozen=True)
class Sweep:
    """A method/setting and the knob values it runs over."""

    method: str
    setting: str
    knob: str
    values: tuple
    options: tuple = ()


REGULARIZED_RTOL = 1e-8  # tight enough that ε, not the tolerance, sets the regularised error

FULL_SWEEPS = (
    Sweep("event-driven", "DOP853", "rtol", (1e-3, 1e-4, 1e-6, 1e-8, 1e-10)),
    # every exact solver of the table (the default one down to 1e-5 s), and one QP backend
    *(Sweep("moreau-jean", name, "h", (1e-2, 3e-3, 1e-3, 3e-4, 1e-4) + ((3e-5, 1e-5) if name == DEFAULT_SOLVER else ()),
            (("solver", name),)) for name in EXACT_SOLVERS),
    Sweep("moreau-jean", "osqp", "h", (1e-2, 3e-3, 1e-3, 3e-4), (("solver", "osqp"),)),
    # error control (integrators/adaptive.py): the step sizes chosen for each tolerance
    Sweep("moreau-jean", f"{DEFAULT_SOLVER}, tol", "tol", (1e-3, 1e-4, 1e-5, 1e-6), (("solver", DEFAULT_SOLVER),)),
    # Runge–Kutta of order 4 in each smooth mode, the reference's events (integrators/hybrid.py)
    Sweep("hybrid", "RK4", "h", (1e-1, 5e-2, 2e-2, 1e-2), (("order", 4),)),
    *(Sweep("regularized", f"stribeck/{ode}", "epsilon", (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6),
            (("friction_curve", "stribeck"), ("ode_method", ode), ("rtol", REGULARIZED_RTOL)))
      for ode in ("RK45", "DOP853", "Radau", "BDF", "LSODA")),
    *(Sweep("regularized", f"{curve}/LSODA", "epsilon", (1e-2, 1e-3, 1e-4, 1e-5, 1e-6),
            (("friction_curve", curve), ("ode_method", "LSODA"), ("rtol", REGULARIZED_RTOL)))
      for curve in ("tanh", "linear")),
    Sweep("switched", "rk4", "h", (1e-2, 1e-3, 1e-4, 1e-5), (("ode_method", "rk4"),)),
    Sweep("switched", "RK45", "rtol", (1e-3, 1e-5, 1e-7, 1e-9), (("ode_method", "RK45"),)),
)

QUICK_SWEEPS = (
    Sweep("event-driven", "DOP853", "rtol", (1e-4, 1e-8)),
    Sweep("moreau-jean", DEFAULT_SOLVER, "h", (1e-2, 1e-3), (("solver", DEFAULT_SOLVER),)),
    Sweep("hybrid", "RK4", "h", (5e-2,), (("order", 4),)),
    Sweep("regularized", "stribeck/LSODA", "epsilon", (1e-3, 1e-5),
          (("friction_curve", "stribeck"), ("ode_method", "LSODA"), ("rtol", REGULARIZED_RTOL))),
    Sweep("switched", "rk4", "h", (1e-3,), (("ode_method", "rk4"),)),
)

FULL_TIME_LIMIT = 40.0  # s per run
QUICK_TIME_LIMIT = 10.0


def sweep_specs(cases=(1, 2, 3), methods=METHOD_NAMES, quick: bool = False) -> list[RunSpec]:
    """Every run of the study, cheapest first within a method so a time limit cuts the tail."""
    for c in cases:
        if c not in PAPER_CASES:
            raise InputError(f"paper case must be 1, 2 or 3, got {c!r}")
    for m in methods:
        if m not in METHOD_NAMES:
            raise InputError(f"unknown method '{m}'; choose from: {', '.join(METHOD_NAMES)}")
    specs = []
    for sw in (QUICK_SWEEPS if quick else FULL_SWEEPS):
        if sw.method not in methods:
            continue
        for value in sw.values:
            for case in cases:
                specs.append(RunSpec(sw.method, sw.setting, case, sw.knob, value, sw.options))
    return specs


# ---------------------------------------------------------------------------- the reference
@dataclass
class Reference:
    case: int
    problem: RodProblem
    t_impact: float
    phases: list[Phase]
    t: np.ndarray
    x_O: np.ndarray
    cpu_s: float
    x_O_dot: np.ndarray | None = None

    def x_O_at(self, t) -> np.ndarray:
        """x_O of the reference at any times: cubic Hermite on its samples (x_O and ẋ_O are
        continuous before the impact, so the interpolation error is O(REFERENCE_DT⁴))."""
        from scipy.interpolate import CubicHermiteSpline

        if getattr(self, "_spline", None) is None:
            keep = np.concatenate([[True], np.diff(self.t) > 0])
            self._spline = CubicHermiteSpline(self.t[keep], self.x_O[keep], self.x_O_dot[keep])
        return self._spline(np.asarray(t, dtype=float))


def reference(case: int, problem: RodProblem | None = None) -> Reference:
    """The event-driven solution at its tightest tolerance, sampled every REFERENCE_DT."""
    from .simulation import simulate

    problem = problem or RodProblem.paper(case)
    run = simulate(problem, "event-driven", rtol=REFERENCE_RTOL, output_dt=REFERENCE_DT)
    if run.status != "ok" or run.impact is None:
        raise RuntimeError(f"the reference run of case {case} failed: {run.result.message}")
    t, x = run.table["t"], run.table["x_O"]
    return Reference(case, problem, run.impact["t"], run.phases, t, x, run.result.cpu_time_s, run.table["x_O_dot"])


# ---------------------------------------------------------------------------- measuring a run
def _phase_comparison(phases: list[Phase], ref: list[Phase]) -> tuple[bool, float]:
    """(same mode sequence, largest boundary error in s; inf if the sequences differ)."""
    modes = [p.mode for p in phases]
    ref_modes = [p.mode for p in ref]
    if modes != ref_modes:
        return False, math.inf
    # The last boundary is the impact itself, measured separately.
    bounds = [p.t_end for p in phases[:-1]]
    ref_bounds = [p.t_end for p in ref[:-1]]
    err = max((abs(a - b) for a, b in zip(bounds, ref_bounds)), default=0.0)
    return True, err


def energy_series(problem: RodProblem, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Kinetic + gravitational energy of the rod along a trajectory of centre-of-mass states."""
    m, J = problem.mass, problem.inertia
    return 0.5 * m * (v[:, 0] ** 2 + v[:, 1] ** 2) + 0.5 * J * v[:, 2] ** 2 + m * problem.g * q[:, 1]


def measure(run, ref: Reference) -> dict:
    """Errors and stability signatures of a RodRun against the reference."""
    p = run.problem
    tab = run.table
    t = np.asarray(tab["t"], dtype=float)
    impact_t = run.impact["t"] if run.impact else math.nan
    impact_error = abs(impact_t - ref.t_impact) if run.impact else math.nan
    t_last = float(t[-1]) if t.size else 0.0
    # Compared at the run's own samples, up to the earlier impact (after it the two motions are
    # different phases, not errors of one).
    t_stop = min(ref.t_impact, impact_t if run.impact else t_last)
    span = t <= t_stop
    x_run = np.asarray(tab["x_O"], dtype=float)
    if np.any(span) and np.all(np.isfinite(x_run[span])):
        x_error = float(np.max(np.abs(x_run[span] - ref.x_O_at(t[span]))))
    else:
        x_error = math.nan
    same, boundary_error = _phase_comparison(run.phases, ref.phases)
    phases_ok = bool(same and boundary_error <= PHASE_TOLERANCE and run.status == "ok")
    # Creep: slip of the contact point (x_O + r θ changes only by slip) in reference stick phases.
    slip_coordinate = np.asarray(tab["x_O"], float) + p.ball_radius * np.asarray(tab["theta"], float)
    creep = 0.0
    for ph in ref.phases:
        if ph.mode != "stick":
            continue
        a, b = ph.t_start, min(ph.t_end, t_last)
        inside = (t >= a) & (t <= b)
        if b > a and np.any(inside):
            s0 = np.interp(a, t, slip_coordinate)
            creep = max(creep, float(np.max(np.abs(slip_coordinate[inside] - s0))))
    tr = run.result.trajectory
    (xo, yo, th), _ = p.ball_a_coordinates(tr.q, tr.v)
    gap_a = yo - p.ball_radius
    gap_b = yo + p.length * np.sin(th) - p.ball_radius
    # A time-stepping run's last sample lies after the impact it stopped at (B inside the plane
    # by up to |u_N| h): penetration counts up to the impact only.
    before = tr.t <= impact_t if run.impact else np.ones(tr.t.shape, bool)
    finite = np.isfinite(gap_a) & np.isfinite(gap_b) & before
    penetration = float(max(0.0, -np.min(gap_a[finite], initial=0.0), -np.min(gap_b[finite], initial=0.0)))
    energy = energy_series(p, tr.q, tr.v)
    energy = energy[np.isfinite(energy)]
    energy_growth = float(np.max(energy) - energy[0]) if energy.size else math.nan
    stats = run.result.stats
    # steps solved: with tol, every step evaluated (the rejected and doubled ones too), not only those kept
    work = int(stats.get("step_evaluations", run.result.steps)) if run.method == "moreau-jean" else \
        int(stats.get("nfev", run.result.steps))
    return {"cpu_s": float(run.result.cpu_time_s), "work": work, "impact_t": impact_t,
            "impact_error_s": impact_error, "x_O_error_m": x_error, "phases_ok": phases_ok,
            "phase_sequence_ok": bool(same), "phase_boundary_error_s": boundary_error, "creep_m": creep,
            "max_penetration_m": penetration, "energy_growth_J": energy_growth, "status": run.status,
            "message": run.result.message, "phases": [(ph.mode, ph.t_start, ph.t_end) for ph in run.phases[:50]],
            "n_phases": len(run.phases)}


STATUS_REASONS = {
    "time-limit": "time limit", "killed": "time limit", "step-size-collapse": "step-size collapse",
    "nan": "NaN", "penetration": "penetration beyond bound", "painleve": "Painlevé stop", "zeno": "Zeno stop",
    "failed": "solver failure", "no-impact": "no impact", "liftoff": "liftoff", "error": "error",
    "too-many-steps": "step-size collapse", "too-many-events": "too many events",
}


def verdict(record: dict, problem: RodProblem) -> tuple[bool, bool, list[str]]:
    """(finished, right answer, reasons it is not) for a measured run."""
    status = record["status"]
    finished = status == "ok" and not math.isnan(record.get("impact_error_s", math.nan))
    reasons = []
    if status != "ok":
        reasons.append(STATUS_REASONS.get(status, status))
    elif not finished:
        reasons.append("no impact")
    if finished and not record["phase_sequence_ok"]:
        reasons.append("wrong phase sequence")
    elif finished and record["phase_boundary_error_s"] > PHASE_TOLERANCE:
        reasons.append(f"phase boundary off by {record['phase_boundary_error_s'] * 1e3:.1f} ms")
    if record.get("creep_m", 0.0) > CREEP_BOUND:
        reasons.append("creep at stick")
    if record.get("max_penetration_m", 0.0) > PENETRATION_BOUND:
        reasons.append("penetration beyond bound")
    scale = problem.mass * problem.g * problem.xi * math.sin(problem.theta0)
    if record.get("energy_growth_J", 0.0) > ENERGY_TOLERANCE * scale:
        reasons.append("energy growth")
    return finished, finished and not reasons, reasons


# ---------------------------------------------------------------------------- running with a limit
def _soft_limit(spec: RunSpec, time_limit: float) -> dict:
    """The regularized and switched integrators stop themselves just before the hard limit."""
    if spec.method in ("regularized", "switched"):
        return {"time_limit": max(0.2, 0.85 * time_limit - 0.2)}
    return {}


def run_one(spec: RunSpec, ref: Reference, time_limit: float | None = None) -> dict:
    """Run and measure one spec in this process."""
    from .simulation import simulate

    base = {"method": spec.method, "setting": spec.setting, "case": spec.case, "knob": spec.knob_label,
            "knob_name": spec.knob, "knob_value": spec.value}
    try:
        kwargs = spec.simulate_kwargs() | (_soft_limit(spec, time_limit) if time_limit else {})
        run = simulate(ref.problem, spec.method, **kwargs)
        record = base | measure(run, ref)
    except Exception as err:  # a method that raises is a result of the study, not its end
        record = base | _empty_record("error", f"{type(err).__name__}: {err}")
    return record


def _empty_record(status: str, message: str, cpu: float = math.nan) -> dict:
    return {"cpu_s": cpu, "work": 0, "impact_t": math.nan, "impact_error_s": math.nan, "x_O_error_m": math.nan,
            "phases_ok": False, "phase_sequence_ok": False, "phase_boundary_error_s": math.inf,
            "creep_m": math.nan, "max_penetration_m": math.nan, "energy_growth_J": math.nan,
            "status": status, "message": message, "phases": [], "n_phases": 0}


def _child(spec, ref, time_limit, conn):
    try:
        conn.send(run_one(spec, ref, time_limit))
    finally:
        conn.close()


def _warm_up(specs) -> None:
    """Compile Moreau–Jean's fast path and the hybrid method's mode solve once here: forked
    children inherit them, spawned ones load them from numba's on-disk cache instead of
    compiling them again (within their time limit)."""
    from .simulation import simulate

    if any(s.method == "moreau-jean" for s in specs):
        simulate(RodProblem.paper(2), "moreau-jean", h=1e-2, solver=DEFAULT_SOLVER)
    if any(s.method == "hybrid" for s in specs):
        simulate(RodProblem.paper(2), "hybrid", h=5e-2)


def run_specs(specs: list[RunSpec], refs: dict, time_limit: float, workers: int = 2,
              progress=None) -> list[dict]:
    """Run every spec in a child process (at most `workers` at once), each killed after
    `time_limit` wall seconds (plus a grace of 2 s) and then recorded with status "killed"."""
    if time_limit <= 0:
        raise InputError(f"time limit must be positive, got {time_limit!r}")
    workers = max(1, int(workers))
    _warm_up(specs)
    ctx = multiprocessing.get_context()  # the platform's default start method (no fork on macOS/Windows)
    pending = list(enumerate(specs))
    running: dict[int, tuple] = {}
    results: list[dict | None] = [None] * len(specs)
    base = lambda s: {"method": s.method, "setting": s.setting, "case": s.case, "knob": s.knob_label,  # noqa: E731
                      "knob_name": s.knob, "knob_value": s.value}
    while pending or running:
        while pending and len(running) < workers:
            i, spec = pending.pop(0)
            recv, send = ctx.Pipe(duplex=False)
            proc = ctx.Process(target=_child, args=(spec, refs[spec.case], time_limit, send), daemon=True)
            proc.start()
            send.close()
            running[i] = (proc, recv, time.perf_counter())
        done = []
        for i, (proc, recv, t0) in running.items():
            record = None
            if recv.poll():
                try:
                    record = recv.recv()
                except EOFError:
                    record = base(specs[i]) | _empty_record("error", "the run's process ended without a result")
            elif not proc.is_alive():
                record = base(specs[i]) | _empty_record("error", f"the run's process died (exit code {proc.exitcode})")
            elif time.perf_counter() - t0 > time_limit + 2.0:
                proc.kill()
                record = base(specs[i]) | _empty_record("killed", f"killed after the time limit of {time_limit:g} s",
                                                        cpu=time_limit)
            if record is not None:
                proc.join()
                recv.close()
                results[i] = record
                done.append(i)
                if progress:
                    progress(record)
        for i in done:
            del running[i]
        if running and not done:
            time.sleep(0.005)
    return results


# ---------------------------------------------------------------------------- tables
def work_precision_table(records: list[dict]) -> dict:
    """The columns of work_precision.csv."""
    return {c: [r[c] if c != "phases_ok" else bool(r[c]) for r in records] for c in CSV_COLUMNS}


def stability_records(records: list[dict], refs: dict) -> list[dict]:
    out = []
    for r in records:
        finished, right, reasons = verdict(r, refs[r["case"]].problem)
        out.append(r | {"finished": finished, "right": right, "reasons": "; ".join(reasons)})
    return out


def stability_table(rows: list[dict]) -> dict:
    return {c: [r[c] for r in rows] for c in STABILITY_COLUMNS}


def _fmt_range(values, fmt="{:.3g}") -> str:
    vals = [v for v in values if v is not None and np.isfinite(v)]
    if not vals:
        return "—"
    lo, hi = min(vals), max(vals)
    return fmt.format(lo) if lo == hi else f"{fmt.format(lo)}–{fmt.format(hi)}"


def stability_markdown(rows: list[dict], extra_sections: list[str] = (), command: str = "") -> str:
    """Per method × setting × case: finished, right, why not (per knob value), cost."""
    lines = ["# Stability study", ""]
    if command:
        lines += [f"Reproduce: `{command}`", ""]
    lines += [
        "Each row: one method/setting on one of the paper's cases over its accuracy knob. "
        "*finished* = reached ball B's impact with status ok; *right* = finished with the reference's "
        f"phase sequence (boundaries within {PHASE_TOLERANCE * 1e3:g} ms), no creep beyond "
        f"{CREEP_BOUND * 1e3:g} mm in the reference's stick phases, no penetration beyond "
        f"{PENETRATION_BOUND * 1e3:g} mm, no energy growth beyond {ENERGY_TOLERANCE:g}·M g ξ sin θ0. "
        "Reference: event-driven, rtol 1e-12.", "",
        "| method | setting | case | finished | right | why not (knob: reasons) | CPU s | work |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    keys = []
    for r in rows:
        k = (r["method"], r["setting"], r["case"])
        if k not in keys:
            keys.append(k)
    for k in keys:
        group = [r for r in rows if (r["method"], r["setting"], r["case"]) == k]
        why = "; ".join(f"{r['knob']}: {r['reasons']}" for r in group if r["reasons"]) or "—"
        lines.append(f"| {k[0]} | {k[1]} | {k[2]} | {sum(r['finished'] for r in group)}/{len(group)} | "
                     f"{sum(r['right'] for r in group)}/{len(group)} | {why} | "
                     f"{_fmt_range([r['cpu_s'] for r in group])} | {_fmt_range([r['work'] for r in group], '{:.0f}')} |")
    lines.append("")
    for section in extra_sections:
        lines += [section, ""]
    return "\n".join(lines)


# ---------------------------------------------------------------------------- the chart
def plot_work_precision(records: list[dict], path) -> None:
    """Two log–log panels, CPU seconds against impact-time error and max |x_O error|.

    One curve per method/setting; a point per knob value, at the mean CPU over the cases and
    the worst error over the cases; a hollow marker where some case got the phases wrong.
    Knob values where some case did not finish are left out (stability.md lists them)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..io import atomic_path

    palettes = {"event-driven": ["black"],
                "moreau-jean": ["#08306b", "#17becf", "#6baed6", "#393b79", "#fd8d3c"],
                "regularized": ["#d62728", "#ff7f0e", "#8c564b", "#e377c2", "#9467bd", "#bcbd22", "#7f0000"],
                "switched": ["#2ca02c", "#74c476"], "hybrid": ["#6a3d9a"]}
    styles = {"event-driven": "-", "moreau-jean": "-", "hybrid": "-.", "regularized": "--", "switched": ":"}
    markers = ["o", "s", "^", "D", "v", "P", "X"]
    groups: dict[tuple, dict] = {}
    for r in records:
        groups.setdefault((r["method"], r["setting"]), {}).setdefault(r["knob_value"], []).append(r)
    fig, axes = plt.subplots(1, 2, figsize=(14, 6.6), constrained_layout=True)
    index: dict[str, int] = {}
    floor = 1e-12
    for (method, setting), by_value in groups.items():
        j = index.get(method, 0)
        index[method] = j + 1
        palette = palettes.get(method, ["gray"])
        colour = palette[j % len(palette)]
        pts = []
        for value, rs in by_value.items():
            if not all(x["status"] == "ok" and np.isfinite(x["impact_error_s"]) for x in rs):
                continue
            pts.append((value, float(np.mean([x["cpu_s"] for x in rs])),
                        max(max(x["impact_error_s"] for x in rs), floor),
                        max(max(x["x_O_error_m"] for x in rs), floor), all(x["phases_ok"] for x in rs)))
        if not pts:
            continue
        pts.sort(key=lambda p: -p[0])  # from the loosest knob value to the tightest
        knob = next(iter(by_value.values()))[0]["knob_name"]
        knob = {"epsilon": "ε", "rtol": "rtol", "h": "h"}.get(knob, knob)
        label = f"{method} / {setting} ({knob} {pts[0][0]:g} → {pts[-1][0]:g})"
        for ax, col in zip(axes, (2, 3)):
            ax.plot([p[1] for p in pts], [p[col] for p in pts], color=colour, ls=styles.get(method, "-"), lw=1.3,
                    label=label if ax is axes[0] else None)
            for p in pts:
                ax.plot(p[1], p[col], marker=markers[j % len(markers)], ms=6, color=colour,
                        mfc=colour if p[4] else "white", ls="none")
    axes[0].set(xscale="log", yscale="log", xlabel="CPU time per run [s] (mean over the cases)",
                ylabel="|t_impact − t_impact,ref| [s] (worst case)", title="impact time of ball B")
    axes[1].set(xscale="log", yscale="log", xlabel="CPU time per run [s] (mean over the cases)",
                ylabel="max |x_O − x_O,ref| [m] (worst case)", title="position of ball A over the motion")
    for ax in axes:
        ax.grid(True, which="major", alpha=0.4)
        ax.grid(True, which="minor", alpha=0.1)
    fig.legend(loc="outside lower center", ncol=3, fontsize=8, frameon=False)
    fig.suptitle("Work–precision on the paper's cases (reference: event-driven, rtol 1e-12); "
                 "hollow marker = wrong phases in some case")
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    plt.close(fig)


# ---------------------------------------------------------------------------- failure modes
def bistable_map(epsilons=(1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6), tolerances=(1e-3, 1e-5, 1e-7, 1e-9),
                 ode_method: str = "BDF", time_limit: float | None = 30.0) -> list[dict]:
    """Case 2's bistable start under the Stribeck curve: which (ε, rtol) roll, which slide.

    The exact solution rolls (T/N = 0.263 at release lies between μd = 0.20 and μs = 0.28) until
    T/N reaches μs at t = 0.1041 s. "rolls" = the first phase sticks for at least 90 % of that."""
    from .simulation import simulate

    ref = reference(2)
    t_break = ref.phases[0].t_end
    out = []
    for eps in epsilons:
        for tol in tolerances:
            run = simulate(RodProblem.paper(2), "regularized", epsilon=eps, rtol=tol, ode_method=ode_method,
                           friction_curve="stribeck", time_limit=time_limit)
            first = run.phases[0] if run.phases else None
            rolls = bool(first and first.mode == "stick" and first.t_end >= 0.9 * t_break)
            m = measure(run, ref)
            out.append({"epsilon": eps, "rtol": tol, "ode_method": ode_method, "status": run.status,
                        "rolls": rolls, "stick_until": first.t_end if first and first.mode == "stick" else 0.0,
                        "impact_shift_s": (m["impact_t"] - ref.t_impact), "phases_ok": m["phases_ok"],
                        "cpu_s": m["cpu_s"], "work": m["work"]})
    return out


def bistable_markdown(rows: list[dict]) -> str:
    eps = sorted({r["epsilon"] for r in rows}, reverse=True)
    tols = sorted({r["rtol"] for r in rows}, reverse=True)
    method = rows[0]["ode_method"] if rows else ""
    lines = [f"## The bistable start of case 2 (μs, μd) = (0.28, 0.20): Stribeck curve, {method}", "",
             "Cell: what the start does (rolls = sticks until ≥ 90 % of the exact break-away at "
             "0.1041 s), then the impact-time shift of ball B against the reference (ms). "
             "✓ = the reference's phases (roll, slide left, slide right) within 2 ms.", "",
             "| ε [m/s] \\ rtol | " + " | ".join(f"{t:g}" for t in tols) + " |",
             "| --- | " + " | ".join("---" for _ in tols) + " |"]
    for e in eps:
        cells = []
        for t in tols:
            r = next((x for x in rows if x["epsilon"] == e and x["rtol"] == t), None)
            if r is None:
                cells.append("")
            elif r["status"] != "ok":
                cells.append(f"✗ {r['status']}")
            else:
                what = "rolls" if r["rolls"] else f"slides at {r['stick_until'] * 1e3:.0f} ms"
                mark = "✓" if r["phases_ok"] else "✗"
                cells.append(f"{mark} {what}, {r['impact_shift_s'] * 1e3:+.2f} ms")
        lines.append(f"| {e:g} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def epsilon_study(epsilons=(1e-3, 1e-4, 1e-5), ode_methods=("RK45", "LSODA"), case: int = 3,
                  t_end: float = 0.05, stiffness: float = 2e8, rtol: float = 1e-6) -> list[dict]:
    """Creep and cost against ε in a stick phase (case 3 sticks until 0.302 s).

    A softer contact than the default (2e8 N/m^1.5) keeps the contact's own stiffness from
    capping the explicit step, so what limits it is the friction curve's slope μ N/ε."""
    from .simulation import simulate

    p = RodProblem.paper(case)
    out = []
    for ode in ode_methods:
        for eps in epsilons:
            run = simulate(p, "regularized", epsilon=eps, ode_method=ode, rtol=rtol, t_end=t_end,
                           stiffness=stiffness, friction_curve="stribeck")
            tab = run.table
            creep = np.abs(tab["x_O"] + p.ball_radius * (tab["theta"] - p.theta0))
            out.append({"ode_method": ode, "epsilon": eps, "status": run.status, "nfev": run.result.stats["nfev"],
                        "steps": run.result.steps, "median_step": run.result.stats["median_step"],
                        "creep_m": float(creep[-1]), "creep_velocity": float(creep[-1] / tab["t"][-1]),
                        "cpu_s": run.result.cpu_time_s})
    return out


def epsilon_markdown(rows: list[dict], t_end: float = 0.05) -> str:
    lines = ["## Regularised friction against ε: creep and cost (case 3's stick phase, first "
             f"{t_end * 1e3:g} ms, Stribeck curve, contact stiffness 2e8 N/m^1.5)", "",
             "| ODE method | ε [m/s] | creep of the contact point [m] | median step [s] | RHS evaluations | CPU s |",
             "| --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        lines.append(f"| {r['ode_method']} | {r['epsilon']:g} | {r['creep_m']:.3g} | {r['median_step']:.3g} | "
                     f"{r['nfev']} | {r['cpu_s']:.3g} |")
    return "\n".join(lines)


RESTICK_CASE = (0.28, 0.24)  # the reference rolls, slides left, sticks again (0.2806–0.2921 s), slides right


def switched_study(h_values=(1e-3, 1e-4), adaptive=("RK45",), time_limit: float = 20.0) -> list[dict]:
    """The switched formulation where the reference re-sticks after a slip reversal."""
    from .simulation import simulate

    p = RodProblem.paper(None, mu_s=RESTICK_CASE[0], mu_d=RESTICK_CASE[1])
    ref = reference(0, p)
    rows = [{"integrator": "event-driven (reference)", "knob": "rtol=1e-12", "status": "ok",
             "modes": [ph.mode for ph in ref.phases], "reversals": 0, "n_phases": len(ref.phases),
             "impact_error_s": 0.0, "steps": 0, "min_step": math.nan, "cpu_s": ref.cpu_s}]
    runs = [("rk4", {"h": h}, f"h={h:g}") for h in h_values] + [(a, {"rtol": 1e-6}, "rtol=1e-06") for a in adaptive]
    for integ, kw, label in runs:
        run = simulate(p, "switched", ode_method=integ, time_limit=time_limit, **kw)
        m = measure(run, ref)
        modes = [ph.mode for ph in run.phases]
        rows.append({"integrator": integ, "knob": label, "status": run.status, "modes": modes,
                     "reversals": run.result.stats["reversals"], "n_phases": len(run.phases),
                     "impact_error_s": m["impact_error_s"], "steps": run.result.steps,
                     "min_step": run.result.stats["min_step"], "cpu_s": run.result.cpu_time_s})
    return rows


def switched_markdown(rows: list[dict]) -> str:
    lines = [f"## The switched formulation at a slip reversal: (μs, μd) = {RESTICK_CASE}", "",
             "The reference rolls, slides left, sticks again at the reversal (μd < |T/N| ≤ μs) and "
             "then slides right.", "",
             "| integrator | knob | status | phases (first 6) | sign flips of v_C | steps | min step [s] | impact error [s] |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        modes = " → ".join(r["modes"][:6]) + (" → …" if len(r["modes"]) > 6 else "")
        lines.append(f"| {r['integrator']} | {r['knob']} | {r['status']} | {modes} ({r['n_phases']}) | "
                     f"{r['reversals']} | {r['steps']} | {r['min_step']:.3g} | {r['impact_error_s']:.3g} |")
    return "\n".join(lines)


def painleve_and_zeno(h: float = 1e-3) -> dict:
    """Where the event-driven reference stops and Moreau–Jean goes on with bounded energy."""
    from .. import toys

    out = {}
    rod = toys.PainleveRod()
    scene = rod.scene()
    # rtol 1e-10 finds the band edge to 1e-12 rad (tests/toys/test_painleve.py) in a tenth of
    # the time 1e-12 takes: the steps shrink as A → 0 until the stall is recognised
    ed = toys.run(rod, "event-driven", 0.2, rtol=1e-10)
    mj = toys.run(rod, "moreau-jean", 0.2, h=h)
    e_mj = np.array([scene.energy(q, v) for q, v in zip(mj.trajectory.q, mj.trajectory.v)])
    out["painleve"] = {"ed_status": ed.status, "ed_t_stop": float(ed.t[-1]), "mj_status": mj.status,
                       "mj_t_end": float(mj.t[-1]), "E0": float(e_mj[0]), "mj_E_max": float(e_mj.max()),
                       "mj_E_end": float(e_mj[-1]), "band_deg": [math.degrees(x) for x in rod.painleve_band()]}
    ball = toys.BouncingBall(drop_height=0.1, restitution=0.5)
    scene = ball.scene()
    ed = toys.run(ball, "event-driven", 1.0)
    mj = toys.run(ball, "moreau-jean", 1.0, h=h)
    e_mj = np.array([scene.energy(q, v) for q, v in zip(mj.trajectory.q, mj.trajectory.v)])
    e_rest = scene.energy(np.array([0.0, ball.radius, 0.0]), np.zeros(3))
    out["zeno"] = {"ed_status": ed.status, "ed_t_stop": float(ed.t[-1]), "zeno_time": ball.zeno_time,
                   "ed_impacts": len(ed.impacts), "mj_status": mj.status, "mj_t_end": float(mj.t[-1]),
                   "E0": float(e_mj[0]), "mj_E_max": float(e_mj.max()), "mj_E_end": float(e_mj[-1]),
                   "E_rest": float(e_rest), "mj_final_height": float(mj.trajectory.q[-1, 1] - ball.radius),
                   "mj_final_speed": float(abs(mj.trajectory.v[-1, 1]))}
    return out


def theta_energy(thetas=(0.3, 0.5, 1.0), h: float = 1e-2, drop_height: float = 1.0) -> list[dict]:
    """Moreau–Jean's θ and energy: a ball's free fall gains (½ − θ) m g² h² per step.

    The default options refuse θ < ½; allow_energy_gain=True runs it for this study."""
    from .. import toys
    from ..integrators.moreau_jean import MoreauJean, MoreauJeanOptions

    ball = toys.BouncingBall(drop_height=drop_height, restitution=0.9)
    scene = ball.scene()
    q0, v0 = ball.initial_state()
    rows = []
    for th in thetas:
        run = MoreauJean(MoreauJeanOptions(h=h, theta=th, allow_energy_gain=True, fast=False)).run(scene, q0, v0, 2.0)
        e = np.array([scene.energy(q, v) for q, v in zip(run.trajectory.q, run.trajectory.v)])
        first = run.impacts[0].t if run.impacts else 2.0
        n_free = int(np.sum(run.t < first - h))  # steps of free fall before the first impact
        rows.append({"theta": th, "h": h, "E0": float(e[0]), "gain_before_impact": float(e[n_free] - e[0]),
                     "predicted_gain": (0.5 - th) * ball.mass * ball.g**2 * h**2 * n_free, "steps": n_free,
                     "E_max": float(e.max()), "E_end": float(e[-1])})
    return rows


def failure_markdown(pz: dict, theta_rows: list[dict]) -> str:
    pa, ze = pz["painleve"], pz["zeno"]
    lines = ["## Where the event-driven reference stops and Moreau–Jean does not", "",
             f"* Painlevé (toys.PainleveRod: thin rod, μ = 2, end sliding at −10 m/s from 30°; "
             f"inconsistent band {pa['band_deg'][0]:.1f}°–{pa['band_deg'][1]:.1f}°): event-driven "
             f"**{pa['ed_status']}** at t = {pa['ed_t_stop']:.4f} s; Moreau–Jean (h = 1e-3) **{pa['mj_status']}** "
             f"to t = {pa['mj_t_end']:.2f} s, energy {pa['E0']:.2f} J → max {pa['mj_E_max']:.2f} J, "
             f"end {pa['mj_E_end']:.2f} J (never above the start).",
             f"* Zeno (ball dropped from 0.1 m, e = 0.5): event-driven **{ze['ed_status']}** at "
             f"t = {ze['ed_t_stop']:.6f} s after {ze['ed_impacts']} impacts (closed form: "
             f"{ze['zeno_time']:.6f} s); Moreau–Jean **{ze['mj_status']}** to t = {ze['mj_t_end']:.1f} s, "
             f"ends at rest (height {ze['mj_final_height']:.2e} m, speed {ze['mj_final_speed']:.1e} m/s), "
             f"energy {ze['E0']:.4f} J → max {ze['mj_E_max']:.4f} J, end {ze['mj_E_end']:.4f} J "
             f"(rest: {ze['E_rest']:.4f} J).", "",
             "## Moreau–Jean's θ: energy (a falling ball, h = 1e-2; θ < ½ needs allow_energy_gain=True)", "",
             "| θ | energy gained before the first impact [J] | predicted (½ − θ) m g² h² n [J] | max energy / start |",
             "| --- | --- | --- | --- |"]
    for r in theta_rows:
        lines.append(f"| {r['theta']:g} | {r['gain_before_impact']:.4g} | {r['predicted_gain']:.4g} | "
                     f"{r['E_max'] / r['E0']:.5f} |")
    return "\n".join(lines)
