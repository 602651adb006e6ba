"""Scene files: a whole simulation (bodies, lines, contacts, forces, initial state, method) as
TOML or JSON, schema "nonsmooth-rod/scene/1" (docs/scene-format.md).

    sf = load_scene("ball.toml", overrides=["contacts.floor.law.restitution=0.8"])
    result = simulate_scene(sf)

Every mistake is one InputError line naming the file, the key (a dotted path by name, the same
syntax `--set` takes: `contacts.floor.law.mu_d`) and what is wrong.
"""
from __future__ import annotations

import dataclasses
import itertools
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .integrators import METHODS
from . import scene_collisions
from .model import shapes
from .model.body import RigidBody
from .model.contacts import DiskOnDisk, DiskOnLine, DiskOnSegment, Line, Segment, SegmentEndOnEdge
from .model.laws import ContactLaw
from .model.motion import INTERPOLATIONS, DrivenBody, Harmonic, Tabulated
from .scene_forces import FORCE_KINDS, build_force, make_scene
from .validation import MAX_INTEGER, MAX_STATE, InputError, quoted, require_finite

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10: the backport (dependency `tomli; python_version < "3.11"`)
    import tomli as tomllib

SCHEMA = "nonsmooth-rod/scene/1"
SHAPES = ("disk", "ball", "rectangle", "polygon", "rod", "rod-with-balls")
CONTACT_KINDS = ("disk-on-line", "point-on-line", "disk-on-disk", "disk-on-segment", "point-on-segment",
                 "segment-end-on-edge", "linear")
NAME_PATTERN = re.compile(r"[A-Za-z0-9_+\-]{1,200}")  # fullmatch: no trailing newline
OVERLAP_TOLERANCE = 1e-9  # m per metre of the scene's size: penetration allowed in the initial state
_REQUIRED = object()
MAX_DEPTH = 16  # tables and lists nest at most this deep (a scene needs 4)

TOP_KEYS = ("schema", "title", "description", "gravity", "bodies", "lines", "segments", "contacts", "forces",
            "joints", "initial", "simulation", "laws")
BODY_KEYS = ("name", "mass", "inertia", "shape", "density", "thickness", "radius", "width", "height",
             "length", "ball_radius", "rod_diameter", "vertices", "collide", "group", "collides_with")
COLLISION_KEYS = ("collide", "group", "collides_with")  # scene_collisions.py: not dimensions of a shape
LINE_KEYS = ("name", "point", "angle_deg", "velocity", "length", "motion")
SEGMENT_KEYS = ("name", "a", "b", "motion")
# A prescribed motion (model/motion.py) of a line, segment or body: a displacement from its placement.
MOTION_KEYS = {"harmonic": ("kind", "amplitude", "frequency_hz", "phase_deg"),
               "table": ("kind", "times", "positions", "interpolation")}
LAW_KEYS = ("mu_s", "mu_d", "restitution")
CONTACT_KEYS = {
    "disk-on-line": ("kind", "name", "body", "offset", "radius", "line", "law"),
    "point-on-line": ("kind", "name", "body", "offset", "line", "law"),
    "disk-on-disk": ("kind", "name", "body_a", "body_b", "radius_a", "radius_b", "offset_a", "offset_b", "law"),
    "disk-on-segment": ("kind", "name", "body", "offset", "radius", "segment", "law"),
    "point-on-segment": ("kind", "name", "body", "offset", "segment", "law"),
    "segment-end-on-edge": ("kind", "name", "body", "segment", "end", "edge_start", "edge_end", "law"),
    "linear": ("kind", "name", "gap0", "normal", "tangent", "tangent_velocity", "law"),
}
FORCE_KEYS = {
    "spring": ("kind", "name", "body", "point", "body_b", "point_b", "stiffness", "rest_length", "damping"),
    "damper": ("kind", "name", "body", "point", "body_b", "point_b", "damping"),
    "constant": ("kind", "name", "body", "force", "torque", "point"),
    "ramped": ("kind", "name", "body", "force", "torque", "point", "t_start", "t_full"),
    "tabulated": ("kind", "name", "body", "times", "forces", "torques", "point"),
    "torsion-spring": ("kind", "name", "body", "body_b", "stiffness", "rest_angle_deg", "damping"),
    "torque": ("kind", "name", "body", "torque"),
}
JOINT_KINDS = ("pin", "slider", "linear")
JOINT_KEYS = {"pin": ("kind", "name", "body_a", "point_a", "body_b", "point_b"),
              "slider": ("kind", "name", "body_a", "point_a", "body_b", "point_b", "axis", "angle_deg"),
              "linear": ("kind", "name", "row", "constant")}


@dataclass
class SceneFile:
    """A parsed scene file: the Scene, its initial state and how to run it, with every name."""

    scene: object
    q0: np.ndarray
    v0: np.ndarray
    t_end: float
    method: str
    options: dict
    stop: list
    body_names: list
    contact_names: list
    line_names: list
    force_names: list
    shapes: dict  # body name -> {"shape": ..., dimensions}; {} when drawn from its contacts
    lines: dict  # line name -> Line
    data: dict  # the file's content after overrides (JSON-able)
    source: str = "<scene>"
    title: str = ""
    text: str = ""  # the file as read (for a copy next to the results)
    overrides: list = field(default_factory=list)
    segments: dict = field(default_factory=dict)  # segment name -> Segment
    joint_names: list = field(default_factory=list)
    save_every: float | None = None  # [simulation] save_every: one kept sample per this many seconds


class _Where:
    """Builds one-line errors: '<file>: <key>: <what>'."""

    def __init__(self, source: str):
        self.source = source

    def error(self, key: str, what: str) -> InputError:
        return InputError(f"{self.source}: {key}: {what}" if key else f"{self.source}: {what}")


# --- reading values ------------------------------------------------------------------------------

def _join(key: str, name: str) -> str:
    """The dotted key of `name` inside `key` (a list index joins without a dot: forces[3])."""
    return f"{key}{name}" if name.startswith("[") else f"{key}.{name}" if key else name


def _check_keys(w: _Where, table, allowed, key: str) -> None:
    if not isinstance(table, dict):
        raise w.error(key, f"must be a table, got {quoted(table)}")
    unknown = [k for k in table if k not in allowed]
    if unknown:
        raise w.error(f"{key}.{unknown[0]}" if key else unknown[0],
                      f"unknown key; allowed here: {', '.join(allowed)}")


def _number(w: _Where, table: dict, name: str, key: str, default=_REQUIRED, *, positive=False,
            nonnegative=False):
    value = table.get(name, default)
    full = _join(key, name)
    if value is _REQUIRED:
        raise w.error(full, "missing (a number is required)")
    if value is None and name not in table:  # an optional number left out
        return None
    try:
        value = require_finite("", value)
    except InputError as err:
        raise w.error(full, str(err).strip()) from None
    if positive and value <= 0:
        raise w.error(full, f"must be positive, got {value:g}")
    if nonnegative and value < 0:
        raise w.error(full, f"must be non-negative, got {value:g}")
    return value


def _vector(w: _Where, table: dict, name: str, key: str, n: int, default=_REQUIRED) -> tuple:
    value = table.get(name, default)
    full = _join(key, name)
    if value is _REQUIRED:
        raise w.error(full, f"missing (a list of {n} numbers is required)")
    if not isinstance(value, (list, tuple)) or len(value) != n:
        raise w.error(full, f"must be a list of {n} numbers, got {quoted(value)}")
    if all(type(x) is float or type(x) is int for x in value):  # fast: a table of 10⁶ rows
        array = np.array(value, dtype=float)
        if np.all(np.isfinite(array)):
            return tuple(array.tolist())
    numbers = []
    for i, x in enumerate(value):  # the slow path names the first bad entry
        try:
            numbers.append(require_finite("", x))
        except InputError as err:
            raise w.error(f"{full}[{i}]", str(err).strip()) from None
    return tuple(numbers)


def _text(w: _Where, table: dict, name: str, key: str, default=_REQUIRED, choices=None) -> str:
    value = table.get(name, default)
    full = _join(key, name)
    if value is _REQUIRED:
        raise w.error(full, "missing")
    if not isinstance(value, str):
        raise w.error(full, f"must be a string, got {quoted(value)}")
    if choices is not None and value not in choices:
        raise w.error(full, f"must be one of {', '.join(choices)}; got {quoted(value)}")
    return value


def _items(w: _Where, data: dict, section: str) -> list[tuple[str, dict]]:
    """(name, table) of an array of tables, names checked: present, well-formed and unique."""
    items = data.get(section, [])
    if not isinstance(items, list):
        raise w.error(section, f"must be an array of tables ([[{section}]]), got {quoted(items)}")
    out, seen = [], set()
    for i, table in enumerate(items):
        if not isinstance(table, dict):
            raise w.error(f"{section}[{i}]", f"must be a table, got {quoted(table)}")
        name = table.get("name", _REQUIRED)
        if name is _REQUIRED:
            raise w.error(f"{section}[{i}].name", "missing (every entry needs a name)")
        if not isinstance(name, str) or not NAME_PATTERN.fullmatch(name):
            raise w.error(f"{section}[{i}].name", f"must be letters, digits, '_', '+' or '-' (1 to 200), got {quoted(name)}")
        if name in seen:
            raise w.error(f"{section}.{name}", "duplicate name")
        seen.add(name)
        out.append((name, table))
    return out


def _lookup(w: _Where, names: list, value, key: str, what: str) -> int:
    if value is None:
        raise w.error(key, f"missing: name a {what} (have: {', '.join(names) or 'none'})")
    if not isinstance(value, str):
        raise w.error(key, f"must be the name of a {what}, got {quoted(value)}")
    if value not in names:
        have = ", ".join(names) or "none"
        raise w.error(key, f"no {what} named {quoted(value)} (have: {have})")
    return names.index(value)


# --- bodies ----------------------------------------------------------------------------------------

def _shape_mass(w, t, key, shape) -> float:
    """Mass from density for the shapes that have a volume (kg/m³; disks and rectangles need a thickness)."""
    rho = _number(w, t, "density", key, positive=True)
    if shape == "ball":
        return rho * 4.0 / 3.0 * math.pi * _number(w, t, "radius", key, positive=True) ** 3
    if shape in ("disk", "rectangle"):
        thick = _number(w, t, "thickness", key, positive=True)
        if shape == "disk":
            return rho * math.pi * _number(w, t, "radius", key, positive=True) ** 2 * thick
        return rho * _number(w, t, "width", key, positive=True) * _number(w, t, "height", key, positive=True) * thick
    raise w.error(f"{key}.density", f"a {shape} takes its mass directly: give mass instead")


SHAPE_KEYS = {None: (), "disk": ("radius", "density", "thickness"), "ball": ("radius", "density"),
              "rectangle": ("width", "height", "density", "thickness"), "rod": ("length",),
              "polygon": ("vertices", "density", "thickness"),
              "rod-with-balls": ("ball_radius", "rod_diameter", "length", "density")}


def _shape_of(w, t, key) -> tuple[dict, float | None, float | None]:
    """(drawing shape, mass, inertia) from `shape` and its dimensions; None where the shape gives none."""
    shape = _text(w, t, "shape", key, None, SHAPES) if "shape" in t else None
    stray = [k for k in t if k in BODY_KEYS[4:] and k not in SHAPE_KEYS[shape] and k not in COLLISION_KEYS]
    if stray:
        takes = ", ".join(SHAPE_KEYS[shape]) or "no dimensions (give mass and inertia, or a shape)"
        raise w.error(f"{key}.{stray[0]}", f"not a dimension of {'a ' + shape if shape else 'a body without shape'}: "
                                           f"it takes {takes}")
    if shape is None:
        return {}, None, None
    if shape == "rod-with-balls":
        dims = {k: _number(w, t, k, key, positive=True) for k in ("ball_radius", "rod_diameter", "length", "density")}
        try:
            mass, inertia = shapes.rod_with_balls(**dims)
        except InputError as err:
            raise w.error(key, str(err)) from None
        return {"shape": shape, **{k: dims[k] for k in ("ball_radius", "rod_diameter", "length")}}, mass, inertia
    if shape == "polygon":
        return _polygon_shape(w, t, key)
    needs = {"disk": ("radius",), "ball": ("radius",), "rectangle": ("width", "height"), "rod": ("length",)}[shape]
    dims = {k: _number(w, t, k, key, positive=True) for k in needs}
    if "mass" in t and "density" in t:
        raise w.error(f"{key}.density", "give mass or density, not both")
    mass = _number(w, t, "mass", key, positive=True) if "mass" in t else _shape_mass(w, t, key, shape)
    inertia = {"disk": shapes.disk_inertia, "ball": shapes.ball_inertia, "rectangle": shapes.rectangle_inertia,
               "rod": shapes.thin_rod_inertia}[shape](mass, *dims.values())
    return {"shape": shape, **dims}, mass, inertia


def _polygon_shape(w, t, key):
    """A convex polygon body: vertices about its centre of mass; mass, or density × area × thickness."""
    polygon = scene_collisions.polygon_of(w, t, key)
    if "mass" in t and "density" in t:
        raise w.error(f"{key}.density", "give mass or density, not both")
    if "mass" in t:
        mass = _number(w, t, "mass", key, positive=True)
    else:
        mass = (_number(w, t, "density", key, positive=True) * scene_collisions.polygon_area(polygon)
                * _number(w, t, "thickness", key, positive=True))
    return ({"shape": "polygon", "vertices": [list(p) for p in polygon.vertices]}, mass,
            scene_collisions.polygon_inertia(mass, polygon))


def _finite_shape_of(w, t, key):
    """_shape_of, refusing dimensions whose mass or inertia overflow a float."""
    try:
        shape, mass, inertia = _shape_of(w, t, key)
    except OverflowError:
        shape, mass, inertia = None, math.inf, math.inf
    if not all(x is None or math.isfinite(x) for x in (mass, inertia)):
        raise w.error(key, "the shape's mass or inertia overflows: dimensions or density far too large")
    return shape, mass, inertia


def _bodies(w, data) -> tuple[list, list, dict]:
    bodies, names, shapes = [], [], {}
    for name, t in _items(w, data, "bodies"):
        key = f"bodies.{name}"
        _check_keys(w, t, BODY_KEYS + ("motion",), key)
        shape, mass, inertia = _finite_shape_of(w, t, key)
        if "mass" in t or mass is None:
            mass = _number(w, t, "mass", key, positive=True)
        if "inertia" in t or inertia is None:
            inertia = _number(w, t, "inertia", key, positive=True)
        for what, x in (("mass", mass), ("inertia", inertia)):
            if x < 1e-300:  # 1/x would overflow
                raise w.error(f"{key}.{what}" if what in t else key, f"the {what} {x:g} is too small to invert")
        bodies.append(RigidBody(mass, inertia, name=name))
        names.append(name)
        shapes[name] = shape
    if not bodies:
        raise w.error("bodies", "a scene needs at least one [[bodies]] entry")
    return bodies, names, shapes


# --- lines, contacts, laws -------------------------------------------------------------------------

def _lines(w, data) -> dict:
    lines = {}
    for name, t in _items(w, data, "lines"):
        key = f"lines.{name}"
        if "angle" in t:
            raise w.error(f"{key}.angle", "angles of lines are given in degrees: write angle_deg")
        _check_keys(w, t, LINE_KEYS, key)
        _number(w, t, "length", key, None, positive=True)
        lines[name] = Line(_vector(w, t, "point", key, 2, [0.0, 0.0]),
                           math.radians(_number(w, t, "angle_deg", key, 0.0)),
                           _number(w, t, "velocity", key, 0.0), _motion(w, t, key, (2,)))
    return lines


def _segments(w, data) -> dict:
    segments = {}
    for name, t in _items(w, data, "segments"):
        key = f"segments.{name}"
        _check_keys(w, t, SEGMENT_KEYS, key)
        a, b = _vector(w, t, "a", key, 2), _vector(w, t, "b", key, 2)
        if a == b:
            raise w.error(f"{key}.b", f"equals a = {list(a)}: a segment of length 0")
        segments[name] = Segment(a, b, name, _motion(w, t, key, (2,)))
    return segments


def _motion(w, t, key, widths):
    """The `motion` table of a line, segment (widths (2,): x, y) or body ((2, 3): x, y(, θ)), or None."""
    if "motion" not in t:
        return None
    try:
        return _motion_of(w, t["motion"], f"{key}.motion", widths)
    except InputError as err:
        if str(err).startswith(w.source):
            raise
        raise w.error(f"{key}.motion", str(err)) from None


def _motion_of(w, m, key, widths):
    if not isinstance(m, dict):
        raise w.error(key, f"must be a table {{ kind = \"harmonic\" | \"table\", ... }}, got {quoted(m)}")
    kind = _text(w, m, "kind", key, choices=tuple(MOTION_KEYS))
    _check_keys(w, m, MOTION_KEYS[kind], key)
    if kind == "harmonic":
        amplitude = m.get("amplitude")
        n = len(amplitude) if isinstance(amplitude, list) and len(amplitude) in widths else widths[0]
        return Harmonic(_vector(w, m, "amplitude", key, n), _number(w, m, "frequency_hz", key, nonnegative=True),
                        math.radians(_number(w, m, "phase_deg", key, 0.0)))
    times = m.get("times")
    if not isinstance(times, list) or not times:
        raise w.error(f"{key}.times", f"must be a non-empty list of times, got {quoted(times)}")
    times = _vector(w, m, "times", key, len(times))
    if any(b <= a for a, b in itertools.pairwise(times)):
        raise w.error(f"{key}.times", "must increase strictly")
    rows = m.get("positions")
    if not isinstance(rows, list) or len(rows) != len(times):
        raise w.error(f"{key}.positions", f"must be a list of {len(times)} positions, one per time")
    n = len(rows[0]) if isinstance(rows[0], list) and len(rows[0]) in widths else widths[0]
    positions = [_vector(w, {f"[{i}]": r}, f"[{i}]", f"{key}.positions", n) for i, r in enumerate(rows)]
    return Tabulated(times, positions, _text(w, m, "interpolation", key, "linear", choices=INTERPOLATIONS))


def _driven_bodies(w, data, body_names) -> list:
    """A DrivenBody for every body with a `motion` table."""
    return [DrivenBody(i, _motion(w, t, f"bodies.{name}", (2, 3)))
            for i, (name, t) in enumerate(_items(w, data, "bodies")) if "motion" in t]


def _segment_contact(w, t, key, name, kind, body_names, segments):
    """A disk (or a body point, radius 0) on a segment: its interior or its nearest end."""
    body = _lookup(w, body_names, t.get("body"), f"{key}.body", "body")
    segment = list(segments.values())[_lookup(w, list(segments), t.get("segment"), f"{key}.segment", "segment")]
    radius = _number(w, t, "radius", key, nonnegative=True) if kind == "disk-on-segment" else 0.0
    return DiskOnSegment(body, _vector(w, t, "offset", key, 2, [0.0, 0.0]), segment, radius, _law(w, t, key), name)


def _segment_end_contact(w, t, key, name, body_names, segments):
    """A segment's end point on a body's straight edge (body frame, counter-clockwise)."""
    body = _lookup(w, body_names, t.get("body"), f"{key}.body", "body")
    segment = list(segments.values())[_lookup(w, list(segments), t.get("segment"), f"{key}.segment", "segment")]
    end = _text(w, t, "end", key, "b", choices=("a", "b"))
    start, stop = _vector(w, t, "edge_start", key, 2), _vector(w, t, "edge_end", key, 2)
    if start == stop:
        raise w.error(f"{key}.edge_end", f"equals edge_start = {list(start)}: an edge of length 0")
    return SegmentEndOnEdge(body, start, stop, segment, end, _law(w, t, key), name)


def _law(w, t, key) -> ContactLaw:
    law = t.get("law", {})
    key = f"{key}.law"
    _check_keys(w, law, LAW_KEYS, key)
    mu_s = _number(w, law, "mu_s", key, 0.0, nonnegative=True)
    mu_d = _number(w, law, "mu_d", key, mu_s, nonnegative=True)
    e = _number(w, law, "restitution", key, 0.0)
    if mu_d > mu_s:
        raise w.error(f"{key}.mu_d", f"{mu_d:g} exceeds mu_s = {mu_s:g} (sliding friction cannot exceed static)")
    if not 0.0 <= e <= 1.0:
        raise w.error(f"{key}.restitution", f"must lie in [0, 1], got {e:g}")
    return ContactLaw.of(mu_s, mu_d, e)


def _contact(w, t, key, name, kind, body_names, lines):
    law = _law(w, t, key)
    if kind == "disk-on-disk":
        a = _lookup(w, body_names, t.get("body_a"), f"{key}.body_a", "body")
        b = _lookup(w, body_names, t.get("body_b"), f"{key}.body_b", "body")
        if a == b:
            raise w.error(f"{key}.body_b", "a disk-on-disk contact joins two different bodies")
        return DiskOnDisk(a, b, _number(w, t, "radius_a", key, nonnegative=True),
                          _number(w, t, "radius_b", key, nonnegative=True),
                          _vector(w, t, "offset_a", key, 2, [0.0, 0.0]), _vector(w, t, "offset_b", key, 2, [0.0, 0.0]),
                          law, name)
    body = _lookup(w, body_names, t.get("body"), f"{key}.body", "body")
    line = list(lines.values())[_lookup(w, list(lines), t.get("line"), f"{key}.line", "line")]
    radius = _number(w, t, "radius", key, nonnegative=True) if kind == "disk-on-line" else 0.0
    return DiskOnLine(body, _vector(w, t, "offset", key, 2, [0.0, 0.0]), line, radius, law, name)


def _body_rows(w, t, name, key, body_names, required=True) -> dict:
    """A linear relation's or joint's row: a table {body name: [x, y, θ coefficients]} → {index: tuple}."""
    table = t.get(name, _REQUIRED if required else {})
    full = _join(key, name)
    if table is _REQUIRED:
        raise w.error(full, "missing (a table { <body> = [x, y, theta coefficients] } is required)")
    if not isinstance(table, dict):
        raise w.error(full, f"must be a table {{ <body> = [x, y, theta coefficients] }}, got {quoted(table)}")
    return {_lookup(w, body_names, body, f"{full}.{body}", "body"): _vector(w, table, body, full, 3)
            for body in table}


def _linear_contact(w, t, key, name, body_names):
    """A contact with the gap gap0 + Σ normal.<body>·(x, y, θ) and the constant tangent row."""
    from .model.contacts import LinearRelation

    normal, tangent = _body_rows(w, t, "normal", key, body_names), _body_rows(w, t, "tangent", key, body_names, False)
    try:
        return LinearRelation(normal, _number(w, t, "gap0", key), tangent, _law(w, t, key), name,
                              _number(w, t, "tangent_velocity", key, 0.0))
    except InputError as err:
        raise w.error(key, str(err)) from None


def _contacts(w, data, body_names, lines, segments=None) -> list:
    contacts = []
    for name, t in _items(w, data, "contacts"):
        key = f"contacts.{name}"
        kind = _text(w, t, "kind", key, choices=CONTACT_KINDS)
        _check_keys(w, t, CONTACT_KEYS[kind], key)
        if kind.endswith("-on-segment"):
            contacts.append(_segment_contact(w, t, key, name, kind, body_names, segments or {}))
        elif kind == "segment-end-on-edge":
            contacts.append(_segment_end_contact(w, t, key, name, body_names, segments or {}))
        elif kind == "linear":
            contacts.append(_linear_contact(w, t, key, name, body_names))
        else:
            contacts.append(_contact(w, t, key, name, kind, body_names, lines))
    return contacts


# --- applied forces --------------------------------------------------------------------------------

def _force_fields(w, t, key, kind, body_names) -> dict:
    body = _lookup(w, body_names, t.get("body"), f"{key}.body", "body")
    if kind == "torque":
        return {"body": body, "torque": _number(w, t, "torque", key)}
    if kind == "torsion-spring":
        return {"body_a": body, "body_b": _other_body(w, t, key, body, body_names),
                "stiffness": _number(w, t, "stiffness", key, nonnegative=True),
                "rest_angle": math.radians(_number(w, t, "rest_angle_deg", key, 0.0)),
                "damping": _number(w, t, "damping", key, 0.0, nonnegative=True)}
    point = _vector(w, t, "point", key, 2, [0.0, 0.0])
    if kind in ("spring", "damper"):
        other = None if "body_b" not in t else _lookup(w, body_names, t["body_b"], f"{key}.body_b", "body")
        if other == body:
            raise w.error(f"{key}.body_b", "joins a body to itself; leave body_b out to anchor point_b in the world")
        fields = {"body_a": body, "point_a": point, "body_b": other,
                  "point_b": _vector(w, t, "point_b", key, 2, [0.0, 0.0]),
                  "damping": _number(w, t, "damping", key, 0.0, nonnegative=True)}
        if kind == "spring":
            fields.update(stiffness=_number(w, t, "stiffness", key, nonnegative=True),
                          rest_length=_number(w, t, "rest_length", key, 0.0, nonnegative=True))
        return fields
    fields = {"body": body, "point": point}
    if kind == "tabulated":
        return {**fields, **_table_fields(w, t, key)}
    fields.update(force=_vector(w, t, "force", key, 2, [0.0, 0.0]), torque=_number(w, t, "torque", key, 0.0))
    if kind == "ramped":
        fields.update(t_start=_number(w, t, "t_start", key, 0.0), t_full=_number(w, t, "t_full", key))
        if fields["t_full"] <= fields["t_start"]:
            raise w.error(f"{key}.t_full", f"must exceed t_start = {fields['t_start']:g}, got {fields['t_full']:g}")
    return fields


def _other_body(w, t, key, body, body_names, name="body_b"):
    """The second body of a two-body force or joint (None: the world), never the first."""
    if name not in t:
        return None
    other = _lookup(w, body_names, t[name], f"{key}.{name}", "body")
    if other == body:
        raise w.error(f"{key}.{name}", "joins a body to itself; leave it out to join the body to the world")
    return other


def _table_fields(w, t, key) -> dict:
    times = t.get("times")
    if not isinstance(times, list) or len(times) < 1:
        raise w.error(f"{key}.times", f"must be a list of times, got {quoted(times)}")
    n = len(times)
    times = _vector(w, t, "times", key, n)
    if any(b <= a for a, b in itertools.pairwise(times)):
        raise w.error(f"{key}.times", "must increase strictly")
    rows = t.get("forces")
    if not isinstance(rows, list) or len(rows) != n:
        raise w.error(f"{key}.forces", f"must be a list of {n} [fx, fy] pairs, one per time")
    forces = _pairs(w, rows, f"{key}.forces")
    torques = _vector(w, t, "torques", key, n) if "torques" in t else None
    return {"times": times, "forces": forces, "torques": torques}


def _pairs(w, rows: list, key: str) -> np.ndarray:
    """[[fx, fy], ...] as an (n, 2) float array, in linear time (one conversion for a clean
    table; row by row, naming the first bad row, otherwise)."""
    number = (float, int)
    if all(type(r) is list and len(r) == 2 and type(r[0]) in number and type(r[1]) in number for r in rows):
        array = np.array(rows, dtype=float)
        if np.all(np.isfinite(array)):
            return array
    return np.array([_vector(w, {f"[{i}]": r}, f"[{i}]", key, 2) for i, r in enumerate(rows)], dtype=float)


def _forces(w, data, body_names) -> list:
    forces = []
    for name, t in _items(w, data, "forces"):
        key = f"forces.{name}"
        kind = _text(w, t, "kind", key, choices=FORCE_KINDS)
        _check_keys(w, t, FORCE_KEYS[kind], key)
        fields = _force_fields(w, t, key, kind, body_names)
        try:
            forces.append(build_force(kind, name=name, **fields))
        except InputError as err:
            raise w.error(key, str(err)) from None
    return forces


# --- joints ------------------------------------------------------------------------------------------

def _linear_joint(w, t, key, name, body_names):
    """constant + Σ row.<body>·(x, y, θ) = 0."""
    from .model.joints import LinearJoint

    try:
        return LinearJoint(_body_rows(w, t, "row", key, body_names), _number(w, t, "constant", key, 0.0), name)
    except InputError as err:
        raise w.error(key, str(err)) from None


def _joints(w, data, body_names) -> list:
    from .model.joints import Pin, Slider

    joints = []
    for name, t in _items(w, data, "joints"):
        key = f"joints.{name}"
        kind = _text(w, t, "kind", key, choices=JOINT_KINDS)
        _check_keys(w, t, JOINT_KEYS[kind], key)
        if kind == "linear":
            joints.append(_linear_joint(w, t, key, name, body_names))
            continue
        body = _lookup(w, body_names, t.get("body_a"), f"{key}.body_a", "body")
        ends = {"body_a": body, "point_a": _vector(w, t, "point_a", key, 2, [0.0, 0.0]),
                "body_b": _other_body(w, t, key, body, body_names),
                "point_b": _vector(w, t, "point_b", key, 2, [0.0, 0.0])}
        if kind == "pin":
            joints.append(Pin(**ends, name=name))
            continue
        axis = _vector(w, t, "axis", key, 2)
        if not math.hypot(*axis) > 0.0:
            raise w.error(f"{key}.axis", f"must be a non-zero direction, got {list(axis)}")
        joints.append(Slider(**ends, axis=axis, angle=math.radians(_number(w, t, "angle_deg", key, 0.0)), name=name))
    return joints


def _check_joints_hold(w, scene, q0) -> None:
    """Every joint holds at the initial state (to the overlap tolerance): the run keeps it there."""
    from .model.joints import ROWS_PER_JOINT, joint_violation

    if not scene.joints:
        return
    violation = joint_violation(scene.joints, len(scene.bodies), q0)
    tol = OVERLAP_TOLERANCE * max(1.0, float(np.max(np.abs(q0))))
    for i, joint in enumerate(scene.joints):
        worst = float(np.max(np.abs(violation[ROWS_PER_JOINT * i: ROWS_PER_JOINT * (i + 1)])))
        if not worst <= tol:
            raise w.error("initial", f"joint {joint.name!r} does not hold at the initial state (off by {worst:.6g}, "
                                     f"tolerance {tol:.3g}): place its points together")


# --- initial state, overlap -----------------------------------------------------------------------

def _initial(w, data, body_names) -> tuple[np.ndarray, np.ndarray]:
    init = data.get("initial", _REQUIRED)
    if init is _REQUIRED:
        raise w.error("initial", "missing: give [initial.<body>] q = [x, y, theta] for every body")
    _check_keys(w, init, body_names, "initial")
    q0, v0 = np.zeros(3 * len(body_names)), np.zeros(3 * len(body_names))
    for i, name in enumerate(body_names):
        key = f"initial.{name}"
        if name not in init:
            raise w.error(key, "missing: every body needs its initial q = [x, y, theta (rad)]")
        _check_keys(w, init[name], ("q", "v"), key)
        q0[3 * i:3 * i + 3] = _vector(w, init[name], "q", key, 3)
        v0[3 * i:3 * i + 3] = _vector(w, init[name], "v", key, 3, [0.0, 0.0, 0.0])
        for part, values in (("q", q0[3 * i:3 * i + 3]), ("v", v0[3 * i:3 * i + 3])):
            if np.max(np.abs(values)) > MAX_STATE:
                raise w.error(f"{key}.{part}", f"must lie within ±{MAX_STATE:g}, got {quoted(values.tolist())}")
    return q0, v0


def _scene_size(scene) -> float:
    """A length for the overlap tolerance: the largest contact lever arm, at least 1 m."""
    sizes = [1.0]
    for c in scene.contacts:
        for off, r in ((getattr(c, "offset", (0, 0)), getattr(c, "radius", 0.0)),
                       (getattr(c, "offset_a", (0, 0)), getattr(c, "radius_a", 0.0)),
                       (getattr(c, "offset_b", (0, 0)), getattr(c, "radius_b", 0.0))):
            sizes.append(math.hypot(*off) + r)
    return max(sizes)


def _check_overlap(w, scene, q0, v0) -> None:
    tol = OVERLAP_TOLERANCE * _scene_size(scene)
    for c in scene.contacts:
        try:
            with np.errstate(all="ignore"):
                kin = c.kinematics(q0, v0, scene.n_dof)
        except InputError as err:
            raise w.error(f"contacts.{c.name}", f"at the initial state: {err}") from None
        gap = kin.gap
        if gap == math.inf:  # found shapes' features that are not the touching pair
            continue
        if not all(math.isfinite(x) for x in (gap, kin.drift_N, kin.drift_T)):
            raise w.error("initial", f"contact {c.name!r}: the initial state overflows its kinematics "
                                     "(positions or velocities far too large)")
        if gap < -tol:
            raise w.error("initial", f"contact {c.name!r} starts overlapping by {-gap:.6g} m "
                                     f"(tolerance {tol:.3g} m): move the bodies apart")


# --- simulation settings ----------------------------------------------------------------------------

def _options_class(method: str):
    from .integrators import integrator_classes

    return integrator_classes(method)[1]


def _simulation(w, data, contact_names) -> tuple[str, float, dict, list, float | None]:
    sim = data.get("simulation", _REQUIRED)
    if sim is _REQUIRED:
        raise w.error("simulation", "missing: give [simulation] with at least t_end")
    if not isinstance(sim, dict):
        raise w.error("simulation", f"must be a table, got {quoted(sim)}")
    method = _text(w, sim, "method", "simulation", "moreau-jean", METHODS)
    t_end = _number(w, sim, "t_end", "simulation", positive=True)
    save_every = _number(w, sim, "save_every", "simulation", positive=True) if "save_every" in sim else None
    stop = _stop(w, sim, contact_names)
    options = _method_options(w, sim, method)
    _check_options(w, _options_class(method), options, stop)
    _check_other_methods(w, sim, method)
    return method, t_end, options, stop, save_every


def _check_other_methods(w, sim: dict, method: str) -> None:
    """The values of the other methods' tables too: a file whose [simulation.event-driven] holds
    rtol = -1 is wrong whichever method runs it now (`--set simulation.method=…` switches later)."""
    flat = _flat_options(sim)
    for name in METHODS:
        if name == method or not isinstance(sim.get(name), dict):
            continue
        allowed = _allowed_options(name)
        _refuse_non_finite(w, f"simulation.{name}", sim[name])
        table = {**{k: v for k, v in flat.items() if k in allowed}, **sim[name]}
        _check_options(w, _options_class(name), table, [], where=f"simulation.{name}")


def _flat_options(sim: dict) -> dict:
    """The method options given directly in [simulation] (not in a method's own table)."""
    return {k: v for k, v in sim.items() if k not in ("method", "t_end", "stop", "save_every") and k not in METHODS}


def _refuse_non_finite(w, prefix: str, table: dict) -> None:
    for key, value in table.items():
        if isinstance(value, float) and not math.isfinite(value):
            raise w.error(f"{prefix}.{key}", f"must be finite, got {quoted(value)}")


def _stop(w, sim: dict, contact_names) -> list:
    stop = sim.get("stop", [])
    stop = [stop] if isinstance(stop, str) else stop
    if not isinstance(stop, list):
        raise w.error("simulation.stop", f"must be a contact name, got {quoted(stop)}")
    if len(stop) > 1:
        raise w.error("simulation.stop", f"one contact at a time (the first impact of it ends the run), got {quoted(stop)}")
    for s in stop:
        _lookup(w, contact_names, s, "simulation.stop", "contact")
    return stop


def _allowed_options(method: str) -> list:
    return [f.name for f in dataclasses.fields(_options_class(method)) if f.name != "stop_at_impact"]


def _method_options(w, sim: dict, method: str) -> dict:
    """Options of the chosen method: [simulation.<method>] over the flat keys of [simulation].
    The other methods' tables are checked too (_check_other_methods), so that
    `--set simulation.method=event-driven` switches to options the file already holds."""
    flat = _flat_options(sim)
    _check_keys(w, flat, _allowed_options(method) + list(METHODS), "simulation")
    for name in METHODS:
        if name in sim:
            _check_keys(w, sim[name], _allowed_options(name), f"simulation.{name}")
    own = sim.get(method, {})
    _refuse_non_finite(w, "simulation", flat)
    _refuse_non_finite(w, f"simulation.{method}", own)
    for key in own:
        if key in flat:
            raise w.error(f"simulation.{key}", f"given twice: also as simulation.{method}.{key}; keep one")
    return {**flat, **own}


def _check_options(w, cls, options: dict, stop: list, where: str = "simulation") -> None:
    """Build the method's options once so a bad value is refused here, naming the key."""
    try:
        cls(**options, stop_at_impact=stop[0] if stop else None)
    except InputError as err:
        raise w.error(where, str(err)) from None
    except (TypeError, ValueError) as err:
        raise w.error(where, f"bad option value: {err}") from None


# --- overrides: --set contacts.floor.law.mu_s=0.3 ------------------------------------------------

def _parse_value(text: str):
    """A TOML value (number, bool, string, list); bare words are strings."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def apply_override(data: dict, assignment: str, source: str = "--set") -> None:
    """Set `path=value` in the file's data; arrays of tables are entered by name."""
    if "=" not in assignment:
        raise InputError(f"{source} {quoted(assignment)}: expected PATH=VALUE, e.g. contacts.floor.law.mu_s=0.3")
    path, text = assignment.split("=", 1)
    keys = path.strip().split(".")
    if not all(keys):
        raise InputError(f"{source} {quoted(assignment)}: empty key in the path {quoted(path)}")
    node, walked = data, []
    for k in keys[:-1]:
        walked.append(k)
        if isinstance(node, list):
            match = [t for t in node if isinstance(t, dict) and t.get("name") == k]
            if not match:
                have = ", ".join(str(t.get("name")) for t in node if isinstance(t, dict))
                raise InputError(f"{source} {path}: no entry named {k!r} in {'.'.join(walked[:-1])} (have: {have})")
            node = match[0]
        elif isinstance(node, dict):
            node = node.setdefault(k, {})
        else:
            raise InputError(f"{source} {path}: {'.'.join(walked[:-1])} is a value, not a table")
    if not isinstance(node, dict):
        raise InputError(f"{source} {path}: {'.'.join(keys[:-1])} is not a table")
    node[keys[-1]] = _parse_value(text.strip())


# --- reading a file ---------------------------------------------------------------------------------

def read_data(path, what: str = "scene") -> tuple[dict, str]:
    """The file's content as a dict (TOML, or JSON by the .json suffix) and its text; `what` the
    file holds (a scene, measured events) names it in the one-line errors."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise InputError(f"{path}: cannot read the {what} file ({getattr(err, 'strerror', None) or err})") from None
    kind = "JSON" if path.suffix.lower() == ".json" else "TOML"
    try:
        data = json.loads(text) if kind == "JSON" else tomllib.loads(text)
    except RecursionError:
        raise InputError(f"{path}: not a {what} file: tables or lists nested too deep to read") from None
    except ValueError as err:  # JSONDecodeError, TOMLDecodeError, an integer over Python's digit limit
        raise InputError(f"{path}: not valid {kind}: {str(err)[:200]}") from None
    if not isinstance(data, dict):
        raise InputError(f"{path}: the {what} must be a table/object at the top level")
    return data, text


def load_scene(path, overrides=()) -> SceneFile:
    """Read, override and check a scene file (InputError naming file and key on any mistake)."""
    data, text = read_data(path)
    for assignment in overrides:
        apply_override(data, assignment)
    sf = parse_scene(data, source=str(path))
    sf.text, sf.overrides = text, list(overrides)
    return sf


def _check_tree(w, data) -> None:
    """Bound the file's shape before reading it: nesting at most MAX_DEPTH deep, integers a
    float can hold, and only numbers, strings, booleans, lists and tables (TOML dates and times
    have no place in a scene, and no JSON form for the summary). Iterative (no recursion limit)
    and linear; a key is spelled out only for the error."""
    pending = [(data, (), 0)]
    while pending:
        node, path, depth = pending.pop()
        if depth >= MAX_DEPTH:
            raise w.error(_dotted(path), f"nested more than {MAX_DEPTH} levels deep")
        items = node.items() if isinstance(node, dict) else enumerate(node)
        for k, v in items:
            kind = type(v)
            if kind is float or kind is str or kind is bool:
                continue
            if kind is int:
                if abs(v) > MAX_INTEGER:
                    raise w.error(_dotted(path + (k,)), f"integer too large (beyond ±2^63): {quoted(v)}")
            elif kind is list and depth + 1 < MAX_DEPTH and all(type(x) is float for x in v):
                continue  # a row of a table: nothing to look into
            elif isinstance(v, (dict, list)):
                pending.append((v, path + (k,), depth + 1))
            elif v is not None:
                raise w.error(_dotted(path + (k,)), f"must be a number, string, list or table, got {quoted(v)}")


def _dotted(path) -> str:
    """The `--set` spelling of a path of keys and list indices: forces.0.times[3] → forces[0].times[3]."""
    text = ""
    for k in path:
        text += f"[{k}]" if isinstance(k, int) else (f".{k}" if text else str(k))
    return text


def _gravity(w, data):
    """`gravity`: a number g ≥ 0 (g downward, −y) or the vector [gx, gy]."""
    if isinstance(data.get("gravity"), list):
        return _vector(w, data, "gravity", "", 2)
    return _number(w, data, "gravity", "", 9.81, nonnegative=True)


def parse_scene(data: dict, source: str = "<scene>") -> SceneFile:
    """The SceneFile of a scene's content (a dict as read from TOML or JSON)."""
    w = _Where(source)
    _check_keys(w, data, TOP_KEYS, "")
    _check_tree(w, data)
    schema = data.get("schema")
    if schema != SCHEMA:
        raise w.error("schema", f"must be {SCHEMA!r} (this version reads that schema), got {quoted(schema)}")
    for key in ("title", "description"):
        _text(w, data, key, "", "")
    gravity = _gravity(w, data)
    bodies, body_names, shapes = _bodies(w, data)
    lines, segments = _lines(w, data), _segments(w, data)
    contacts = _contacts(w, data, body_names, lines, segments)
    contacts += scene_collisions.found_contacts(w, data, bodies, shapes, lines, segments, contacts)
    forces = _forces(w, data, body_names)
    driven = _driven_bodies(w, data, body_names)
    joints = _joints(w, data, body_names)
    try:
        with np.errstate(all="ignore"):
            scene = make_scene(bodies, contacts, gravity, forces, driven, joints)
    except InputError as err:
        raise w.error("", str(err)) from None
    if not np.all(np.isfinite(scene.weight)):
        raise w.error("gravity", "the weight m g of a body overflows: masses or gravity far too large")
    q0, v0 = _initial(w, data, body_names)
    _check_overlap(w, scene, q0, v0)
    _check_joints_hold(w, scene, q0)
    contact_names = [c.name for c in contacts]
    method, t_end, options, stop, save_every = _simulation(w, data, contact_names)
    return SceneFile(scene, q0, v0, t_end, method, options, stop, body_names, contact_names, list(lines),
                     [f.name for f in forces], shapes, lines, data, source,
                     title=str(data.get("title", "")), segments=segments, save_every=save_every,
                     joint_names=[j.name for j in joints])


# --- running ----------------------------------------------------------------------------------------

def run_method(scene, q0, v0, t_end: float, method: str, options: dict, stop=(), t0: float = 0.0,
               save_every: float | None = None):
    """The one place that runs a scene file's scene: nr.simulate."""
    from .driver import simulate

    return simulate(scene, q0, v0, t_end, method, t0=t0, stop=list(stop) or None, save_every=save_every,
                    **options)


def simulate_scene(sf: SceneFile):
    """Run a loaded scene file with its own method, options and stop conditions; a refusal by the
    driver (a method that does not handle a contact kind, a run too large for memory) names the file."""
    try:
        result = run_method(sf.scene, sf.q0, sf.v0, sf.t_end, sf.method, sf.options, sf.stop,
                            save_every=sf.save_every)
    except InputError as err:
        raise InputError(f"{sf.source}: simulation: {err}") from None
    result.scene_file = sf  # names and shapes for files, figures and animations
    return result
