"""Maps of any scene: the outcome of a scene file at every point of a grid of scene keys.

An axis is a dotted path into the scene file (`contacts.foot.law.mu_s`, `lines.belt.velocity`,
`contacts.*.law.mu_s` for every contact, `initial.block.v.0` for a component; `a,b` for two keys
moving together) with its values. Each point is the file with those
values, run with the file's own method and options; its row holds the axes, then the outcome
(outcome.py): the regime (every contact's phase sequence), status, whether the scene held, each
contact's first slip / stick / lift-off / impact time, the final state. A point the scene
refuses (μd > μs, ...) is recorded with the regime "refused". Each worker parses the scene once
and patches every point's values into it where the paths allow (patching.py: laws, initial state,
run settings), the same scene the full parse of the point gives.

The points run on the rod's sweep machinery (runner.py, executors.py): chunks on a local pool,
a Dask LocalCluster or a scheduler; rows streamed to DIR/map.csv (resumed when rerun), the
final table sorted and rewritten atomically, DIR/map.parquet beside it with pyarrow, and
DIR/sweep.json with the scene, axes, counts and provenance. `refine=K` bisects every pair of
neighbouring grid points of different regimes K times along their axis: DIR/boundaries.csv.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import _jit
from ..io import output_error, provenance, remove_stale_temps, write_csv, write_json
from ..scenefile import parse_scene, read_data, simulate_scene
from ..validation import InputError
from . import runner
from .outcome import outcome_columns, outcome_row, refused_row
from .patching import PointScenes, point_scenes
from .paths import apply_sets, check_path

SCHEMA = "nonsmooth-rod/scene-sweep/1"
CSV_NAME, PARQUET_NAME, SETTINGS_NAME, BOUNDARIES_NAME, MAP_NAME = (
    "map.csv", "map.parquet", "sweep.json", "boundaries.csv", "map")
TEXT_COLUMNS = ("regime", "status", "message")
MAX_POINTS = 1_000_000


@dataclass(frozen=True)
class Axis:
    path: str
    values: np.ndarray


def parse_axis(text: str, max_count: int = 2000) -> Axis:
    """'PATH=START:STOP:N' or 'PATH=v1,v2,...' (the --axis option)."""
    path, sep, spec = str(text).partition("=")
    if not sep or not path.strip():
        raise InputError(f"--axis {text!r}: expected PATH=START:STOP:N or PATH=v1,v2,...")
    return Axis(path.strip(), runner.parse_range(spec, f"--axis {path.strip()}", max_count=max_count))


def _axes_of(axes) -> list[Axis]:
    if isinstance(axes, dict):
        axes = [Axis(p, np.atleast_1d(np.asarray(v, dtype=float))) for p, v in axes.items()]
    out = [a if isinstance(a, Axis) else parse_axis(a) for a in axes]
    if not out:
        raise InputError("a map needs at least one --axis PATH=...")
    paths = [a.path for a in out]
    if len(set(paths)) != len(paths):
        raise InputError(f"--axis: a path is given twice in {', '.join(paths)}")
    for a in out:
        if a.values.size == 0 or runner.has_repeats(a.values) or not np.all(np.isfinite(a.values)):
            raise InputError(f"--axis {a.path}: give distinct finite values")
    return out


def scene_data(scene, sets=()) -> tuple[dict, str]:
    """The scene file's content (a path, or a dict as read from TOML) with --set applied."""
    if isinstance(scene, dict):
        return apply_sets(scene, sets), "<scene>"
    data, _text = read_data(scene)
    return apply_sets(data, sets), str(scene)


# --------------------------------------------------------------------------- one point
def run_point(data: dict, source: str, paths, point, names, scenes: PointScenes | None = None) -> dict:
    """The row of one point: its axis values, then its outcome. `scenes`: the map's scene at
    each point (patching.PointScenes; default: this worker's, built once)."""
    contacts, n_dof = names
    row = dict(zip(paths, map(float, point)))
    try:
        sf = (scenes or point_scenes(data, source, paths)).scene_file(row)
    except InputError as err:
        return row | refused_row(contacts, n_dof, "refused", str(err))
    try:
        result = simulate_scene(sf)
    except Exception as err:  # one bad point must not end a long sweep; it is recorded
        return row | refused_row(contacts, n_dof, "failed", f"{type(err).__name__}: {err}")
    return row | outcome_row(result, contacts)


def _run_chunk(data, source, paths, names, points) -> list[dict]:
    scenes = point_scenes(data, source, paths)  # the base scene parsed once per worker
    with _jit.one_blas_thread():  # once per chunk, not once per short run
        return [run_point(data, source, paths, pt, names, scenes) for pt in points]


def _base_run(data: dict, source: str):
    """Run the base scene once: its names, and (before forking) the compiled engine loaded."""
    sf = parse_scene(data, source)
    simulate_scene(sf)
    return list(sf.contact_names), int(sf.q0.size)


# --------------------------------------------------------------------------- the result
@dataclass
class MapResult:
    out_dir: Path
    axes: list
    columns: tuple
    rows: list[dict]             # this grid's rows (resumed ones too), sorted
    computed: int
    reused: int
    boundaries: list[dict] = field(default_factory=list)
    files: list = field(default_factory=list)
    compute_s: float = 0.0
    wall_s: float = 0.0

    @property
    def regimes(self) -> list[str]:
        return sorted({r["regime"] for r in self.rows})

    @property
    def frame(self):
        import pandas as pd

        return pd.DataFrame([{c: r[c] for c in self.columns} for r in self.rows], columns=list(self.columns))


# --------------------------------------------------------------------------- the sweep
def _columns(paths, names, outcomes) -> tuple:
    every = outcome_columns(*names)
    if outcomes is None:
        return tuple(paths) + every
    unknown = [o for o in outcomes if o not in every]
    if unknown:
        raise InputError(f"--outcome {unknown[0]!r}: not an outcome; choose from: {', '.join(every)}")
    kept = ("regime", "status") + tuple(o for o in outcomes if o not in ("regime", "status"))
    return tuple(paths) + kept + (("message",) if "message" not in kept else ())


def _prepare_folder(out_dir: Path, record: dict, columns, paths) -> list[dict]:
    """Check the folder's earlier map was made from the same scene and axes; its readable rows."""
    csv_path, settings_path = out_dir / CSV_NAME, out_dir / SETTINGS_NAME
    runner.claim_folder(out_dir, csv_path, settings_path, record, "a map of another scene, other --set values or other axes")
    rows = runner.read_table(csv_path, columns, TEXT_COLUMNS, paths, "regime")[0] if csv_path.exists() else []
    runner.write_table(csv_path, rows, columns, paths)  # drop a half-written last line before appending
    return rows


def _grid_points(axes) -> list[tuple]:
    mesh = np.meshgrid(*[a.values for a in axes], indexing="ij")
    return [tuple(map(float, p)) for p in np.stack([m.ravel() for m in mesh], axis=1)]


def _check_axes(data, source, axes) -> None:
    n = math.prod(a.values.size for a in axes)
    if n > MAX_POINTS:
        raise InputError(f"{n} grid points is too many (at most {MAX_POINTS})")
    for a in axes:
        for path in a.path.split(","):
            check_path(data, path.strip(), float(a.values[0]), "--axis")
    parse_scene(data, source)  # the base scene itself must be valid


def sweep(scene, axes, out_dir, *, sets=(), outcomes=None, refine: int = 0, jobs: int = 2, executor=None,
          scheduler=None, progress: bool = False, plot: bool = True, map_axes=None, formats=("png",),
          dpi: int = 110, command=None) -> MapResult:
    """Run the scene file `scene` (a path or its content as a dict, `sets` = --set overrides
    applied) at every point of `axes` (a list of 'PATH=START:STOP:N' / 'PATH=a,b' texts, Axis
    objects or a {path: values} dict) and write the map into `out_dir`; see the module doc.
    `executor`: None/"local" (a pool of `jobs` workers, this process for jobs = 1), "dask", or
    any concurrent.futures-style executor (used as given). `refine`: bisection steps per
    boundary. `map_axes`: the figure's (x, y) paths (default the first two axes)."""
    data, source = scene_data(scene, sets)
    axes = _axes_of(axes)
    _check_axes(data, source, axes)
    out_dir = runner.check_sweep_args(out_dir, jobs)
    if not 0 <= refine <= 40:
        raise InputError(f"refine must lie in [0, 40] bisection steps, got {refine}")
    names = _base_run(data, source)  # before forking: the workers inherit the loaded engine
    paths = tuple(a.path for a in axes)
    columns = _columns(paths, names, outcomes)
    xy = _map_axes(map_axes, paths) if plot else None
    out_dir.mkdir(parents=True, exist_ok=True)
    remove_stale_temps(out_dir)
    job = _Job(data, source, axes, paths, names, columns, out_dir, refine, progress, command)
    with runner.folder_lock(out_dir), runner.executor_pool(executor, jobs, scheduler, out_dir / CSV_NAME) as \
            (pool, workers):
        result = job.run(pool, workers)
    if plot:
        from .map_figure import map_figure, save

        result.files += save(map_figure(result, *xy), out_dir / MAP_NAME, formats, dpi)
    return result


def _map_axes(map_axes, paths) -> tuple:
    if map_axes is None:
        return (paths[0], paths[1] if len(paths) > 1 else None)
    xy = tuple(map_axes)
    for p in xy:
        if p is not None and p not in paths:
            raise InputError(f"--map-axes: {p!r} is not an axis of this map ({', '.join(paths)})")
    if len(xy) != 2 or xy[0] == xy[1]:
        raise InputError("--map-axes: give two different axes X,Y")
    return xy


@dataclass
class _Job:
    data: dict
    source: str
    axes: list
    paths: tuple
    names: tuple
    columns: tuple
    out_dir: Path
    refine: int
    progress: bool
    command: object

    @property
    def record(self) -> dict:
        """What rows of one folder must share: the scene (after --set), the axes, the columns."""
        return {"schema": SCHEMA, "scene": self.data, "axes": list(self.paths), "columns": list(self.columns)}

    def points(self, pool, workers, points, on_rows=None) -> list[dict]:
        rows: list[dict] = []

        def take(chunk):
            rows.extend(chunk)
            if on_rows is not None:
                on_rows(chunk)

        args = (self.data, self.source, self.paths, self.names)
        if pool is None:
            with _jit.one_blas_thread():
                runner.run_chunked(_run_chunk, args, points, None, 1, take)
        else:
            runner.run_chunked(_run_chunk, args, points, pool, workers, take)
        return rows

    def run(self, pool, workers) -> MapResult:
        started = time.perf_counter()
        earlier = _prepare_folder(self.out_dir, self.record, self.columns, self.paths)
        done = {runner.row_key(r, self.paths) for r in earlier}
        points = _grid_points(self.axes)
        todo = [p for p in points if runner.point_key(p) not in done]
        new: list[dict] = []
        lines: dict = {}  # the new rows' CSV lines, formatted once (runner.row_sink)
        with runner.progress(self.progress, len(points)) as bar, \
                runner.row_sink(self.out_dir / CSV_NAME, self.columns, bar, new, lines) as record_rows:
            bar.advance(len(points) - len(todo))
            self.points(pool, workers, todo, record_rows)
        compute_s = time.perf_counter() - started
        every = runner.sorted_unique(earlier + new, self.paths)
        runner.write_table(self.out_dir / CSV_NAME, every, self.columns, self.paths, lines)
        wanted = {runner.point_key(p) for p in points}
        rows = [r for r in every if runner.row_key(r, self.paths) in wanted]
        boundaries = refine_boundaries(self, rows, pool, workers) if self.refine else []
        result = MapResult(self.out_dir, self.axes, self.columns, rows, len(new), len(points) - len(todo),
                           boundaries, compute_s=compute_s)
        result.files = self.write_outputs(result, pool is not None and workers or 1)
        result.wall_s = time.perf_counter() - started
        return result

    def write_outputs(self, result: MapResult, workers: int) -> list[Path]:
        files = [self.out_dir / CSV_NAME, self.out_dir / SETTINGS_NAME]
        if runner.has_pyarrow():
            files.append(runner.write_parquet(self.out_dir / PARQUET_NAME, self.out_dir / CSV_NAME, self.columns,
                                              TEXT_COLUMNS))
        if result.boundaries:
            keys = list(result.boundaries[0])
            write_csv(self.out_dir / BOUNDARIES_NAME, {k: [b[k] for b in result.boundaries] for k in keys})
            files.append(self.out_dir / BOUNDARIES_NAME)
        counts = {"points": len(result.rows), "computed": result.computed, "reused": result.reused,
                  "compute_wall_s": result.compute_s, "workers": workers, "regimes": len(result.regimes),
                  "boundaries": len(result.boundaries), "refine_steps": self.refine}
        grid = {a.path: a.values.tolist() for a in self.axes}
        write_json(self.out_dir / SETTINGS_NAME, self.record | {"grid": grid, "counts": counts,
                                                                "provenance": provenance(self.command)})
        return files


# --------------------------------------------------------------------------- boundaries
def _brackets(job: _Job, rows) -> list[dict]:
    """Neighbouring grid points (along one axis, the others equal) of different regimes."""
    by_key = {runner.row_key(r, job.paths): r for r in rows}
    out = []
    for k, axis in enumerate(job.axes):
        for r in rows:
            i = int(np.searchsorted(axis.values, r[axis.path]))
            if i + 1 >= axis.values.size:
                continue
            nxt = [r[p] for p in job.paths]
            nxt[k] = float(axis.values[i + 1])
            other = by_key.get(runner.point_key(nxt))
            if other is not None and other["regime"] != r["regime"]:
                out.append({"axis": axis.path, "point": [r[p] for p in job.paths], "lo": r[axis.path],
                            "hi": nxt[k], "regime_lo": r["regime"], "regime_hi": other["regime"], "k": k})
    return out


def refine_boundaries(job: _Job, rows, pool, workers) -> list[dict]:
    """Bisect every bracket `job.refine` times, all brackets' midpoints run as one batch per
    step: the boundary lies in [lo, hi] (lo keeps regime_lo's regime)."""
    brackets = _brackets(job, rows)
    for _ in range(job.refine):
        mids = []
        for b in brackets:
            p = list(b["point"])
            p[b["k"]] = 0.5 * (b["lo"] + b["hi"])
            mids.append(tuple(p))
        got = {runner.row_key(r, job.paths): r for r in job.points(pool, workers, mids)}
        for b, p in zip(brackets, mids):
            if got[runner.point_key(p)]["regime"] == b["regime_lo"]:
                b["lo"] = p[b["k"]]
            else:
                b["hi"] = p[b["k"]]
    out = []
    for b in brackets:
        at = dict(zip(job.paths, b["point"])) | {b["axis"]: 0.5 * (b["lo"] + b["hi"])}
        out.append({"axis": b["axis"], **at, "lo": b["lo"], "hi": b["hi"], "regime_lo": b["regime_lo"],
                    "regime_hi": b["regime_hi"]})
    return out
