"""A map's fast path: the scene file parsed once, each point's values patched into it.

A map runs one scene at many points that differ only in the swept keys; parsing the whole file
again at every point cost a quarter of a point's time (the ladder: 0.5 of 2.2 ms). `PointScenes`
parses the base scene once (per worker: `point_scenes` keeps the last one); at a point it copies
only the sections its paths touch and parses those again with scenefile's own functions into a
copy of the base SceneFile:

* a contact's law (`contacts.NAME.law.mu_s`, `mu_d`, `restitution`; `*` for every contact):
  the law table of each contact a path names, copied and patched, is read again (`_law`: the
  same defaults — μd = μs when the file leaves it out — and checks) into a copy of its relation,
  kept by its law table for the points that repeat it (the values along one axis repeat at every
  value of the others);
* the initial state (`initial.*`): `_initial`, then the overlap and joint checks on it;
* the run's settings (`simulation.*`: t_end, h, ...): `_simulation`.

Any other path (a body's mass, a line's angle: they reach the mass matrix, the geometry, the
contacts found between shapes) takes the full parse, and so does a point whose patched values
are refused, so that a refusal says what the full parse says. Both give the same SceneFile
values, hence the same run bit for bit (tests/studies/test_patching.py).
"""
from __future__ import annotations

import copy
import dataclasses

from ..scenefile import _check_joints_hold, _check_overlap, _initial, _law, _simulation, _Where, parse_scene
from ..validation import InputError
from .paths import _slots, set_value, with_values

PATCHED_LAW_KEYS = ("mu_s", "mu_d", "restitution")
PATCHED_SECTIONS = ("contacts", "initial", "simulation")  # the order parse_scene reads them in


def patchable(path: str) -> bool:
    """True when a point's value at `path` can be patched into the parsed base scene."""
    keys = path.split(".")
    if keys[0] == "contacts":
        return len(keys) == 4 and keys[2] == "law" and keys[3] in PATCHED_LAW_KEYS
    return keys[0] in ("initial", "simulation")


class PointScenes:
    """The SceneFile of each point of a map over `paths` (axis keys, 'a,b' for two moving
    together) of the scene `data` (already checked: the base parses); `fast=False` parses every
    point in full."""

    def __init__(self, data: dict, source: str, paths, fast: bool = True):
        self.data, self.source, self.paths = data, source, tuple(paths)
        single = [p.strip() for key in self.paths for p in key.split(",")]
        sections = {p.split(".")[0] for p in single}
        self.fast = bool(fast) and all(map(patchable, single)) and all(isinstance(data.get(s), (dict, list))
                                                                        for s in sections)
        self.sections = [s for s in PATCHED_SECTIONS if s in sections and s != "contacts"]
        try:
            self.law_slots = _law_slots(data, [p for p in single if p.startswith("contacts.")]) if self.fast else {}
        except InputError:  # a path the full parse refuses, point by point
            self.fast, self.law_slots = False, {}
        self.base = parse_scene(data, source) if self.fast else None
        self._relations: dict = {}  # (contact, its law table) -> the relation with that law

    def scene_file(self, values: dict):
        """The scene at a point ({axis key: value}); an InputError (from the full parse) if the
        scene refuses it."""
        if self.fast:
            try:
                return self._patched(values)
            except InputError:
                pass  # refused: the full parse below says why, in its own words
        return parse_scene(with_values(self.data, values), self.source)

    def _patched(self, values: dict):
        data = dict(self.data)  # the sections a path touches copied; the rest shared with the base
        for section in self.sections:
            data[section] = copy.deepcopy(self.data[section])
        laws = {i: dict(self.data["contacts"][i]["law"]) for i in {i for s in self.law_slots.values() for i, _ in s}}
        for keys, value in values.items():
            for path in keys.split(","):
                path = path.strip()
                if path in self.law_slots:
                    for i, key in self.law_slots[path]:
                        laws[i][key] = float(value)
                else:
                    set_value(data, path, value)
        base, w = self.base, _Where(self.source)
        changes = {"data": data}
        if laws:
            changes["scene"] = self._with_laws(w, data, laws)
        if "initial" in self.sections:
            scene = changes.get("scene", base.scene)
            q0, v0 = _initial(w, data, base.body_names)
            _check_overlap(w, scene, q0, v0)
            _check_joints_hold(w, scene, q0)
            changes.update(q0=q0, v0=v0)
        if "simulation" in self.sections:
            method, t_end, options, stop, save_every = _simulation(w, data, base.contact_names)
            changes.update(method=method, t_end=t_end, options=options, stop=stop, save_every=save_every)
        return dataclasses.replace(base, **changes)

    def _with_laws(self, w, data: dict, laws: dict):
        """A copy of the base scene whose declared contacts i carry the law tables laws[i] (read
        by scenefile's `_law`: its defaults and checks); `data` gets those tables too."""
        scene, tables = copy.copy(self.base.scene), list(data["contacts"])
        scene.contacts = list(scene.contacts)
        for i, law_table in laws.items():
            tables[i] = {**tables[i], "law": law_table}
            key = (i, tuple((k, type(v), repr(v)) for k, v in law_table.items()))  # -0.0 is not 0.0
            relation = self._relations.get(key)
            if relation is None:
                relation = copy.copy(scene.contacts[i])
                relation.law = _law(w, tables[i], f"contacts.{tables[i]['name']}")
                if len(self._relations) >= MAX_RELATIONS:
                    self._relations.clear()
                self._relations[key] = relation
            scene.contacts[i] = relation  # runs never change a relation: points may share it
        data["contacts"] = tables
        return scene


MAX_RELATIONS = 4096  # relations kept by law (a map's axis values repeat along the other axes)


def _law_slots(data: dict, paths) -> dict:
    """{path: [(declared contact index, law key)]} of contact-law paths (`*` names several)."""
    tables = data.get("contacts")
    out = {}
    for path in paths:
        slots = []
        for node, key in _slots(data, path):
            where = [i for i, t in enumerate(tables) if isinstance(t, dict) and t.get("law") is node]
            if len(where) != 1:
                raise InputError(f"{path}: not a contact's law")  # (checked before a map starts)
            slots.append((where[0], key))
        out[path] = slots
    return out


_last: list = []  # [PointScenes] of the last map a worker ran points of


def point_scenes(data: dict, source: str, paths) -> PointScenes:
    """The PointScenes of this map, built once per worker process (chunks arrive pickled: the
    same map is recognised by its content, not by identity)."""
    paths = tuple(paths)
    if _last and _last[0].paths == paths and _last[0].source == source and _last[0].data == data:
        return _last[0]
    _last[:] = [PointScenes(data, source, paths)]
    return _last[0]
