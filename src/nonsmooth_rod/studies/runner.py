"""The machinery every sweep shares (the rod's regime map and maps of any scene): points run in
chunks on any concurrent.futures-style executor (executors.py), rows streamed to a CSV as they
finish (flushed: an interrupted sweep resumes), the table read back, sorted and rewritten
atomically, Parquet beside it, a folder lock, a progress bar."""
from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import os
import sys

import numpy as np
from concurrent.futures import FIRST_COMPLETED, wait
from pathlib import Path

from ..io import dumps_json, output_error, write_json, write_text
from ..validation import InputError

KEY_DIGITS = 12  # point values are matched to this many decimals when resuming
LOCK_NAME = ".sweep.lock"


# --------------------------------------------------------------------------- axes' values
def _range_values(text: str, name: str, max_count: int) -> np.ndarray:
    parts = text.split(":")
    usage = f"{name}: expected START:STOP:N, a,b,c or a number, got {text!r}"
    if len(parts) != 3:
        raise InputError(usage)
    try:
        start, stop = float(parts[0]), float(parts[1])
    except ValueError:
        raise InputError(usage) from None
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise InputError(f"{name}: values must be finite, got {text!r}")
    if not parts[2].strip().isdigit():
        raise InputError(f"{name}: the count N in START:STOP:N must be a positive integer, got {parts[2]!r}")
    count = int(parts[2])
    if not 1 <= count <= max_count:
        raise InputError(f"{name}: the count N must lie in [1, {max_count}], got {count}")
    if count == 1 and start != stop:
        raise InputError(f"{name}: one value between {start:g} and {stop:g}? give N ≥ 2 or a single number")
    if stop < start:
        raise InputError(f"{name}: the range {text!r} runs backwards: give START ≤ STOP")
    if count > 1 and start == stop:
        raise InputError(f"{name}: {count} values from {start:g} to {stop:g} are all the same: give N = 1")
    return np.linspace(start, stop, count)


def parse_range(text: str, name: str, *, max_count: int = 2000) -> np.ndarray:
    """'START:STOP:N' (N values, ends included, START ≤ STOP), 'a,b,c' (no repeats) or a number."""
    text = str(text).strip()
    if ":" in text:
        values = _range_values(text, name, max_count)
    else:
        try:
            values = np.array([float(x) for x in text.split(",")])
        except ValueError:
            raise InputError(f"{name}: expected START:STOP:N, a,b,c or a number, got {text!r}") from None
    if not np.all(np.isfinite(values)):
        raise InputError(f"{name}: values must be finite, got {text!r}")
    if values.size > max_count:
        raise InputError(f"{name}: at most {max_count} values, got {values.size}")
    if has_repeats(values):
        raise InputError(f"{name}: a value is given twice in {text!r}")
    return values


def has_repeats(values: np.ndarray) -> bool:
    """Two values equal to KEY_DIGITS decimals (the resume key). Huge values are refused by
    the axis limits later; rounding them must not warn of an overflow first."""
    with np.errstate(over="ignore", invalid="ignore"):
        rounded = np.round(values, KEY_DIGITS)
    rounded = np.where(np.isfinite(rounded), rounded, values)
    return np.unique(rounded).size != rounded.size


# --------------------------------------------------------------------------- rows in a CSV
def point_key(values) -> tuple:
    return tuple([round(float(v), KEY_DIGITS) for v in values])


def row_key(row: dict, columns) -> tuple:
    return point_key([row[c] for c in columns])


def _cell(value) -> str:
    if isinstance(value, float):
        return "" if value != value else repr(float(value))  # shortest round-trip text; NaN empty
    return str(value)


def row_lines(rows, columns) -> str:
    return "".join(each_row_line(rows, columns))


def each_row_line(rows, columns) -> list[str]:
    """Each row's CSV line (row_lines cut per row): kept by the sink, so the final table joins
    them instead of formatting every cell a second time (10⁴ points × 40 columns: 0.2 s)."""
    buf = io.StringIO()
    writer, ends = csv.writer(buf, lineterminator="\n"), []
    for row in rows:
        writer.writerow([_cell(row[c]) for c in columns])
        ends.append(buf.tell())
    text, start, lines = buf.getvalue(), 0, []
    for end in ends:
        lines.append(text[start:end])
        start = end
    return lines


def _parse_row(fields, columns, text_columns, key_columns, required) -> dict | None:
    if len(fields) != len(columns):
        return None
    row = dict(zip(columns, fields))
    try:
        for c in columns:
            if c not in text_columns:
                row[c] = float(row[c]) if row[c] != "" else math.nan
    except ValueError:
        return None
    if not row[required] or not all(math.isfinite(row[c]) for c in key_columns):
        return None
    return row


def read_table(path, columns, text_columns, key_columns, required: str) -> tuple[list[dict], int]:
    """Rows of a sweep's CSV and the number of unreadable lines (an interrupted write); a row
    needs finite `key_columns` and a non-empty `required` text."""
    path = Path(path)
    text = path.read_text(encoding="utf-8")
    if text and not text.endswith("\n"):
        # Every row is written with its newline: a last line without one was cut mid-write,
        # even if its cells happen to parse (a truncated text cell would).
        text = text[: text.rfind("\n") + 1]
    lines = list(csv.reader(io.StringIO(text, newline="")))
    if not lines:
        return [], 0
    if tuple(lines[0]) != tuple(columns):
        raise InputError(f"{path} does not start with the header {','.join(columns)}: not this sweep's map")
    rows, bad = [], 0
    for fields in lines[1:]:
        row = _parse_row(fields, columns, text_columns, key_columns, required)
        if row is None:
            bad += 1
        else:
            rows.append(row)
    return rows, bad


def sorted_unique(rows, key_columns) -> list[dict]:
    """One row per point (the last one read wins), the first key column varying fastest."""
    unique = {row_key(r, key_columns): r for r in rows}
    return [unique[k] for k in sorted(unique, key=lambda k: k[::-1])]


def write_table(path, rows, columns, key_columns, lines: dict | None = None) -> None:
    """The table, one row per point in order, atomically; `lines`: rows' CSV lines already
    formatted (by id of the row: row_sink's), the others formatted here."""
    header = row_lines([dict(zip(columns, columns))], columns)  # quoted where a name holds a comma
    lines = lines or {}
    body = "".join(lines.get(id(r)) or row_lines([r], columns) for r in sorted_unique(rows, key_columns))
    write_text(path, header + body)


def write_parquet(path: Path, csv_path: Path, columns, text_columns) -> Path:
    """The table as Parquet, atomically, converted from the final CSV by Arrow's own reader:
    building it from Python values would import pandas (a second) through pyarrow."""
    import pyarrow as pa
    import pyarrow.csv as pa_csv
    import pyarrow.parquet as pq

    from ..io import atomic_path

    types = {c: pa.string() if c in text_columns else pa.float64() for c in columns}
    table = pa_csv.read_csv(csv_path, convert_options=pa_csv.ConvertOptions(
        column_types=types, strings_can_be_null=False, include_columns=list(columns)))
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp)
    return path


def has_pyarrow() -> bool:
    import importlib.util

    return importlib.util.find_spec("pyarrow") is not None


def claim_folder(out_dir: Path, csv_path: Path, settings_path: Path, record: dict, other: str) -> None:
    """Refuse a folder whose earlier sweep was made with other settings (`other` says what differs)
    or whose table has no settings beside it; record the settings of a new one."""
    if settings_path.exists():
        try:
            old = json.loads(settings_path.read_text(encoding="utf-8"))
        except (json.JSONDecodeError, UnicodeDecodeError):
            raise InputError(f"{settings_path} is not valid JSON: remove it or use another --out") from None
        old = {k: old.get(k) for k in record}  # the grid, provenance and accuracy may differ
        if json.loads(dumps_json(old)) != json.loads(dumps_json(record)):
            raise InputError(f"{out_dir} holds {other} (see {settings_path}): use another --out or remove the folder")
    elif csv_path.exists():
        raise InputError(f"{csv_path} exists without {settings_path.name}: not a sweep folder; use another --out")
    else:
        write_json(settings_path, record)


def check_sweep_args(out_dir, jobs: int) -> Path:
    """The arguments every sweep shares, checked: at least one job, an --out that is (or can be) a folder."""
    if jobs < 1:
        raise InputError(f"jobs must be at least 1, got {jobs}")
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError(f"--out '{out_dir}' exists and is not a folder")
    return out_dir


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


# --------------------------------------------------------------------------- running points
@contextlib.contextmanager
def executor_pool(executor, jobs: int, scheduler, csv_path: Path):
    """(pool, workers) for a sweep's `executor`: one given by the caller is used as is (not shut
    down here; `jobs` sizes the chunks); None/"local" and "dask" are opened and closed here. A
    lost worker stops the sweep with where its finished points are kept."""
    if executor is not None and not isinstance(executor, str):
        yield executor, jobs
        return
    from ..executors import WorkerLost, open_executor

    try:
        with open_executor(executor or "local", jobs, scheduler) as (pool, workers):
            yield pool, workers
    except WorkerLost as err:
        raise WorkerLost(f"{err}: the sweep stopped; the points finished are kept in {csv_path}: "
                         "run the same sweep again to resume") from None


@contextlib.contextmanager
def row_sink(csv_path: Path, columns, bar, collected: list, lines: dict | None = None):
    """`record_rows(rows)`: append finished rows to the sweep's CSV as they arrive (a row on disk
    is a row an interrupted sweep need not redo), keep them in `collected` (and each one's line in
    `lines`, by id, for write_table), advance the bar."""
    with open(csv_path, "a", newline="", encoding="utf-8") as sink:
        def record_rows(rows):
            texts = each_row_line(rows, columns)
            if lines is not None:
                lines.update(zip(map(id, rows), texts))
            try:
                sink.write("".join(texts))
                sink.flush()
            except OSError as err:  # a full disk: the rows written stay, a resume redoes the rest
                raise output_error(csv_path, err) from None
            collected.extend(rows)
            bar.advance(len(rows))

        yield record_rows


def run_chunked(task, args: tuple, todo, pool, workers, on_rows, meanwhile=None) -> None:
    """Run `task(*args, chunk) → rows` over `todo`: in this process (pool None, one point per
    call) or in chunks on `pool`; `on_rows` gets each finished chunk's rows as they arrive.
    `meanwhile()` runs in this process, in a thread while the workers compute (after them
    without a pool). `task` must be a module-level function (pickled to the workers)."""
    if pool is None:
        for pt in todo:
            on_rows(task(*args, [pt]))
        if meanwhile is not None:
            meanwhile()
        return
    # Chunks: little pickling overhead per point, yet a progress bar that moves and enough
    # tasks to balance the workers.
    size = max(1, min(250, len(todo) // (8 * workers)))
    pending = {pool.submit(task, *args, todo[i:i + size]) for i in range(0, len(todo), size)}
    side = Background(meanwhile)
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


class Background:
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


def progress(enabled: bool, total: int):
    return _RichProgress(total) if enabled else _NoProgress()
