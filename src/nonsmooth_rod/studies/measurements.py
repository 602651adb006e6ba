"""Measurements a fit explains: located events and/or a sampled trajectory.

Events: a TOML or JSON file of `[[events]]`, each with `kind` (impact, slip, stick, lift-off),
`contact` (a contact of the scene), `t` (s) and `sigma` (its standard uncertainty, s > 0);
events of one kind at one contact in increasing time (the n-th measured one is matched with the
n-th simulated one). A trajectory: a CSV whose header is `t` and columns named as trajectory.csv
names them (`block.x`, `rod.theta`, `A.N`, ...), then one row starting with `sigma` (each
column's standard uncertainty, > 0), then the samples at strictly increasing t."""
from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..result_files import BODY_QUANTITIES
from ..validation import InputError, require_nonnegative, require_positive
from .outcome import EVENT_KINDS


@dataclass
class Measurements:
    events: list[dict] = field(default_factory=list)   # kind, contact, t, sigma
    t: np.ndarray | None = None                          # trajectory sample times
    columns: dict = field(default_factory=dict)          # name -> measured values
    sigma: dict = field(default_factory=dict)            # name -> standard uncertainty
    files: list = field(default_factory=list)

    @property
    def count(self) -> int:
        return len(self.events) + (0 if self.t is None else self.t.size * len(self.columns))


def trajectory_names(body_names, contact_names) -> list[str]:
    """The numeric columns of trajectory.csv a measured trajectory may name."""
    return [f"{b}.{q}" for b in body_names for q in BODY_QUANTITIES] + [
        f"{c}.{f}" for c in contact_names for f in ("N", "T")]


def _number(where: str, name: str, value, check=require_nonnegative) -> float:
    """A measured time (≥ 0) or uncertainty (> 0): a number, not a string or a bool."""
    try:
        return check(name, value)
    except InputError as err:
        raise InputError(f"{where}: {err}") from None


def _event(path, i: int, e, contact_names) -> dict:
    where = f"{path}: events[{i}]"
    if not isinstance(e, dict):
        raise InputError(f"{where}: must be a table with kind, contact, t, sigma")
    unknown = sorted(set(e) - {"kind", "contact", "t", "sigma"})
    missing = [k for k in ("kind", "contact", "t", "sigma") if k not in e]
    if unknown or missing:
        raise InputError(f"{where}: {'unknown key ' + repr(unknown[0]) if unknown else 'missing ' + missing[0]}"
                         "; an event has kind, contact, t, sigma")
    if e["kind"] not in EVENT_KINDS:
        raise InputError(f"{where}: kind {e['kind']!r} is not one of {', '.join(EVENT_KINDS)}")
    if e["contact"] not in contact_names:
        raise InputError(f"{where}: no contact named {e['contact']!r} in the scene (have: {', '.join(contact_names)})")
    t = _number(where, "t", e["t"])
    return {"kind": e["kind"], "contact": e["contact"], "t": t,
            "sigma": _number(where, "sigma", e["sigma"], require_positive)}


def read_events(path, contact_names) -> list[dict]:
    from ..scenefile import read_data

    path = Path(path)
    data, _ = read_data(path, "measured events")
    if set(data) - {"events"} or not isinstance(data.get("events"), list):
        raise InputError(f"{path}: expected only [[events]] tables (kind, contact, t, sigma)")
    events = [_event(path, i, e, contact_names) for i, e in enumerate(data["events"])]
    if not events:
        raise InputError(f"{path}: no events")
    last: dict = {}
    for e in events:
        key = (e["kind"], e["contact"])
        if key in last and e["t"] <= last[key]:
            raise InputError(f"{path}: the {e['kind']} events at {e['contact']} must have increasing times "
                             f"({e['t']:g} after {last[key]:g})")
        last[key] = e["t"]
    return events


def _numbers(path, line_no: int, fields) -> np.ndarray:
    try:
        values = np.array([float(f) for f in fields])
    except ValueError:
        raise InputError(f"{path}: line {line_no}: every cell must be a number, got {fields}") from None
    if not np.all(np.isfinite(values)):
        raise InputError(f"{path}: line {line_no}: values must be finite")
    return values


def read_trajectory(path, known_columns) -> tuple[np.ndarray, dict, dict]:
    """(t, measured columns, sigma per column) of a measured trajectory CSV (see the module doc)."""
    path = Path(path)
    try:
        lines = [row for row in csv.reader(path.read_text(encoding="utf-8").splitlines()) if row]
    except (OSError, UnicodeDecodeError) as err:
        raise InputError(f"{path}: cannot read ({getattr(err, 'strerror', None) or err})") from None
    if len(lines) < 3 or not lines[0] or lines[0][0].strip() != "t" or len(lines[0]) < 2:
        raise InputError(f"{path}: expected a header 't,<column>,...', a 'sigma,...' row, then samples")
    names = [n.strip() for n in lines[0][1:]]
    unknown = [n for n in names if n not in known_columns]
    if unknown:
        raise InputError(f"{path}: unknown column {unknown[0]!r}; columns are named as in trajectory.csv: "
                         f"{', '.join(known_columns)}")
    if len(set(names)) != len(names):
        raise InputError(f"{path}: a column is named twice")
    if lines[1][0].strip() != "sigma" or len(lines[1]) != len(names) + 1:
        raise InputError(f"{path}: line 2 must be 'sigma' then each column's standard uncertainty")
    sigma = _numbers(path, 2, lines[1][1:])
    if np.any(sigma <= 0):
        raise InputError(f"{path}: sigma of {names[int(np.argmin(sigma))]} must be > 0, got {sigma.min():g}")
    rows = []
    for i, fields in enumerate(lines[2:], start=3):
        if len(fields) != len(names) + 1:
            raise InputError(f"{path}: line {i}: expected {len(names) + 1} cells, got {len(fields)}")
        rows.append(_numbers(path, i, fields))
    data = np.array(rows)
    t = data[:, 0]
    if t[0] < 0 or np.any(np.diff(t) <= 0):
        raise InputError(f"{path}: the times t must be ≥ 0 and strictly increasing")
    return t, {n: data[:, k + 1] for k, n in enumerate(names)}, dict(zip(names, map(float, sigma)))


def read_measurements(files, body_names, contact_names) -> Measurements:
    """Events from .toml/.json files, a trajectory from a .csv (at most one)."""
    m = Measurements(files=[str(f) for f in files])
    if not files:
        raise InputError("--measured: give at least one file of events (.toml/.json) or a trajectory (.csv)")
    for f in files:
        if Path(f).suffix.lower() == ".csv":
            if m.t is not None:
                raise InputError(f"--measured {f}: one trajectory file at most")
            m.t, m.columns, m.sigma = read_trajectory(f, trajectory_names(body_names, contact_names))
        else:
            m.events += read_events(f, contact_names)
    return m
