"""Scene keys named by dotted paths, as `run --set` names them (`contacts.foot.law.mu_s`,
`bodies.block.mass`, `lines.slope.angle_deg`, `initial.ball.v.0`), with `*` for every entry of an
array of tables (`contacts.*.law.mu_s`: both corners of a block) and an integer for a vector's
component. A study varies such a key: it must name a number the scene file holds or accepts."""
from __future__ import annotations

import copy
import math

from ..scenefile import apply_override, parse_scene
from ..validation import InputError


def _entries(node, key: str, walked: list, path: str) -> list:
    """The children of `node` a path segment selects (several for `*`)."""
    where = ".".join(walked) or "the scene"
    if isinstance(node, list):
        if key == "*":
            return [t for t in node if isinstance(t, dict)] or _nothing(path, where)
        if key.isdigit() and int(key) < len(node) and not isinstance(node[int(key)], dict):
            return [(node, int(key))]
        match = [t for t in node if isinstance(t, dict) and t.get("name") == key]
        if not match:
            have = ", ".join(str(t.get("name")) for t in node if isinstance(t, dict)) or "nothing"
            raise InputError(f"{path}: no entry named {key!r} in {where} (have: {have})")
        return match
    if isinstance(node, dict):
        if key not in node:
            raise InputError(f"{path}: {where} has no key {key!r} (has: {', '.join(map(str, node)) or 'nothing'})")
        return [node[key]]
    raise InputError(f"{path}: {where} is a value, not a table")


def _nothing(path, where):
    raise InputError(f"{path}: {where} has no entries for '*'")


def _slots(data: dict, path: str) -> list[tuple]:
    """(container, key) of every value `path` names in `data`; the last key may be absent from
    a table (the scene's default then applies: checked by parsing)."""
    keys = path.split(".")
    if not path or not all(keys):
        raise InputError(f"{path!r}: expected a dotted path such as contacts.floor.law.mu_s")
    nodes, walked = [data], []
    for k in keys[:-1]:
        nodes = [c for n in nodes for c in _entries(n, k, walked, path)]
        walked.append(k)
        if any(isinstance(n, tuple) for n in nodes):
            raise InputError(f"{path}: {'.'.join(walked)} is a number, not a table")
    last, slots = keys[-1], []
    for n in nodes:
        if isinstance(n, list) and last.isdigit() and int(last) < len(n):
            slots.append((n, int(last)))
        elif isinstance(n, dict):
            slots.append((n, last))
        elif isinstance(n, list):
            raise InputError(f"{path}: {'.'.join(walked)} has no entry {last!r}")
        else:
            raise InputError(f"{path}: {'.'.join(walked)} is a value, not a table")
    return slots


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def current_value(data: dict, path: str) -> float | None:
    """The number `path` holds in `data` (the first, for `*`), None if the file leaves it to a
    default; an InputError if it names nothing or something that is not a number."""
    values = []
    for node, key in _slots(data, path):
        has = key in node if isinstance(node, dict) else True
        if has and not _is_number(node[key]):
            raise InputError(f"{path}: holds {node[key]!r}, not a number: it cannot be varied")
        values.append(float(node[key]) if has else None)
    return values[0]


def set_value(data: dict, path: str, value: float) -> None:
    """Set the number at `path` (every entry for `*`) in `data`, in place."""
    for node, key in _slots(data, path):
        node[key] = float(value)


def with_values(data: dict, values: dict) -> dict:
    """A copy of `data` with every path of `values` set; a key 'a,b' sets both paths (one axis
    moving two keys together: a belt's speed and the block's initial velocity)."""
    out = copy.deepcopy(data)
    for paths, value in values.items():
        for path in paths.split(","):
            set_value(out, path.strip(), value)
    return out


def apply_sets(data: dict, assignments, source: str = "--set") -> dict:
    """A copy of `data` with `--set PATH=VALUE` overrides: a numeric value may use `*`."""
    out = copy.deepcopy(data)
    for text in assignments:
        path, _, value = text.partition("=")
        if "*" in path.split("."):
            try:
                number = float(value)
            except ValueError:
                raise InputError(f"{source} {text!r}: a path with '*' takes a number") from None
            set_value(out, path.strip(), number)
        else:
            apply_override(out, text, source)
    return out


def check_path(data: dict, path: str, probe: float, source: str) -> float | None:
    """Refuse a path that names nothing, holds no number, or that the scene refuses at the
    value `probe` (a key the schema does not know); return its current value."""
    try:
        now = current_value(data, path)
    except InputError as err:
        raise InputError(f"{source} {err}") from None
    if not math.isfinite(probe):
        raise InputError(f"{source} {path}: values must be finite")
    try:
        parse_scene(with_values(data, {path: probe}), source=f"{source} {path}={probe:g}")
    except InputError as err:
        if "unknown key" in str(err):  # a point the scene refuses (μd > μs) is recorded, not fatal
            raise
    return now
