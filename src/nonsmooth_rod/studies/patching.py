"""A map's fast path: the scene file parsed once, each point's values patched into it.

A map runs one scene at many points that differ only in the swept keys; parsing the whole file
again at every point cost a quarter of a point's time (the ladder: 0.5 of 2.2 ms). `PointScenes`
parses the base scene once (per worker: `point_scenes` keeps the last one); at a point it copies
only the sections its paths touch and parses those again with scenefile's own functions into a
copy of the base SceneFile:

* a contact's law (`contacts.NAME.law.mu_s`, `mu_d`, `restitution`; `*` for every contact):
  every declared contact's law is read again (`_law`: the same defaults — μd = μs when the file
  leaves it out — and checks), a changed one in a copy of its relation;
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

from ..scenefile import (_check_joints_hold, _check_overlap, _initial, _items, _law, _simulation, _Where,
                         parse_scene)
from ..validation import InputError
from .paths import set_value, with_values

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
        self.sections = [s for s in PATCHED_SECTIONS if s in sections]
        self.base = parse_scene(data, source) if self.fast else None

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
        for keys, value in values.items():
            for path in keys.split(","):
                set_value(data, path.strip(), value)
        base, w = self.base, _Where(self.source)
        changes = {"data": data}
        if "contacts" in self.sections:
            changes["scene"] = _with_laws(w, base.scene, data)
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


def _with_laws(w, scene, data):
    """A copy of `scene` whose declared contacts carry the laws `data` gives them (the contacts
    found between shapes come after the declared ones, in parse_scene's order, unchanged)."""
    contacts = list(scene.contacts)
    for i, (name, table) in enumerate(_items(w, data, "contacts")):
        law = _law(w, table, f"contacts.{name}")
        if law != contacts[i].law:
            contacts[i] = copy.copy(contacts[i])
            contacts[i].law = law
    out = copy.copy(scene)
    out.contacts = contacts
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
