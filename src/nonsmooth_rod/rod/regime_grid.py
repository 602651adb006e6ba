"""The regime map's grid: axes and their ranges, the sweep settings, the keys that match points
when a sweep resumes, and the analytic thresholds of the rolling hypothesis (shared by the sweep,
regime.py, and its figure, regime_figure.py)."""
from __future__ import annotations

import itertools
import math
from dataclasses import asdict, dataclass, field, replace

import numpy as np

from ..studies.runner import (  # noqa: F401  (re-exported)
    KEY_DIGITS, LOCK_NAME, has_repeats, parse_range, point_key, row_key)
from ..solvers.registry import DEFAULT_SOLVER
from ..validation import InputError
from .hypotheses import RollingHypothesis, rolling_hypothesis
from .problem import RodProblem

SCENARIOS = ("slide-at-start", "roll-until-r1", "roll-until-r2", "roll-to-impact")
GEOMETRY_AXES = ("ball_radius", "rod_diameter", "length", "density")
EXTRA_AXES = GEOMETRY_AXES + ("restitution",)
AXES = ("mu_s", "mu_d", "mu_d_ratio", "theta0_deg") + EXTRA_AXES
RESULT_COLUMNS = ("scenario", "status", "t_transition", "t_impact", "theta_impact", "theta_dot_impact",
                  "x_O_dot_impact", "phases")
TEXT_COLUMNS = ("scenario", "status", "phases")
CSV_COLUMNS = ("mu_s", "mu_d", "theta0_deg") + RESULT_COLUMNS  # a μs × μd(or ratio) × θ0 grid's table
CSV_NAME, SETTINGS_NAME, THRESHOLDS_NAME, MAP_NAME = ("regime_map.csv", "sweep.json", "thresholds.csv",
                                                      "regime_map")
PARQUET_NAME = "regime_map.parquet"
SWEEP_SCHEMA = "nonsmooth-rod/sweep/2"
SCENARIO_COLOURS = {"slide-at-start": "#d62728", "roll-until-r1": "#ff9f4a", "roll-until-r2": "#8fbbe0",
                    "roll-to-impact": "#1f5fa8"}
OTHER_COLOUR = "#444444"  # runs that ended with another status (painleve, failed, ...)

# --------------------------------------------------------------------------- one point
@dataclass(frozen=True)
class SweepSettings:
    """How every point is simulated; rows made with other settings are not mixed.

    The default, Moreau–Jean at h = 2e-3 with lemke, runs the compiled whole-run path (about
    0.35 ms a point, 100 times less than the event-driven reference); its scenarios match the
    reference and its transition and impact times lie within 3h = 6 ms of it (checked on a
    random sample in every sweep). The boundaries in μs move by far less than a grid step:
    the first step averages T/N over h, a change of ~1e-4 at most."""

    method: str = "moreau-jean"
    h: float = 2e-3
    solver: str = DEFAULT_SOLVER
    rtol: float | None = None  # None: the method's own default (event-driven 1e-12)

    def simulate_kwargs(self) -> dict:
        # The event-driven samples only feed the phases here; a coarse output grid saves time
        # without touching the located events.
        return dict(h=self.h, solver=self.solver, rtol=self.rtol, output_dt=2e-2)

    @property
    def time_tolerance(self) -> float:
        """How far this method's transition and impact times may lie from the reference: the
        switch is seen at a step boundary, the impact interpolated within a step."""
        return 1e-6 if self.method == "event-driven" else 3.0 * self.h


REFERENCE = SweepSettings(method="event-driven")


def problem_at(base: RodProblem, point: dict) -> RodProblem:
    """The problem at one grid point: `base` with the point's axes (a geometry axis rebuilds
    the mass properties from the geometry)."""
    changes = {"mu_s": point["mu_s"], "mu_d": point["mu_d"], "theta0": math.radians(point["theta0_deg"])}
    if "restitution" in point:
        changes["restitution"] = point["restitution"]
    geometry = {k: point[k] for k in GEOMETRY_AXES if k in point}
    if not geometry:
        return replace(base, **changes)
    if base.geometry is None:
        raise InputError(f"a sweep over {', '.join(geometry)} needs a body given by its geometry, "
                         "not by --mass/--xi/--inertia")
    return RodProblem.from_geometry(replace(base.geometry, **geometry), g=base.g,
                                    restitution=changes.pop("restitution", base.restitution), **changes)


@dataclass
class Thresholds:
    """Boundaries in μs from the pure-rolling hypothesis at one θ0 (and body)."""

    theta0_deg: float
    T_over_N_initial: float
    T_over_N_max: float
    t_max: float
    T_over_N_min: float
    rolling: RollingHypothesis = field(repr=False)
    params: dict = field(default_factory=dict)  # the other axes of the group (geometry, ...)

    def as_row(self) -> dict:
        row = {k: v for k, v in asdict(self).items() if k not in ("rolling", "params")}
        return {"theta0_deg": row.pop("theta0_deg"), **self.params, **row}


def thresholds(base: RodProblem, theta0_deg: float, params: dict | None = None) -> Thresholds:
    """|T/N(0)| (slide-at-start below), max T/N (roll-until-r1 below, the paper's critical
    coefficient) and |min T/N| (roll-to-impact above) of the rolling hypothesis at θ0.
    `params`: geometry axes of a group (the friction does not change the thresholds)."""
    params = dict(params or {})
    point = {"mu_s": base.mu_s, "mu_d": base.mu_d, "theta0_deg": theta0_deg, **params}
    rh = rolling_hypothesis(problem_at(base, point))
    return Thresholds(float(theta0_deg), rh.T_over_N_initial, rh.T_over_N_max, rh.t_max,
                      float(np.min(rh.T_over_N)), rh, params)


def predicted_scenario(rh: RollingHypothesis, mu_s: float) -> tuple[str, float]:
    """(scenario, transition time) the rolling hypothesis predicts for μs: rolling lasts until
    |T/N| first exceeds μs; the side it leaves by fixes the slip direction."""
    r = rh.T_over_N
    if abs(r[0]) > mu_s:
        return "slide-at-start", 0.0
    out = np.nonzero(np.abs(r) > mu_s)[0]
    if out.size == 0:
        return "roll-to-impact", math.nan
    k = int(out[0])  # ≥ 1: the first sample lies inside the band
    level = mu_s if r[k] > 0 else -mu_s
    t = rh.t[k - 1] + (level - r[k - 1]) * (rh.t[k] - rh.t[k - 1]) / (r[k] - r[k - 1])
    return ("roll-until-r1" if r[k] > 0 else "roll-until-r2"), float(t)


# --------------------------------------------------------------------------- grids
# What a sweep accepts per axis (lo, hi, lo open, hi open): beyond these the physics overflows
# or stops being the paper's (a rod of 100 m, a density above osmium's ×5, μ above 100).
AXIS_LIMITS = {"mu_s": (0.0, 100.0, False, False), "mu_d": (0.0, 100.0, False, False),
               "mu_d_ratio": (0.0, 1.0, False, False), "theta0_deg": (0.0, 90.0, True, True),
               "ball_radius": (0.0, 10.0, True, False), "rod_diameter": (0.0, 10.0, True, False),
               "length": (0.0, 100.0, True, False), "density": (0.0, 1e5, True, False),
               "restitution": (0.0, 1.0, False, False)}


def check_axis_values(name: str, values) -> None:
    """Refuse values of axis `name` outside AXIS_LIMITS, naming the option and the range."""
    lo, hi, open_lo, open_hi = AXIS_LIMITS[name]
    v = np.asarray(values, dtype=float)
    bad = v[~((v > lo if open_lo else v >= lo) & (v < hi if open_hi else v <= hi))]
    if bad.size:
        interval = f"{'(' if open_lo else '['}{lo:g}, {hi:g}{')' if open_hi else ']'}"
        raise InputError(f"--{name.replace('_', '-')}: values must lie in {interval}, got {bad[0]:g}")


def _axis_array(name: str, values) -> np.ndarray:
    arr = np.atleast_1d(np.asarray(values, dtype=float)).ravel()
    if arr.size == 0:
        raise InputError(f"--{name.replace('_', '-')}: no values")
    if not np.all(np.isfinite(arr)):
        raise InputError(f"--{name.replace('_', '-')}: values must be finite, got {arr.tolist()}")
    if has_repeats(arr):
        raise InputError(f"--{name.replace('_', '-')}: a value is given twice: {arr.tolist()}")
    return arr


@dataclass
class Grid:
    """The axes of a sweep: μs, θ0 (degrees), μd as a ratio R (μd = R·μs, one value or several)
    or as values (points with μd > μs are left out), and `extra` axes among EXTRA_AXES."""

    mu_s: np.ndarray
    theta0_deg: np.ndarray
    mu_d_ratio: float | np.ndarray | None = None
    mu_d: np.ndarray | None = None
    extra: dict = field(default_factory=dict)

    def __post_init__(self):
        if (self.mu_d_ratio is None) == (self.mu_d is None):
            raise InputError("give either --mu-d-ratio or --mu-d, not both")
        self.mu_s, self.theta0_deg = _axis_array("mu_s", self.mu_s), _axis_array("theta0_deg", self.theta0_deg)
        self.ratios = None if self.mu_d_ratio is None else _axis_array("mu_d_ratio", self.mu_d_ratio)
        if self.mu_d is not None:
            self.mu_d = _axis_array("mu_d", self.mu_d)
        self.extra = {k: _axis_array(k, v) for k, v in (self.extra or {}).items()}
        unknown = sorted(set(self.extra) - set(EXTRA_AXES))
        if unknown:
            raise InputError(f"unknown sweep axis {unknown[0]!r}; axes: {', '.join(AXES)}")
        self._check_ranges()
        if not self.points():
            raise InputError("no grid point has mu_d ≤ mu_s: nothing to sweep")

    def _check_ranges(self):
        check_axis_values("mu_s", self.mu_s)
        check_axis_values("theta0_deg", self.theta0_deg)
        if self.ratios is not None:
            check_axis_values("mu_d_ratio", self.ratios)
        if self.mu_d is not None:
            check_axis_values("mu_d", self.mu_d)
        for name, values in self.extra.items():
            check_axis_values(name, values)

    @property
    def varies_ratio(self) -> bool:
        return self.ratios is not None and self.ratios.size > 1

    @property
    def varies_mu_d(self) -> bool:
        return self.mu_d is not None and len(self.mu_d) > 1

    @property
    def extra_names(self) -> tuple:
        return tuple(k for k in EXTRA_AXES if k in self.extra)

    @property
    def columns(self) -> tuple:
        """The point columns of the table: always μs, μd, θ0; then the ratio and extra axes."""
        return ("mu_s", "mu_d", "theta0_deg") + (("mu_d_ratio",) if self.varies_ratio else ()) + self.extra_names

    @property
    def axes(self) -> dict:
        """Every axis with its values, as given (mu_d_ratio or mu_d)."""
        out = {"mu_s": self.mu_s}
        out |= {"mu_d_ratio": self.ratios} if self.ratios is not None else {"mu_d": self.mu_d}
        return out | {"theta0_deg": self.theta0_deg} | {k: self.extra[k] for k in self.extra_names}

    def groups(self) -> list[dict]:
        """(θ0, extra axes) of each group of points sharing a rolling hypothesis."""
        combos = itertools.product(*(self.extra[k] for k in self.extra_names))
        return [{"theta0_deg": float(th), **dict(zip(self.extra_names, map(float, c)))}
                for c in combos for th in self.theta0_deg]

    def points(self) -> list[tuple]:
        """Every point as a tuple in the order of `columns`; μd ≤ μs (points with μd > μs are
        not physical: left out)."""
        pts = []
        for group in self.groups():
            th, rest = group["theta0_deg"], tuple(group[k] for k in self.extra_names)
            for ms in map(float, self.mu_s):
                if self.ratios is not None:
                    for R in map(float, self.ratios):
                        pts.append((ms, min(ms, R * ms), th) + ((R,) if self.varies_ratio else ()) + rest)
                else:
                    pts.extend((ms, float(md), th) + rest for md in self.mu_d if md <= ms)
        return pts


# --------------------------------------------------------------------------- CSV rows
