"""The regime map: which of the paper's scenarios each (μs, μd, θ0) produces.

The paper's scenarios (its Figs. 10–12), read from a simulated run's phase sequence at ball A:

* ``slide-at-start``  μs cannot hold the start: |T/N(0)| > μs under rolling;
* ``roll-until-r1``   rolling, then sliding (v_C < 0) when T/N rises to +μs;
* ``roll-until-r2``   rolling, then sliding (v_C > 0) when T/N falls to −μs;
* ``roll-to-impact``  rolling all the way to ball B's impact.

A run that ends otherwise is recorded with its status as the scenario ("painleve", "no-impact",
"failed"). The rolling hypothesis alone predicts the scenario (`predicted_scenario`): the first
time |T/N| leaves [−μs, μs] and which side it leaves by. Its boundaries in μs are |T/N(0)|,
max T/N (the critical coefficient, ≈ 0.290 at θ0 = 60°) and |min T/N| — the value at the
horizontal, ≈ 1.968 at 60°: rolling to the impact needs a rubber-like μs.

`sweep` runs a grid in worker processes, appending each finished row to
DIR/regime_map.csv at once (flushed), so an interrupted sweep resumes where it stopped; the
final CSV is rewritten sorted, atomically. DIR/sweep.json records the settings the rows were
made with; a sweep with other settings refuses to mix its rows into the same folder.
"""
from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import os
import sys
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np

from ..io import dumps_json, write_csv, write_json, write_text
from .problem import RodProblem
from .hypotheses import RollingHypothesis, rolling_hypothesis
from ..validation import InputError

SCENARIOS = ("slide-at-start", "roll-until-r1", "roll-until-r2", "roll-to-impact")
CSV_COLUMNS = ("mu_s", "mu_d", "theta0_deg", "scenario", "t_transition", "t_impact", "phases")
CSV_NAME, SETTINGS_NAME, THRESHOLDS_NAME, MAP_NAME = ("regime_map.csv", "sweep.json", "thresholds.csv",
                                                      "regime_map")
LOCK_NAME = ".sweep.lock"
SWEEP_SCHEMA = "nonsmooth-rod/sweep/1"
SCENARIO_COLOURS = {"slide-at-start": "#d62728", "roll-until-r1": "#ff9f4a", "roll-until-r2": "#8fbbe0",
                    "roll-to-impact": "#1f5fa8"}
OTHER_COLOUR = "#444444"  # runs that ended with another status (painleve, failed, ...)
KEY_DIGITS = 12  # grid values are matched to this many decimals when resuming


# --------------------------------------------------------------------------- one point
@dataclass(frozen=True)
class SweepSettings:
    """How every point is simulated; rows made with other settings are not mixed."""

    method: str = "event-driven"
    h: float = 1e-4
    solver: str = "lemke"
    rtol: float | None = None  # None: the method's own default (event-driven 1e-12)

    def simulate_kwargs(self) -> dict:
        # The event-driven samples only feed the phases here; a coarse output grid saves time
        # without touching the located events.
        return dict(h=self.h, solver=self.solver, rtol=self.rtol, output_dt=2e-2)


def phases_text(phases) -> str:
    """'stick 0.000000..0.104101; slip- 0.104101..0.302350; ...' (times in s)."""
    return "; ".join(f"{ph.mode} {ph.t_start:.6f}..{ph.t_end:.6f}" for ph in phases)


def scenario_of(phases, status: str = "ok") -> str:
    """The paper's scenario from ball A's phase sequence; the status word if the run failed."""
    from .simulation import scenario

    return status if status != "ok" else scenario(phases)


def classify_point(base: RodProblem, mu_s: float, mu_d: float, theta0_deg: float,
                   settings: SweepSettings = SweepSettings()) -> dict:
    """Simulate one grid point and return its CSV row.

    t_transition: when rolling ends (0 for slide-at-start; NaN if it never ends);
    t_impact: ball B's impact (NaN if none)."""
    from .simulation import simulate

    row = {"mu_s": float(mu_s), "mu_d": float(mu_d), "theta0_deg": float(theta0_deg)}
    try:
        problem = replace(base, mu_s=mu_s, mu_d=mu_d, theta0=math.radians(theta0_deg))
        run = simulate(problem, settings.method, **settings.simulate_kwargs())
    except Exception as err:  # one bad point must not end a long sweep; it is recorded
        message = " ".join(f"{type(err).__name__}: {err}".split())
        return row | {"scenario": "failed", "t_transition": math.nan, "t_impact": math.nan,
                      "phases": message[:200]}
    scenario = scenario_of(run.phases, run.status)
    if scenario == "slide-at-start":
        t_transition = 0.0
    elif run.phases and run.phases[0].mode == "stick" and len(run.phases) > 1:
        t_transition = float(run.phases[0].t_end)
    else:
        t_transition = math.nan
    t_impact = float(run.impact["t"]) if run.impact else math.nan
    return row | {"scenario": scenario, "t_transition": t_transition, "t_impact": t_impact,
                  "phases": phases_text(run.phases)}


def _classify_chunk(base: RodProblem, settings: SweepSettings, points) -> list[dict]:
    return [classify_point(base, *pt, settings=settings) for pt in points]


# --------------------------------------------------------------------------- analytic thresholds
@dataclass
class Thresholds:
    """Boundaries in μs from the pure-rolling hypothesis at one θ0."""

    theta0_deg: float
    T_over_N_initial: float
    T_over_N_max: float
    t_max: float
    T_over_N_min: float
    rolling: RollingHypothesis = field(repr=False)

    def as_row(self) -> dict:
        return {k: v for k, v in asdict(self).items() if k != "rolling"}


def thresholds(base: RodProblem, theta0_deg: float) -> Thresholds:
    """|T/N(0)| (slide-at-start below), max T/N (roll-until-r1 below, the paper's critical
    coefficient) and |min T/N| (roll-to-impact above) of the rolling hypothesis at θ0."""
    rh = rolling_hypothesis(replace(base, theta0=math.radians(theta0_deg)))
    return Thresholds(float(theta0_deg), rh.T_over_N_initial, rh.T_over_N_max, rh.t_max,
                      float(np.min(rh.T_over_N)), rh)


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
def parse_range(text: str, name: str, *, max_count: int = 2000) -> np.ndarray:
    """'START:STOP:N' (N values, ends included), 'a,b,c' or a single number."""
    text = str(text).strip()
    usage = f"{name}: expected START:STOP:N, a,b,c or a number, got {text!r}"
    if ":" in text:
        parts = text.split(":")
        if len(parts) != 3:
            raise InputError(usage)
        try:
            start, stop = float(parts[0]), float(parts[1])
        except ValueError:
            raise InputError(usage) from None
        if not parts[2].strip().isdigit():
            raise InputError(f"{name}: the count N in START:STOP:N must be a positive integer, got {parts[2]!r}")
        count = int(parts[2])
        if not 1 <= count <= max_count:
            raise InputError(f"{name}: the count N must lie in [1, {max_count}], got {count}")
        if count == 1 and start != stop:
            raise InputError(f"{name}: one value between {start:g} and {stop:g}? give N ≥ 2 or a single number")
        values = np.linspace(start, stop, count)
    else:
        try:
            values = np.array([float(x) for x in text.split(",")])
        except ValueError:
            raise InputError(usage) from None
    if not np.all(np.isfinite(values)):
        raise InputError(f"{name}: values must be finite, got {text!r}")
    if values.size > max_count:
        raise InputError(f"{name}: at most {max_count} values, got {values.size}")
    return values


@dataclass
class Grid:
    mu_s: np.ndarray
    theta0_deg: np.ndarray
    mu_d_ratio: float | None = None
    mu_d: np.ndarray | None = None

    def __post_init__(self):
        if np.any(self.mu_s < 0):
            raise InputError("--mu-s: friction coefficients must be non-negative")
        if np.any((self.theta0_deg <= 0) | (self.theta0_deg >= 90)):
            raise InputError("--theta0-deg: values must lie in (0, 90)")
        if (self.mu_d_ratio is None) == (self.mu_d is None):
            raise InputError("give either --mu-d-ratio or --mu-d, not both")
        if self.mu_d_ratio is not None and not 0.0 <= self.mu_d_ratio <= 1.0:
            raise InputError(f"--mu-d-ratio must lie in [0, 1] (μd ≤ μs), got {self.mu_d_ratio:g}")
        if self.mu_d is not None and np.any(self.mu_d < 0):
            raise InputError("--mu-d: friction coefficients must be non-negative")
        if not self.points():
            raise InputError("no grid point has mu_d ≤ mu_s: nothing to sweep")

    def points(self) -> list[tuple[float, float, float]]:
        """(μs, μd, θ0°) of every point, μd ≤ μs (points with μd > μs are not physical: left out)."""
        pts = []
        for th in self.theta0_deg:
            for ms in self.mu_s:
                if self.mu_d_ratio is not None:
                    pts.append((float(ms), min(float(ms), float(self.mu_d_ratio * ms)), float(th)))
                else:
                    pts.extend((float(ms), float(md), float(th)) for md in self.mu_d if md <= ms)
        return pts

    @property
    def varies_mu_d(self) -> bool:
        return self.mu_d is not None and len(self.mu_d) > 1


def point_key(mu_s, mu_d, theta0_deg) -> tuple:
    return (round(float(mu_s), KEY_DIGITS), round(float(mu_d), KEY_DIGITS), round(float(theta0_deg), KEY_DIGITS - 2))


# --------------------------------------------------------------------------- CSV rows
def _cell(value) -> str:
    if isinstance(value, float):
        return "" if math.isnan(value) else f"{value:.17g}"
    return str(value)


def _row_line(row: dict) -> str:
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerow([_cell(row[c]) for c in CSV_COLUMNS])
    return buf.getvalue()


def _parse_row(fields: list[str]) -> dict | None:
    if len(fields) != len(CSV_COLUMNS):
        return None
    try:
        row = dict(zip(CSV_COLUMNS, fields))
        for c in ("mu_s", "mu_d", "theta0_deg"):
            row[c] = float(row[c])
        for c in ("t_transition", "t_impact"):
            row[c] = float(row[c]) if row[c] != "" else math.nan
    except ValueError:
        return None
    if not row["scenario"] or not all(math.isfinite(row[c]) for c in ("mu_s", "mu_d", "theta0_deg")):
        return None
    return row


def read_rows(path) -> tuple[list[dict], int]:
    """Rows of a regime_map.csv and the number of unreadable lines (an interrupted write)."""
    path = Path(path)
    text = path.read_text(encoding="utf-8")
    if text and not text.endswith("\n"):
        # Every row is written with its newline: a last line without one was cut mid-write,
        # even if its cells happen to parse (a truncated phases text would).
        text = text[: text.rfind("\n") + 1]
    lines = list(csv.reader(io.StringIO(text, newline="")))
    if not lines:
        return [], 0
    if tuple(lines[0]) != CSV_COLUMNS:
        raise InputError(f"{path} does not start with the header {','.join(CSV_COLUMNS)}: not a regime map")
    rows, bad = [], 0
    for fields in lines[1:]:
        row = _parse_row(fields)
        if row is None:
            bad += 1
        else:
            rows.append(row)
    return rows, bad


def sorted_rows(rows) -> list[dict]:
    unique = {point_key(r["mu_s"], r["mu_d"], r["theta0_deg"]): r for r in rows}
    return [unique[k] for k in sorted(unique, key=lambda k: (k[2], k[1], k[0]))]


def write_rows(path, rows) -> None:
    write_text(path, ",".join(CSV_COLUMNS) + "\n" + "".join(_row_line(r) for r in sorted_rows(rows)))


def rows_as_columns(rows) -> dict:
    return {c: np.array([r[c] for r in rows], dtype=object if c in ("scenario", "phases") else float)
            for c in CSV_COLUMNS}


# --------------------------------------------------------------------------- the sweep
@dataclass
class SweepResult:
    out_dir: Path
    rows: list[dict]          # every row of the final CSV (this grid's and earlier ones'), sorted
    grid_rows: list[dict]     # this grid's rows
    computed: int
    reused: int
    thresholds: list[Thresholds]
    files: list[Path]


def _settings_record(base: RodProblem, settings: SweepSettings) -> dict:
    body = {k: v for k, v in base.as_params().items() if k not in ("mu_s", "mu_d", "theta0_deg", "theta0_rad")}
    return {"schema": SWEEP_SCHEMA, "settings": asdict(settings), "body": body}


def _prepare_folder(out_dir: Path, record: dict) -> list[dict]:
    """Check a folder's earlier sweep is compatible; return its readable rows."""
    csv_path, settings_path = out_dir / CSV_NAME, out_dir / SETTINGS_NAME
    if settings_path.exists():
        try:
            old = json.loads(settings_path.read_text(encoding="utf-8"))
        except (json.JSONDecodeError, UnicodeDecodeError):
            raise InputError(f"{settings_path} is not valid JSON: remove it or use another --out") from None
        if json.loads(dumps_json(old)) != json.loads(dumps_json(record)):
            raise InputError(f"{out_dir} holds a sweep made with other settings or another body "
                             f"(see {settings_path}): use another --out or remove the folder")
    elif csv_path.exists():
        raise InputError(f"{csv_path} exists without {SETTINGS_NAME}: not a sweep folder of this "
                         "program; use another --out")
    rows = []
    if csv_path.exists():
        rows, _bad = read_rows(csv_path)
    write_json(settings_path, record)
    # Rewrite what was readable (dropping a half-written last line) before appending to it.
    write_rows(csv_path, rows)
    return rows


@contextlib.contextmanager
def folder_lock(out_dir: Path):
    """Refuse a second sweep writing into the same folder at the same time (their appends
    would interleave). An advisory lock, released by the system if the process dies."""
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock
        yield
        return
    path = out_dir / LOCK_NAME
    fh = open(path, "w")
    try:
        fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        fh.close()
        raise InputError(f"another sweep is writing to {out_dir} (it holds {path}): wait for it or use "
                         "another --out") from None
    try:
        yield
    finally:
        with contextlib.suppress(OSError):
            path.unlink()
        fh.close()


def _chunks(points, size):
    return [points[i:i + size] for i in range(0, len(points), size)]


def sweep(base: RodProblem, grid: Grid, out_dir, settings: SweepSettings = SweepSettings(), *,
          jobs: int = 2, progress: bool = False, plot: bool = True, formats=("png",), dpi: int = 110) -> SweepResult:
    """Classify every grid point (skipping the ones out_dir already holds), write the CSVs and
    the map; see the module doc."""
    if jobs < 1:
        raise InputError(f"jobs must be at least 1, got {jobs}")
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError(f"--out '{out_dir}' exists and is not a folder")
    out_dir.mkdir(parents=True, exist_ok=True)
    with folder_lock(out_dir):
        return _sweep(base, grid, out_dir, settings, jobs, progress, plot, formats, dpi)


def _sweep(base, grid, out_dir, settings, jobs, progress, plot, formats, dpi) -> SweepResult:
    record = _settings_record(base, settings)
    earlier = _prepare_folder(out_dir, record)
    done = {point_key(r["mu_s"], r["mu_d"], r["theta0_deg"]) for r in earlier}
    points = grid.points()
    todo = [pt for pt in points if point_key(*pt) not in done]
    new_rows: list[dict] = []
    csv_path = out_dir / CSV_NAME
    pool = None
    try:
        if jobs > 1 and len(todo) > 1:
            # Workers are started (forked) here, before the progress bar starts its thread.
            # Small chunks: little pickling overhead per point, a progress bar that still moves.
            size = max(1, min(8, len(todo) // (4 * jobs)))
            pool = ProcessPoolExecutor(max_workers=min(jobs, len(todo)))
            pending = {pool.submit(_classify_chunk, base, settings, chunk) for chunk in _chunks(todo, size)}
        with open(csv_path, "a", newline="", encoding="utf-8") as sink, _progress(progress, len(points)) as bar:
            bar.advance(len(points) - len(todo))

            def record_rows(rows):
                for row in rows:
                    sink.write(_row_line(row))
                    new_rows.append(row)
                sink.flush()  # a row on disk is a row an interrupted sweep need not redo
                bar.advance(len(rows))

            if pool is None:
                for pt in todo:
                    record_rows([classify_point(base, *pt, settings=settings)])
            else:
                while pending:
                    finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                    for fut in finished:
                        record_rows(fut.result())
    except BaseException:
        if pool is not None:
            pool.shutdown(wait=False, cancel_futures=True)
        raise
    if pool is not None:
        pool.shutdown()
    rows = sorted_rows(earlier + new_rows)
    write_rows(csv_path, rows)
    wanted = {point_key(*pt) for pt in points}
    grid_rows = [r for r in rows if point_key(r["mu_s"], r["mu_d"], r["theta0_deg"]) in wanted]
    ths = [thresholds(base, th) for th in grid.theta0_deg]
    th_cols = {k: [t.as_row()[k] for t in ths] for k in ths[0].as_row()}
    files = [csv_path, out_dir / SETTINGS_NAME, out_dir / THRESHOLDS_NAME]
    write_csv(out_dir / THRESHOLDS_NAME, th_cols)
    if plot:
        from .plotting import save_figure
        files += save_figure(regime_map_figure(grid_rows, grid, base, ths, settings), out_dir / MAP_NAME,
                             formats, dpi)
    return SweepResult(out_dir, rows, grid_rows, len(new_rows), len(points) - len(todo), ths, files)


class _NoProgress:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    def advance(self, n):
        pass


class _RichProgress:
    def __init__(self, total):
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

        self.progress = Progress(TextColumn("sweep"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                                 console=Console(file=sys.stderr), transient=False)
        self.total = total

    def __enter__(self):
        self.progress.__enter__()
        self.task = self.progress.add_task("sweep", total=self.total)
        return self

    def __exit__(self, *exc):
        return self.progress.__exit__(*exc)

    def advance(self, n):
        self.progress.advance(self.task, n)


def _progress(enabled: bool, total: int):
    return _RichProgress(total) if enabled else _NoProgress()


# --------------------------------------------------------------------------- the map
def _edges(values: np.ndarray) -> np.ndarray:
    """Cell edges around sorted grid values (half a step beyond the ends)."""
    v = np.asarray(sorted(set(np.round(values, KEY_DIGITS))), float)
    if v.size == 1:
        half = max(abs(v[0]) * 0.05, 0.01)
        return np.array([v[0] - half, v[0] + half])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]])


def _scenario_codes(rows) -> tuple[list[str], dict]:
    names = list(SCENARIOS) + sorted({r["scenario"] for r in rows} - set(SCENARIOS))
    return names, {n: i for i, n in enumerate(names)}


def regime_map_figure(rows, grid: Grid, base: RodProblem, ths: list[Thresholds],
                      settings: SweepSettings = SweepSettings()):
    """Scenario of each grid cell with the analytic boundaries. With μd = R·μs (or one μd) the
    map is μs × θ0 with the boundaries as curves of θ0, and a second panel shows the transition
    and impact times against μs beside the rolling hypothesis' prediction; with a μd grid it is
    μs × μd, one panel per θ0, and the boundaries are vertical lines (they do not depend on μd)."""
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    names, code = _scenario_codes(rows)
    colours = [SCENARIO_COLOURS.get(n, OTHER_COLOUR) for n in names]
    cmap = ListedColormap(colours).with_extremes(bad="white")
    norm = BoundaryNorm(np.arange(len(names) + 1) - 0.5, len(names))
    mu_s_edges = _edges(grid.mu_s)
    mu_s_vals = np.asarray(sorted(set(np.round(grid.mu_s, KEY_DIGITS))), float)
    x_lo, x_hi = mu_s_edges[0], mu_s_edges[-1]
    boundary_styles = (("T_over_N_initial", "|T/N(0)|", "k", "-"), ("T_over_N_max", "max T/N", "k", "--"),
                       ("T_over_N_min", "|min T/N|", "k", ":"))
    by_key = {point_key(r["mu_s"], r["mu_d"], r["theta0_deg"]): r for r in rows}

    if not grid.varies_mu_d:
        th_vals = np.asarray(sorted(set(np.round(grid.theta0_deg, KEY_DIGITS - 2))), float)
        fig = Figure(figsize=(13, 5.2), layout="constrained")
        ax, ax_t = fig.subplots(1, 2, width_ratios=(1.25, 1))
        ax.set_label("map")
        ax_t.set_label("times")
        Z = np.full((th_vals.size, mu_s_vals.size), np.nan)
        for i, th in enumerate(th_vals):
            for j, ms in enumerate(mu_s_vals):
                md = min(ms, grid.mu_d_ratio * ms) if grid.mu_d_ratio is not None else float(grid.mu_d[0])
                r = by_key.get(point_key(ms, md, th))
                if r is not None:
                    Z[i, j] = code[r["scenario"]]
        ax.pcolormesh(mu_s_edges, _edges(th_vals), np.ma.masked_invalid(Z), cmap=cmap, norm=norm)
        # Boundaries as curves of θ0 (a fine θ0 grid when the map has several rows).
        if th_vals.size > 1:
            fine = np.linspace(th_vals[0], th_vals[-1], 40)
            fine_th = [thresholds(base, th) for th in fine]
            ys = fine
        else:
            fine_th = ths[:1]
            ys = None
        off = []
        for key, label, colour, ls in boundary_styles:
            vals = np.array([abs(getattr(t, key)) for t in fine_th])
            if ys is None:
                ax.axvline(vals[0], color=colour, ls=ls, lw=1.4, label=f"{label} = {vals[0]:.4f}", gid=key)
            else:
                ax.plot(vals, ys, color=colour, ls=ls, lw=1.4, label=label, gid=key)
            off += [f"{label} ≥ {v.min():.3g}" for v in [vals] if v.min() > x_hi]
        ax.set_xlim(x_lo, x_hi)
        ax.set(xlabel="μs", ylabel="θ0 [°]")
        if th_vals.size == 1:
            ax.set_yticks(th_vals)
        mu_d_text = f"μd = {grid.mu_d_ratio:g}·μs" if grid.mu_d_ratio is not None else f"μd = {float(grid.mu_d[0]):g}"
        ax.set_title(f"scenario ({mu_d_text}, {settings.method})")
        handles = [Patch(color=SCENARIO_COLOURS.get(n, OTHER_COLOUR), label=n) for n in names]
        handles += ax.get_legend_handles_labels()[0]
        ax.legend(handles=handles, fontsize=8, loc="upper left", bbox_to_anchor=(0, -0.13), ncol=3)
        if off:
            ax.text(0.99, 0.02, "off the map: " + "; ".join(off) + "\n(roll-to-impact lies beyond)",
                    transform=ax.transAxes, ha="right", va="bottom", fontsize=8,
                    bbox=dict(fc="white", ec="0.7", alpha=0.9))
        # Times against μs for a few θ0 rows, beside the rolling hypothesis' transition time.
        picks = th_vals if th_vals.size <= 4 else th_vals[np.linspace(0, th_vals.size - 1, 4).round().astype(int)]
        fine_mu = np.linspace(x_lo, x_hi, 300)
        for k, th in enumerate(picks):
            colour = f"C{k}"
            th_obj = next((t for t in ths if abs(t.theta0_deg - th) < 1e-9), None) or thresholds(base, th)
            pred = np.array([predicted_scenario(th_obj.rolling, m)[1] for m in fine_mu])
            ax_t.plot(fine_mu, pred, color=colour, lw=1.0, ls="--", gid=f"predicted:{th:g}")
            sel = [r for r in rows if abs(r["theta0_deg"] - th) < 1e-9]
            sel.sort(key=lambda r: r["mu_s"])
            ms = [r["mu_s"] for r in sel]
            ax_t.plot(ms, [r["t_transition"] for r in sel], "o", color=colour, ms=4,
                      gid=f"t_transition:{th:g}", label=f"θ0 = {th:g}°: end of rolling")
            ax_t.plot(ms, [r["t_impact"] for r in sel], "s", color=colour, ms=4, mfc="none",
                      gid=f"t_impact:{th:g}", label=f"θ0 = {th:g}°: impact of B")
        ax_t.plot([], [], "k--", lw=1.0, label="rolling hypothesis: |T/N| reaches μs")
        ax_t.set(xlabel="μs", ylabel="t [s]", title="end of rolling and impact time", xlim=(x_lo, x_hi))
        ax_t.grid(alpha=0.3)
        ax_t.legend(fontsize=7, loc="upper left", bbox_to_anchor=(0, -0.13), ncol=2)
    else:
        n = len(grid.theta0_deg)
        cols = min(n, 3)
        fig = Figure(figsize=(5.2 * cols, 4.6 * math.ceil(n / cols) + 0.6), layout="constrained")
        axes = np.atleast_1d(fig.subplots(math.ceil(n / cols), cols, squeeze=False)).ravel()
        md_vals = np.asarray(sorted(set(np.round(grid.mu_d, KEY_DIGITS))), float)
        for ax, th, th_obj in zip(axes, grid.theta0_deg, ths):
            ax.set_label(f"map:{th:g}")
            Z = np.full((md_vals.size, mu_s_vals.size), np.nan)
            for i, md in enumerate(md_vals):
                for j, ms in enumerate(mu_s_vals):
                    r = by_key.get(point_key(ms, md, th))
                    if r is not None:
                        Z[i, j] = code[r["scenario"]]
            ax.pcolormesh(mu_s_edges, _edges(md_vals), np.ma.masked_invalid(Z), cmap=cmap, norm=norm)
            lim = (min(x_lo, md_vals[0]), max(x_hi, md_vals[-1]))
            ax.plot(lim, lim, color="0.5", lw=0.8, label="μd = μs (white above: μd > μs)")
            off = []
            for key, label, colour, ls in boundary_styles:
                v = abs(getattr(th_obj, key))
                if x_lo <= v <= x_hi:
                    ax.axvline(v, color=colour, ls=ls, lw=1.4, label=f"{label} = {v:.4f}", gid=key)
                else:
                    off.append(f"{label} = {v:.3g}")
            if off:
                ax.text(0.99, 0.02, "off the map: " + "; ".join(off), transform=ax.transAxes, ha="right",
                        va="bottom", fontsize=8, bbox=dict(fc="white", ec="0.7", alpha=0.9))
            ax.set(xlim=(x_lo, x_hi), ylim=(_edges(md_vals)[0], _edges(md_vals)[-1]), xlabel="μs", ylabel="μd",
                   title=f"θ0 = {th:g}° ({settings.method})")
            ax.legend(fontsize=7, loc="upper left")
        for ax in axes[n:]:
            ax.axis("off")
        fig.legend(handles=[Patch(color=SCENARIO_COLOURS.get(nm, OTHER_COLOUR), label=nm) for nm in names],
                   loc="outside lower center", ncol=len(names), fontsize=8)
    fig.suptitle("Regime map: the paper's scenarios, with the boundaries of the pure-rolling hypothesis")
    return fig


def grid_step(values) -> float:
    v = np.unique(np.round(np.asarray(values, float), KEY_DIGITS))
    return float(np.max(np.diff(v))) if v.size > 1 else 0.0


def default_jobs() -> int:
    return max(1, min(2, os.cpu_count() or 1))
