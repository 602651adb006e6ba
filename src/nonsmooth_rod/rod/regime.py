"""The regime map: which of the paper's scenarios each point of a parameter grid produces.

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

Axes: μs, μd (or μd/μs), θ0 and any of the body's geometry, density and the restitution
(`Grid`). A point is simulated by Moreau–Jean (lemke, the compiled whole-run path) by default;
a random sample of points is re-run with the event-driven reference in every sweep and the
agreement (scenario, transition and impact times) is reported (`check_accuracy`).

`sweep` runs the grid in chunks on any concurrent.futures-style executor, appending each
finished row to DIR/regime_map.csv at once (flushed), so an interrupted sweep resumes where it
stopped; the final CSV is rewritten sorted, atomically, and so is DIR/regime_map.parquet when
pyarrow is installed. DIR/sweep.json records the settings the rows were made with (a sweep
with other settings refuses to mix its rows into the same folder), the grid, the provenance
and the accuracy check.
"""
from __future__ import annotations

import math
import os
import time
import zlib
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .. import _jit
from ..io import dumps_json, provenance, remove_stale_temps, write_csv, write_json
from ..studies import runner
from ..validation import InputError
from .problem import RodProblem
from .regime_grid import (  # noqa: F401  (the grid's names, re-exported for the sweep's callers)
    AXES,
    CSV_NAME,
    MAP_NAME,
    SETTINGS_NAME,
    THRESHOLDS_NAME,
    CSV_COLUMNS,
    GEOMETRY_AXES,
    Grid,
    KEY_DIGITS,
    LOCK_NAME,
    PARQUET_NAME,
    REFERENCE,
    RESULT_COLUMNS,
    SCENARIOS,
    SWEEP_SCHEMA,
    SweepSettings,
    TEXT_COLUMNS,
    Thresholds,
    check_axis_values,
    parse_range,
    point_key,
    predicted_scenario,
    problem_at,
    row_key,
    thresholds,
)

CHECK_POINTS = 8  # points of every sweep re-run with the event-driven reference


def phases_text(phases) -> str:
    """'stick 0.000000..0.104101; slip- 0.104101..0.302350; ...' (times in s)."""
    return "; ".join(f"{ph.mode} {ph.t_start:.6f}..{ph.t_end:.6f}" for ph in phases)


def scenario_of(phases, status: str = "ok") -> str:
    """The paper's scenario from ball A's phase sequence; the status word if the run failed."""
    from .simulation import scenario

    return status if status != "ok" else scenario(phases)


def _failed_row(point: dict, err: Exception) -> dict:
    message = " ".join(f"{type(err).__name__}: {err}".split())
    return point | {"scenario": "failed", "status": "failed", "t_transition": math.nan, "t_impact": math.nan,
                    "theta_impact": math.nan, "theta_dot_impact": math.nan, "x_O_dot_impact": math.nan,
                    "phases": message[:200]}


def classify_point(base: RodProblem, point: dict, settings: SweepSettings = SweepSettings()) -> dict:
    """Simulate one grid point (a dict of axis values with mu_s, mu_d, theta0_deg) → its row.

    t_transition: when rolling ends (0 for slide-at-start; NaN if it never ends);
    t_impact and the state at it: ball B's impact (NaN if none)."""
    from .simulation import simulate

    point = {k: float(v) for k, v in point.items()}
    try:
        run = simulate(problem_at(base, point), settings.method, **settings.simulate_kwargs())
    except Exception as err:  # one bad point must not end a long sweep; it is recorded
        return _failed_row(point, err)
    scenario = scenario_of(run.phases, run.status)
    if scenario == "slide-at-start":
        t_transition = 0.0
    elif run.phases and run.phases[0].mode == "stick" and len(run.phases) > 1:
        t_transition = float(run.phases[0].t_end)
    else:
        t_transition = math.nan
    imp = run.impact or {}
    return point | {"scenario": scenario, "status": str(run.status), "t_transition": t_transition,
                    "t_impact": float(imp.get("t", math.nan)), "theta_impact": float(imp.get("theta", math.nan)),
                    "theta_dot_impact": float(imp.get("theta_dot", math.nan)),
                    "x_O_dot_impact": float(imp.get("x_O_dot", math.nan)), "phases": phases_text(run.phases)}


_WARM: set = set()


def warm_engine(settings: SweepSettings) -> None:
    """Load (compile once, then from the cache) what `settings` runs on, once per process: a
    worker pays it before its first chunk, not per task."""
    if settings.method in _WARM:
        return
    from .simulation import simulate

    if settings.method == "moreau-jean":
        simulate(RodProblem.paper(), "moreau-jean", h=1e-2, solver=settings.solver)
    _WARM.add(settings.method)


def _classify_chunk(base: RodProblem, settings: SweepSettings, columns, points) -> list[dict]:
    warm_engine(settings)
    with _jit.one_blas_thread():  # once per chunk, not once per short run
        return [classify_point(base, dict(zip(columns, pt)), settings) for pt in points]


# --------------------------------------------------------------------------- CSV rows
def read_rows(path, columns=CSV_COLUMNS) -> tuple[list[dict], int]:
    """Rows of a regime_map.csv and the number of unreadable lines (an interrupted write)."""
    return runner.read_table(path, columns, TEXT_COLUMNS, point_columns(columns), "scenario")


def point_columns(columns) -> tuple:
    return tuple(c for c in columns if c not in RESULT_COLUMNS)


def sorted_rows(rows, columns=CSV_COLUMNS) -> list[dict]:
    """One row per point (the last one read wins), the first column varying fastest."""
    return runner.sorted_unique(rows, point_columns(columns))


def write_rows(path, rows, columns=CSV_COLUMNS) -> None:
    runner.write_table(path, rows, columns, point_columns(columns))


def rows_as_columns(rows, columns=CSV_COLUMNS) -> dict:
    return {c: np.array([r[c] for r in rows], dtype=object if c in TEXT_COLUMNS else float) for c in columns}


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
    columns: tuple = CSV_COLUMNS
    accuracy: dict = field(default_factory=dict)
    wall_s: float = 0.0     # the whole call
    compute_s: float = 0.0  # classifying the points (without the check, tables and figure)

    @property
    def frame(self):
        """This grid's rows as a pandas DataFrame (one column per axis and per result)."""
        try:
            import pandas as pd
        except ImportError:
            raise ImportError("SweepResult.frame needs pandas: pip install 'nonsmooth-rod[tables]'") from None

        return pd.DataFrame(rows_as_columns(self.grid_rows, self.columns), columns=list(self.columns)).astype(
            {c: float for c in self.columns if c not in TEXT_COLUMNS})


def _settings_record(base: RodProblem, settings: SweepSettings, grid: Grid) -> dict:
    """What rows of one folder must share: the method, the body, the table's columns."""
    swept = set(grid.columns) | {"theta0_rad"}
    body = {k: v for k, v in base.as_params().items() if k not in swept}
    return {"schema": SWEEP_SCHEMA, "settings": asdict(settings), "body": body, "columns": list(grid.columns)}


def _prepare_folder(out_dir: Path, record: dict, columns) -> list[dict]:
    """Check a folder's earlier sweep is compatible; return its readable rows."""
    csv_path, settings_path = out_dir / CSV_NAME, out_dir / SETTINGS_NAME
    runner.claim_folder(out_dir, csv_path, settings_path, record, "a sweep made with other settings, axes or another body")
    rows = []
    if csv_path.exists():
        rows, _bad = read_rows(csv_path, columns)
    # Rewrite what was readable (dropping a half-written last line) before appending to it.
    write_rows(csv_path, rows, columns)
    return rows


folder_lock = runner.folder_lock


def _check_problems(base: RodProblem, grid: Grid) -> None:
    """Refuse a grid with an impossible body (rod thicker than the balls, ...) before running."""
    for group in grid.groups():
        problem_at(base, {"mu_s": base.mu_s, "mu_d": base.mu_d} | group)


def sweep(base: RodProblem, grid: Grid, out_dir, settings: SweepSettings = SweepSettings(), *,
          jobs: int = 2, executor=None, scheduler: str | None = None, progress: bool = False, plot: bool = True,
          formats=("png",), dpi: int = 110, check_points: int = CHECK_POINTS, map_axes=(None, None),
          command=None) -> SweepResult:
    """Classify every grid point (skipping the ones out_dir already holds), write the tables,
    sweep.json and the map; see the module doc.

    executor: None or "local" (a process pool of `jobs` workers; in this process for jobs = 1),
    "dask" (a dask.distributed LocalCluster of `jobs` workers, or the scheduler at `scheduler`),
    or any concurrent.futures-style executor (a Dask client's get_executor(), loky, a
    ProcessPoolExecutor), used as given and not shut down here; `jobs` then only sizes the
    chunks (give the number of workers). `map_axes`: the figure's (x, y) axes (default: see
    `regime_map_figure`). The table in memory: `result.frame`."""
    out_dir = runner.check_sweep_args(out_dir, jobs)
    if not 0 <= check_points <= 1000:
        raise InputError(f"check_points must lie in [0, 1000], got {check_points}")
    _check_problems(base, grid)
    out_dir.mkdir(parents=True, exist_ok=True)
    remove_stale_temps(out_dir)
    opts = dict(progress=progress, plot=plot, formats=formats, dpi=dpi, check_points=check_points,
                map_axes=tuple(map_axes), command=command)
    if executor in (None, "local"):
        warm_engine(settings)  # before forking: the workers inherit the loaded engine
    with folder_lock(out_dir), runner.executor_pool(executor, jobs, scheduler, out_dir / CSV_NAME) as (pool, workers):
        return _sweep(base, grid, out_dir, settings, pool, workers, **opts)


def _run_points(base, settings, columns, todo, pool, workers, on_rows, meanwhile=None) -> None:
    """Classify `todo`, in this process (pool None) or in chunks on `pool` (runner.run_chunked)."""
    if pool is None:
        warm_engine(settings)
        with _jit.one_blas_thread():  # once for the batch, not once per short run
            runner.run_chunked(_classify_chunk, (base, settings, columns), todo, None, 1, on_rows, meanwhile)
        return
    runner.run_chunked(_classify_chunk, (base, settings, columns), todo, pool, workers, on_rows, meanwhile)


def _sweep(base, grid, out_dir, settings, pool, workers, *, progress, plot, formats, dpi, check_points,
           map_axes, command) -> SweepResult:
    started = time.perf_counter()
    columns = grid.columns + RESULT_COLUMNS
    pcols = grid.columns
    record = _settings_record(base, settings, grid)
    earlier = _prepare_folder(out_dir, record, columns)
    done = {row_key(r, pcols) for r in earlier}
    points = grid.points()
    todo = [pt for pt in points if point_key(pt) not in done]
    new_rows: list[dict] = []
    csv_path = out_dir / CSV_NAME
    with runner.progress(progress, len(points)) as bar, \
            runner.row_sink(csv_path, columns, bar, new_rows) as record_rows:
        bar.advance(len(points) - len(todo))

        side: dict = {}

        def meanwhile():
            # In this process while the workers run: the reference runs of the accuracy check
            # (cheaper than importing the reference in every worker), the thresholds, and the
            # figure's imports.
            side["refs"] = reference_rows(base, grid, settings, check_points)
            side["ths"] = [thresholds(base, g["theta0_deg"], {k: g[k] for k in grid.extra_names})
                           for g in grid.groups()]
            if plot:
                from . import plotting  # noqa: F401  (imports matplotlib)

        _run_points(base, settings, pcols, todo, pool, workers, record_rows, meanwhile)
    compute_s = time.perf_counter() - started
    rows = sorted_rows(earlier + new_rows, columns)
    write_rows(csv_path, rows, columns)
    wanted = {point_key(pt) for pt in points}
    grid_rows = [r for r in rows if row_key(r, pcols) in wanted]
    accuracy = check_accuracy(base, grid, grid_rows, settings, check_points, side["refs"])
    ths = side["ths"]
    files = _write_outputs(out_dir, columns, rows, ths, record, grid, accuracy, command,
                           {"points": len(points), "computed": len(new_rows), "reused": len(points) - len(todo),
                            "compute_wall_s": compute_s, "workers": workers})
    if plot:
        from .plotting import save_figure
        from .regime_figure import regime_map_figure

        files += save_figure(regime_map_figure(grid_rows, grid, base, ths, settings, *map_axes),
                             out_dir / MAP_NAME, formats, dpi)
    return SweepResult(out_dir, rows, grid_rows, len(new_rows), len(points) - len(todo), ths, files, columns,
                       accuracy, time.perf_counter() - started, compute_s)


def _write_outputs(out_dir, columns, rows, ths, record, grid, accuracy, command, counts) -> list[Path]:
    files = [out_dir / CSV_NAME, out_dir / SETTINGS_NAME, out_dir / THRESHOLDS_NAME]
    th_rows = [t.as_row() for t in ths]
    write_csv(out_dir / THRESHOLDS_NAME, {k: [r[k] for r in th_rows] for k in th_rows[0]})
    grid_record = {name: values.tolist() for name, values in grid.axes.items()}
    write_json(out_dir / SETTINGS_NAME, record | {"grid": grid_record, "counts": counts, "accuracy": accuracy,
                                                  "provenance": provenance(command)})
    if runner.has_pyarrow():
        files.append(runner.write_parquet(out_dir / PARQUET_NAME, out_dir / CSV_NAME, columns, TEXT_COLUMNS))
    return files


# --------------------------------------------------------------------------- accuracy
def sample_points(grid: Grid, n: int) -> list[tuple]:
    """`n` points drawn at random, the same for the same grid (a resumed sweep checks the same)."""
    points = grid.points()
    seed = zlib.crc32(dumps_json({k: v.tolist() for k, v in grid.axes.items()}).encode())
    pick = np.random.default_rng(seed).choice(len(points), size=min(n, len(points)), replace=False)
    return [points[i] for i in sorted(pick)]


def reference_rows(base, grid, settings, n) -> list[dict]:
    """The event-driven reference at `n` random points of the grid (none if the sweep runs it)."""
    if settings.method == "event-driven" or n == 0:
        return []
    return [classify_point(base, dict(zip(grid.columns, pt)), REFERENCE) for pt in sample_points(grid, n)]


def check_accuracy(base, grid, grid_rows, settings, n, refs=None) -> dict:
    """Compare the scenario, the end of rolling and ball B's impact time of the sweep's rows
    with the event-driven reference at a random sample of points (`refs` if already run)."""
    if settings.method == "event-driven" or n == 0:
        return {"reference": "event-driven", "checked": 0,
                "note": "the sweep ran the reference itself" if n else "no check asked for"}
    refs = reference_rows(base, grid, settings, n) if refs is None else refs
    by_key = {row_key(r, grid.columns): r for r in grid_rows}
    tol = settings.time_tolerance
    agree, worst, mismatches = 0, {"t_transition": 0.0, "t_impact": 0.0}, []
    for ref in refs:
        row = by_key[row_key(ref, grid.columns)]
        same = row["scenario"] == ref["scenario"]
        agree += same
        for c in worst:
            if same and math.isfinite(ref[c]) and math.isfinite(row[c]):
                worst[c] = max(worst[c], abs(row[c] - ref[c]))
        if not same:
            mismatches.append({c: row[c] for c in grid.columns} | {"scenario": row["scenario"],
                                                                  "reference": ref["scenario"]})
    return {"reference": "event-driven (rtol 1e-12)", "checked": len(refs), "scenario_agree": agree,
            "max_abs_error_t_transition_s": worst["t_transition"], "max_abs_error_t_impact_s": worst["t_impact"],
            "time_tolerance_s": tol, "within_tolerance": agree == len(refs) and max(worst.values()) <= tol,
            "mismatches": mismatches}


def accuracy_text(acc: dict) -> str:
    if not acc.get("checked"):
        return f"accuracy: not checked ({acc.get('note', '')})"
    verdict = "within" if acc["within_tolerance"] else "NOT within"
    return (f"accuracy vs {acc['reference']} on {acc['checked']} random points: scenario "
            f"{acc['scenario_agree']}/{acc['checked']}, |Δt| transition ≤ "
            f"{acc['max_abs_error_t_transition_s']:.2g} s, impact ≤ {acc['max_abs_error_t_impact_s']:.2g} s "
            f"({verdict} the stated {acc['time_tolerance_s']:.2g} s)")


# --------------------------------------------------------------------------- the map


def default_jobs() -> int:
    return max(1, min(2, os.cpu_count() or 1))
