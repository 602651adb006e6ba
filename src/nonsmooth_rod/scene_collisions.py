"""Scene files' shapes that collide: polygon bodies, each body's collision shapes, `[[laws]]` by
pair and the contacts found between shapes (model/collision.py) — the part of scenefile.py that
reads them (it passes its `_Where`, which builds the one-line errors).

A body with shape disk, ball, rectangle, polygon or rod-with-balls (two disks) collides with
every other such body, line and segment unless `collide = false`; bodies of one `group` never
collide with each other; a body with `collides_with = [names]` collides with those only. A pair
of shapes between which the file declares any contact by hand is not searched: the declared
contacts say how those two touch (so a scene written before shapes collided keeps its contacts
and its results).
"""
from __future__ import annotations

import math

import numpy as np

from .model.collision import Disk, PairLaws, Polygon, find_contacts
from .model.contacts import Line, Segment
from .model.laws import ContactLaw
from .validation import InputError

LAWS_KEYS = ("between", "mu_s", "mu_d", "restitution")
CENTROID_TOL = 1e-9  # m per metre of the polygon's size: vertices are relative to the centre of mass


def polygon_of(w, t, key) -> Polygon:
    """The body's `vertices` as a convex counter-clockwise Polygon centred on its centre of mass."""
    vertices = t.get("vertices")
    if not isinstance(vertices, list) or not all(isinstance(p, list) and len(p) == 2 and
                                                 all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                     for x in p) for p in vertices):
        raise w.error(f"{key}.vertices", "must be a list of [x, y] points (body frame, counter-clockwise)")
    try:
        polygon = Polygon(tuple(tuple(float(x) for x in p) for p in vertices), name="polygon")
    except InputError as err:
        raise w.error(f"{key}.vertices", str(err).removeprefix("polygon vertices: ")) from None
    pts = np.array(polygon.vertices)
    centroid, _ = _area_moments(pts)
    if np.hypot(*centroid) > CENTROID_TOL * max(1.0, polygon.reach):
        raise w.error(f"{key}.vertices", f"their centroid is ({centroid[0]:.6g}, {centroid[1]:.6g}), not (0, 0): "
                                         "vertices are relative to the body's centre of mass")
    return polygon


def _area_moments(pts: np.ndarray):
    """(centroid, area) of a counter-clockwise polygon."""
    x, y = pts[:, 0], pts[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    cross = x * y1 - x1 * y
    area = cross.sum() / 2
    return np.array([((x + x1) * cross).sum(), ((y + y1) * cross).sum()]) / (6 * area), area


def polygon_area(polygon: Polygon) -> float:
    return float(_area_moments(np.array(polygon.vertices))[1])


def polygon_inertia(mass: float, polygon: Polygon) -> float:
    """A uniform polygon about its centroid (the origin): m/A · Σ cᵢ (xᵢ² + xᵢxᵢ₊₁ + xᵢ₊₁² + (the same
    in y))/12, cᵢ = xᵢyᵢ₊₁ − xᵢ₊₁yᵢ."""
    pts = np.array(polygon.vertices)
    x, y = pts[:, 0], pts[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    cross = x * y1 - x1 * y
    second = (cross * (x * x + x * x1 + x1 * x1 + y * y + y * y1 + y1 * y1)).sum() / 12
    return mass * second / (cross.sum() / 2)


def collision_shapes(shape: dict):
    """The collision shapes of a body's drawing shape (scenefile's `shapes` entry): [] for a
    thin rod or a body without shape."""
    kind = shape.get("shape")
    if kind in ("disk", "ball"):
        return [Disk(shape["radius"])]
    if kind == "rectangle":
        return [Polygon.rectangle(shape["width"], shape["height"])]
    if kind == "polygon":
        return [Polygon(tuple(tuple(p) for p in shape["vertices"]))]
    if kind == "rod-with-balls":
        half, r = shape["length"] / 2, shape["ball_radius"]
        return [Disk(r, (-half, 0.0)), Disk(r, (half, 0.0))]
    return []


def pair_laws(w, data, names) -> PairLaws:
    """The `[[laws]]` entries: between = [a, b] ("*": any), mu_s, mu_d, restitution."""
    entries = data.get("laws", [])
    if not isinstance(entries, list):
        raise w.error("laws", "must be an array of tables ([[laws]])")
    found = []
    for k, t in enumerate(entries):
        key = f"laws[{k}]"
        if not isinstance(t, dict):
            raise w.error(key, "must be a table")
        stray = [x for x in t if x not in LAWS_KEYS]
        if stray:
            raise w.error(f"{key}.{stray[0]}", f"unknown key (allowed: {', '.join(LAWS_KEYS)})")
        between = t.get("between")
        if not (isinstance(between, list) and len(between) == 2 and all(isinstance(x, str) for x in between)):
            raise w.error(f"{key}.between", "must be two names of bodies, lines or segments (\"*\": any)")
        for name in between:
            if name != "*" and name not in names:
                raise w.error(f"{key}.between", f"{name!r} names no body, line or segment")
        found.append((*between, _law(w, t, key)))
    return PairLaws(found)


def _law(w, t, key) -> ContactLaw:
    values = {}
    for name, default in (("mu_s", 0.0), ("mu_d", None), ("restitution", 0.0)):
        x = t.get(name, default)
        if x is not None and (isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x)):
            raise w.error(f"{key}.{name}", f"must be a number, got {x!r}")
        values[name] = x
    try:
        return ContactLaw.of(values["mu_s"], values["mu_d"], values["restitution"])
    except InputError as err:
        raise w.error(key, str(err)) from None


def _declared_pairs(declared, body_names, obstacles) -> list:
    """(name, name) of every pair of shapes a declared contact joins."""
    pairs = []
    for c in declared:
        owners = [body_names[b] for b in c.bodies]
        for attr in ("line", "segment"):
            thing = getattr(c, attr, None)
            owners += [name for name, o in obstacles.items() if o is thing]
        if len(owners) == 2:
            pairs.append(tuple(owners))
    return pairs


def _outside_lists(w, tables, names) -> list:
    """(body, name) of every pair a body's `collides_with` list leaves out."""
    never = []
    for body, t in tables.items():
        listed = t.get("collides_with")
        if listed is None:
            continue
        key = f"bodies.{body}.collides_with"
        if not isinstance(listed, list) or not all(isinstance(x, str) for x in listed):
            raise w.error(key, f"must be a list of names of bodies, lines or segments, got {listed!r}")
        for name in listed:
            if name not in names:
                raise w.error(key, f"{name!r} names no body, line or segment")
        never += [(body, name) for name in names if name != body and name not in listed]
    return never


def found_contacts(w, data, bodies, shapes: dict, lines: dict, segments: dict, declared) -> list:
    """The contacts found between the file's colliding shapes (module docstring)."""
    tables = {t.get("name"): t for t in data.get("bodies", []) if isinstance(t, dict)}
    colliding, groups = {}, {}
    for body in bodies:
        t = tables.get(body.name, {})
        collide = t.get("collide", True)
        if not isinstance(collide, bool):
            raise w.error(f"bodies.{body.name}.collide", f"must be true or false, got {collide!r}")
        group = t.get("group")
        if group is not None:
            if not isinstance(group, str) or not group:
                raise w.error(f"bodies.{body.name}.group", f"must be a name, got {group!r}")
            groups[body.name] = group
        try:
            parts = collision_shapes(shapes.get(body.name) or {})
        except InputError as err:
            raise w.error(f"bodies.{body.name}", f"its shape cannot collide: {err}") from None
        if collide and parts:
            colliding[body.name] = parts
    obstacles: dict = {**lines, **segments}
    names = [b.name for b in bodies] + list(obstacles)
    laws = pair_laws(w, data, names)
    if not colliding:
        return []
    never = _declared_pairs(declared, [b.name for b in bodies], obstacles)
    never += _outside_lists(w, tables, names)
    try:
        return find_contacts(bodies, colliding, obstacles, laws, never=never, groups=groups)
    except InputError as err:
        raise w.error("bodies", str(err)) from None


__all__ = ["polygon_of", "polygon_inertia", "polygon_area", "collision_shapes", "pair_laws", "found_contacts",
           "Line", "Segment"]
