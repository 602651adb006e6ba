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

import contextlib
import csv
import io
import json
import math
import os
import sys
import time
import zlib
from concurrent.futures import FIRST_COMPLETED, wait
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .. import _jit
from ..io import dumps_json, output_error, provenance, remove_stale_temps, write_csv, write_json, write_text
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


# --------------------------------------------------------------------------- analytic thresholds
def _cell(value) -> str:
    if isinstance(value, float):
        return "" if value != value else repr(float(value))  # shortest round-trip text; NaN empty
    return str(value)


def _row_lines(rows, columns) -> str:
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerows([[_cell(row[c]) for c in columns] for row in rows])
    return buf.getvalue()


def _parse_row(fields: list[str], columns) -> dict | None:
    if len(fields) != len(columns):
        return None
    row = dict(zip(columns, fields))
    try:
        for c in columns:
            if c not in TEXT_COLUMNS:
                row[c] = float(row[c]) if row[c] != "" else math.nan
    except ValueError:
        return None
    points = [row[c] for c in columns if c not in RESULT_COLUMNS]
    if not row["scenario"] or not all(math.isfinite(v) for v in points):
        return None
    return row


def read_rows(path, columns=CSV_COLUMNS) -> tuple[list[dict], int]:
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
    if tuple(lines[0]) != tuple(columns):
        raise InputError(f"{path} does not start with the header {','.join(columns)}: not this sweep's map")
    rows, bad = [], 0
    for fields in lines[1:]:
        row = _parse_row(fields, columns)
        if row is None:
            bad += 1
        else:
            rows.append(row)
    return rows, bad


def point_columns(columns) -> tuple:
    return tuple(c for c in columns if c not in RESULT_COLUMNS)


def sorted_rows(rows, columns=CSV_COLUMNS) -> list[dict]:
    """One row per point (the last one read wins), the first column varying fastest."""
    pcols = point_columns(columns)
    unique = {row_key(r, pcols): r for r in rows}
    return [unique[k] for k in sorted(unique, key=lambda k: k[::-1])]


def write_rows(path, rows, columns=CSV_COLUMNS) -> None:
    write_text(path, ",".join(columns) + "\n" + _row_lines(sorted_rows(rows, columns), columns))


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
    if settings_path.exists():
        try:
            old = json.loads(settings_path.read_text(encoding="utf-8"))
        except (json.JSONDecodeError, UnicodeDecodeError):
            raise InputError(f"{settings_path} is not valid JSON: remove it or use another --out") from None
        old = {k: old.get(k) for k in record}  # the grid, provenance and accuracy may differ
        if json.loads(dumps_json(old)) != json.loads(dumps_json(record)):
            raise InputError(f"{out_dir} holds a sweep made with other settings, axes or another body "
                             f"(see {settings_path}): use another --out or remove the folder")
    elif csv_path.exists():
        raise InputError(f"{csv_path} exists without {SETTINGS_NAME}: not a sweep folder of this "
                         "program; use another --out")
    rows = []
    if csv_path.exists():
        rows, _bad = read_rows(csv_path, columns)
    if not settings_path.exists():
        write_json(settings_path, record)
    # Rewrite what was readable (dropping a half-written last line) before appending to it.
    write_rows(csv_path, rows, columns)
    return rows


# flock belongs to the open file, which a fork shares: the local pool's workers, forked while the
# sweep holds its folder's lock, would hold it too, and one still finishing its chunk after the
# sweep stopped (a worker killed, Ctrl-C) would refuse the rerun. Each child drops it at once.
_HELD_LOCKS: set[int] = set()


def _drop_locks_in_child() -> None:
    if not _HELD_LOCKS:
        return
    null = os.open(os.devnull, os.O_RDONLY)
    for fd in _HELD_LOCKS:  # dup2, not close: the number stays valid for the file object that owns it
        with contextlib.suppress(OSError):
            os.dup2(null, fd)
    os.close(null)
    _HELD_LOCKS.clear()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_drop_locks_in_child)


@contextlib.contextmanager
def folder_lock(out_dir: Path):
    """Refuse a second sweep writing into the same folder at the same time (their appends
    would interleave). An advisory lock, released by the system if the process dies. The lock
    file stays on disk: unlinking it on release would let a sweep that opened the old file and
    one that creates a new one both hold "the" lock."""
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock
        yield
        return
    path = out_dir / LOCK_NAME
    try:
        fh = open(path, "a")  # never truncate: the file is the lock, not its content
    except OSError as err:
        raise output_error(path, err) from None
    try:
        fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        fh.close()
        raise InputError(f"another sweep is writing to {out_dir} (it holds {path}): wait for it or use "
                         "another --out") from None
    _HELD_LOCKS.add(fh.fileno())
    try:
        yield
    finally:
        _HELD_LOCKS.discard(fh.fileno())
        fh.close()


def _chunks(points, size):
    return [points[i:i + size] for i in range(0, len(points), size)]


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
    if jobs < 1:
        raise InputError(f"jobs must be at least 1, got {jobs}")
    if not 0 <= check_points <= 1000:
        raise InputError(f"check_points must lie in [0, 1000], got {check_points}")
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError(f"--out '{out_dir}' exists and is not a folder")
    _check_problems(base, grid)
    out_dir.mkdir(parents=True, exist_ok=True)
    remove_stale_temps(out_dir)
    opts = dict(progress=progress, plot=plot, formats=formats, dpi=dpi, check_points=check_points,
                map_axes=tuple(map_axes), command=command)
    with folder_lock(out_dir):
        if executor is not None and not isinstance(executor, str):
            return _sweep(base, grid, out_dir, settings, executor, jobs, **opts)
        from ..executors import WorkerLost, open_executor

        if executor in (None, "local"):
            warm_engine(settings)  # before forking: the workers inherit the loaded engine
        try:
            with open_executor(executor or "local", jobs, scheduler) as (pool, workers):
                return _sweep(base, grid, out_dir, settings, pool, workers, **opts)
        except WorkerLost as err:
            raise WorkerLost(f"{err}: the sweep stopped; the points finished are kept in {out_dir / CSV_NAME}: "
                             "run the same sweep again to resume") from None


def _run_points(base, settings, columns, todo, pool, workers, on_rows, meanwhile=None) -> None:
    """Classify `todo`, in this process (pool None) or in chunks on `pool`; `on_rows` gets each
    finished chunk's rows as they arrive. `meanwhile()` runs in this process, in a thread
    while the workers compute (after them without a pool)."""
    if pool is None:
        warm_engine(settings)
        with _jit.one_blas_thread():  # once for the batch, not once per short run
            for pt in todo:
                on_rows([classify_point(base, dict(zip(columns, pt)), settings)])
        if meanwhile is not None:
            meanwhile()
        return
    # Chunks: little pickling overhead per point, yet a progress bar that moves and enough
    # tasks to balance the workers.
    size = max(1, min(250, len(todo) // (8 * workers)))
    pending = {pool.submit(_classify_chunk, base, settings, columns, chunk) for chunk in _chunks(todo, size)}
    side = _Background(meanwhile)
    try:
        while pending:
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in finished:
                on_rows(fut.result())
    except BaseException:
        for fut in pending:
            fut.cancel()
        raise
    side.join()


class _Background:
    """A function run in a thread; join() re-raises what it raised."""

    def __init__(self, fn):
        import threading

        self.error = None
        self.thread = None
        if fn is not None:
            self.thread = threading.Thread(target=self._run, args=(fn,), daemon=True, name="sweep-side")
            self.thread.start()

    def _run(self, fn):
        try:
            fn()
        except BaseException as err:  # handed to the main thread
            self.error = err

    def join(self):
        if self.thread is not None:
            self.thread.join()
        if self.error is not None:
            raise self.error


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
    with open(csv_path, "a", newline="", encoding="utf-8") as sink, _progress(progress, len(points)) as bar:
        bar.advance(len(points) - len(todo))

        def record_rows(rows):
            try:
                sink.write(_row_lines(rows, columns))
                sink.flush()  # a row on disk is a row an interrupted sweep need not redo
            except OSError as err:  # a full disk: the rows already written stay, resume redoes the rest
                raise output_error(csv_path, err) from None
            new_rows.extend(rows)
            bar.advance(len(rows))

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
    if _has_pyarrow():
        files.append(write_parquet(out_dir / PARQUET_NAME, out_dir / CSV_NAME, columns))
    return files


def write_parquet(path: Path, csv_path: Path, columns) -> Path:
    """The table as Parquet, atomically, converted from the final CSV by Arrow's own reader:
    building it from Python values would import pandas (a second) through pyarrow."""
    import pyarrow as pa
    import pyarrow.csv as pa_csv
    import pyarrow.parquet as pq

    from ..io import atomic_path

    types = {c: pa.string() if c in TEXT_COLUMNS else pa.float64() for c in columns}
    table = pa_csv.read_csv(csv_path, convert_options=pa_csv.ConvertOptions(
        column_types=types, strings_can_be_null=False, include_columns=list(columns)))
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp)
    return path


def _has_pyarrow() -> bool:
    import importlib.util

    return importlib.util.find_spec("pyarrow") is not None


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


# --------------------------------------------------------------------------- progress
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
        from rich.progress import (BarColumn, MofNCompleteColumn, Progress, ProgressColumn, TextColumn,
                                   TimeRemainingColumn)
        from rich.text import Text

        class Rate(ProgressColumn):
            def render(self, task):
                return Text(f"{task.speed or 0:,.0f} points/s", style="progress.data.speed")

        self.progress = Progress(TextColumn("sweep"), BarColumn(), MofNCompleteColumn(), Rate(),
                                 TimeRemainingColumn(), console=Console(file=sys.stderr), transient=False)
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


def default_jobs() -> int:
    return max(1, min(2, os.cpu_count() or 1))
