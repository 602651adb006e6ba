"""Writing results: every file is written to a temporary sibling and renamed into place, so an
interrupted run never leaves a half-written file where a complete one is expected.

A temporary file is locked (flock) by the process writing it, so the next run in the folder can
tell the temporary files of a killed run (unlocked: removed by `remove_stale_temps`) from those
of a run still writing. A write that fails (a full disk, a folder gone read-only) raises
`OutputError` naming the file: the CLI says it in one line and exits 1."""
from __future__ import annotations

import contextlib
import csv
import hashlib
import json
import math
import os
import re
import tempfile
from pathlib import Path

try:
    import fcntl
except ImportError:  # not POSIX: temporary files are not locked, and never taken for stale
    fcntl = None

import numpy as np

# Image formats every figure writer accepts (lossless PNG, SVG).
IMAGE_FORMATS = ("png", "svg")

_UMASK = os.umask(0)
os.umask(_UMASK)


class RunAborted(Exception):
    """A run or a sweep stopped for a reason outside its input (a full disk, a worker process
    killed): the CLI prints the message in one line and exits 1."""


class OutputError(RunAborted):
    """A results file could not be written; the message names it."""


def output_error(path, err: OSError) -> OutputError:
    return OutputError(f"cannot write {path}: {err.strerror or err}")


# mkstemp's names: ".<file name>.<8 random characters>.tmp", or ".tmp.gif" (keep_extension)
_TEMP_NAME = re.compile(r"^\..+\.[a-z0-9_]{8}\.tmp(\.[A-Za-z0-9]{1,5})?$")


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike, keep_extension: bool = False):
    """Yield a temporary path next to `path`; rename it over `path` only on success.
    `keep_extension`: the temporary name ends with `path`'s extension too, for writers that
    choose the format by it (Pillow's GIF, ffmpeg's MP4). An OSError while writing (ENOSPC,
    EROFS, ...) becomes an OutputError naming `path`."""
    path = Path(path)
    suffix = ".tmp" + (path.suffix if keep_extension else "")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix, dir=path.parent)
    except OSError as err:
        raise output_error(path, err) from None
    try:
        if fcntl is not None:
            fcntl.flock(fd, fcntl.LOCK_EX)  # ours while we write: not stale (remove_stale_temps)
        os.chmod(tmp, 0o666 & ~_UMASK)  # mkstemp makes 0600; give the file the usual permissions
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException as err:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        if isinstance(err, OSError):
            raise output_error(path, err) from None
        raise
    finally:
        os.close(fd)


def remove_stale_temps(folder) -> list[Path]:
    """Remove the temporary files a killed run left in `folder` (25 MB for a long trajectory):
    those no live process holds locked. Returns what was removed."""
    removed = []
    if fcntl is None:
        return removed
    with contextlib.suppress(OSError):
        for entry in os.scandir(folder):
            if not (_TEMP_NAME.match(entry.name) and entry.is_file(follow_symlinks=False)):
                continue
            try:
                with open(entry.path, "rb") as fh:
                    fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    os.unlink(entry.path)
                removed.append(Path(entry.path))
            except OSError:
                continue  # locked: a run writing it now
    return removed


def file_digest(path) -> str:
    """sha256 of a file's bytes (summary.json records those of the files it describes)."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def write_text(path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def _json_default(obj):
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


def _finite_or_none(obj):
    """JSON has no NaN/Infinity: write null instead of an invalid token."""
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, dict):
        return {k: _finite_or_none(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite_or_none(v) for v in obj]
    return obj


def dumps_json(data) -> str:
    return json.dumps(_finite_or_none(json.loads(json.dumps(data, default=_json_default))), indent=2,
                      allow_nan=False) + "\n"


def write_json(path, data) -> None:
    write_text(path, dumps_json(data))


def write_csv(path, columns: dict, order=None) -> None:
    """Columns of equal length; floats in their shortest round-trip form (0.05, not
    0.050000000000000003): reading the file back gives the very same float64. Written in blocks
    of rows straight to the (atomic) file: its text never sits in memory whole."""
    order = list(order or columns.keys())
    cols = [columns[name] for name in order]
    n = len(cols[0]) if cols else 0
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", newline="") as fh:
        writer = csv.writer(fh, lineterminator="\n")
        writer.writerow(order)
        for lo in range(0, n, _CSV_BLOCK):
            block = [c[lo: lo + _CSV_BLOCK] for c in cols]
            writer.writerows([repr(float(x)) if isinstance(x, (float, np.floating)) else x for x in row]
                             for row in zip(*block))


_CSV_BLOCK = 10_000  # rows per block written


def read_csv(path) -> dict:
    """Read a CSV written by write_csv: numeric columns as float arrays, others as str arrays."""
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    header, body = rows[0], rows[1:]
    out = {}
    for j, name in enumerate(header):
        col = [r[j] for r in body]
        try:
            out[name] = np.array([float(x) for x in col])
        except ValueError:
            out[name] = np.array(col, dtype=object)
    return out


def provenance(command: str | None = None) -> dict:
    """Where a result came from: package and library versions, the command line, the time."""
    import datetime
    import platform
    import shlex
    import sys
    from importlib import metadata

    from . import __version__

    def version(name: str):
        try:
            return metadata.version(name)
        except metadata.PackageNotFoundError:
            return None

    if command is None:
        command = " ".join(shlex.quote(a) for a in ["nonsmooth-rod", *sys.argv[1:]]) \
            if sys.argv and sys.argv[0].endswith("nonsmooth-rod") else " ".join(map(shlex.quote, sys.argv))
    return {"version": __version__, "command": command, "python": platform.python_version(),
            "numpy": np.__version__, "scipy": version("scipy"), "numba": version("numba"),
            "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}
