"""A scene's packed arrays, kept for the runs that repeat the scene.

A study's points, a fit's evaluations and a benchmark's repeats run one scene many times, and
packing it (model/packing.py) with the loop's model tuple costs more than a short run's steps
(docs/performance.md, "The fixed cost of a call"). `scene_plan(scene)` packs a scene once and
hands the same plan back while nothing the packing read has changed:

* the scene's lists (contacts, forces, joints, driven bodies) hold the same objects, its
  `applied_force` is the same object, and its mass and weight arrays the same numbers (bit for bit);
* no relation's field has been set since (`model.contacts.relation_changes`: the relations are
  mutable dataclasses; any assignment to any relation re-packs every scene — coarse, never stale);
* the scene holds nothing that can change in place: its forces, joints, laws and obstacles are
  frozen dataclasses of numbers and tuples. A scene with something mutable in them (a
  LinearRelation's or a LinearJoint's dict rows) or with driven obstacles or bodies (the loop
  writes their rows while it runs) is packed again for every run, as before.

The per-run arrays a plan lends (a short run's `Work` and window `Records`, lent as one set; a few
sets, each small) go to one run at a time and come back zeroed; nothing a result keeps points into them.
Plans and what they lend are per process: a study's workers each pack their scene once.
"""
from __future__ import annotations

import dataclasses
import weakref

import numpy as np

from ..model.contacts import relation_changes
from ..model.joints import pack_joints
from ..model.motion import Prescribed
from ..model.packing import pack_scene
from .carved import owners

# Scenes kept (the earliest packed first out when full) and the largest kept: beyond it
# packing is a small part of any run, and the arrays are not worth keeping.
MAX_PLANS = 8
MAX_PLAN_CONTACTS = 4096
# Sets of per-run arrays a plan lends (a run's Work and window records, for windows of a few lengths).
MAX_SPARES = 4
SETS_PER_KEY = 2  # sets lent a key: the last result can keep its arrays while the next run takes the other
_PLANS: dict = {}  # id(scene) → (scene, fingerprint, what the fingerprint's ids name, plan, checked)
_IMMUTABLE = (float, int, str, bool, type(None))


class ScenePlan:
    """What every Moreau–Jean run of a scene reads before its steps: the packed scene, the joint
    table, the contact names, whether its forces change with time alone, its Python motions; the
    model tuple once built (`model`, only for a scene without driven motions), and per-run arrays
    lent to one run at a time (`borrow`, `give_back`)."""

    __slots__ = ("packed", "joints", "names", "kinds", "varies_in_time", "python_motions", "static", "model",
                 "_spares", "_owners", "parameters", "predicted", "predictors")

    def __init__(self, scene):
        self.packed = pack_scene(scene)
        self.joints = pack_joints(scene.joints, len(scene.bodies))
        self.names = tuple(c.name for c in scene.contacts)
        self.kinds = frozenset(type(c).__name__ for c in scene.contacts)  # its contacts' relation classes
        self.varies_in_time = scene.forces_vary_in_time()
        motions = self.packed.motions  # all of them when one is a Python (Prescribed) one: each step evaluates them
        self.python_motions = motions if any(isinstance(m, Prescribed) for m in motions) else []
        self.static = not scene.driven_things()  # the loop writes nothing of its packed arrays
        self.model = None
        self._spares: dict = {}  # key → [(arrays, the buffers they are carved from, their result's weakref)]
        self._owners: dict = {}  # id(arrays) → (arrays, their buffers, their bytes)
        self.parameters = None  # (options, t0, t_end, grid, params, iparams, slip default) of the last run (moreau_jean._run_parameters)
        self.predicted = None  # whether the hybrid method runs the scene (stick_decisions), at its first prediction
        # the stick decisions' predicting Hybrids (their compiled mode solves set up), one to a run at a time
        self.predictors: list = []

    def borrow(self, key):
        """A set of arrays lent under `key` by an earlier run, zeroed, or None (none lent, or other
        runs hold them: each set goes to one run at a time). Of the SETS_PER_KEY sets, one whose
        result is gone or has its end state is taken first; else the earliest, once its result has
        copied its end state out of it."""
        sets = self._spares.get(key)
        if not sets:
            return None
        for i, (_, _, holder) in enumerate(sets):
            result = None if holder is None else holder()
            if result is None or not result.end_state_pending():
                break
        else:  # every set still read by a result: a new set while there are fewer than SETS_PER_KEY
            if len(sets) < SETS_PER_KEY:
                return None
            i = 0
        arrays, buffers, holder = sets.pop(i)
        result = None if holder is None else holder()
        if result is not None:
            result.settle_end_state()
        for buffer in buffers:  # one fill a buffer the arrays are carved from (integrators/carved.py)
            buffer.fill(0)
        return arrays

    def give_back(self, key, arrays, max_bytes: float = float("inf"), holder=None) -> bool:
        """Lend `arrays` (a set: sequences of arrays, the loop's tuples) to the next run that asks
        for `key` (SETS_PER_KEY sets a key, MAX_SPARES keys), when they hold at most `max_bytes`;
        True if lent. `holder`: the result whose end state is built from them on first read
        (settled before they are lent again, if it is alive): two sets a key, so that a loop that
        keeps each result until the next call returns never has one copied. A set too large is
        not remembered either (a long run's window is not kept alive by the plan)."""
        known = self._owners.get(id(arrays))
        if known is None or known[0] is not arrays:  # the same sets come back run after run
            buffers = owners([a for part in arrays for a in part])
            known = (arrays, buffers, sum(b.nbytes for b in buffers))
            if known[2] > max_bytes:
                return False
            if len(self._owners) >= SETS_PER_KEY * MAX_SPARES:
                self._owners.clear()
            self._owners[id(arrays)] = known
        if known[2] > max_bytes:
            return False
        if key not in self._spares and len(self._spares) >= MAX_SPARES:
            try:  # the earliest lent out
                self._spares.pop(next(iter(self._spares)), None)
            except (RuntimeError, StopIteration):
                return False
        sets = self._spares.setdefault(key, [])
        if len(sets) >= SETS_PER_KEY:
            sets.pop(0)  # not lent again: its result, if any, keeps it
        sets.append((arrays, known[1], None if holder is None else weakref.ref(holder)))
        return True


def _fingerprint(scene):
    """What the packing read, cheaply: ids of the scene's items (kept alive by the entry, so an id
    cannot name another object later), the relations' change count, the mass and weight bits."""
    return (relation_changes(), len(scene.bodies), tuple(map(id, scene.contacts)), tuple(map(id, scene.forces)),
            tuple(map(id, scene.joints)), tuple(map(id, scene.driven)), id(scene.applied_force),
            scene.inverse_mass_diagonal.tobytes(), scene.weight.tobytes())


def _immutable(value) -> bool:
    """A number, a string, None, or tuples and frozen dataclasses of these (nothing that can
    change in place)."""
    if isinstance(value, _IMMUTABLE):
        return True
    if isinstance(value, tuple):
        return all(_immutable(v) for v in value)
    params = getattr(type(value), "__dataclass_params__", None)
    if params is not None and params.frozen:
        return all(_immutable(getattr(value, f.name)) for f in dataclasses.fields(value))
    return False


def _keepable(scene, plan: ScenePlan) -> bool:
    """Whether a plan of this scene may be kept: no driven motion, few enough contacts, and
    nothing in its relations, forces and joints that can change in place."""
    if not plan.static or len(scene.contacts) > MAX_PLAN_CONTACTS:
        return False
    return (all(_immutable(v) for c in scene.contacts for v in vars(c).values())
            and all(_immutable(item) for item in (*scene.forces, *scene.joints)))


def scene_plan(scene) -> ScenePlan:
    """The scene's plan: kept from an earlier run while nothing it was built from changed
    (`_fingerprint`), else built now. A new scene's plan is kept on trust and checked
    (`_keepable`) when the scene comes again: a study's points are each run once, and a check
    they never use would cost them more than it saves the scenes that repeat."""
    key = id(scene)
    entry = _PLANS.get(key)
    fingerprint = _fingerprint(scene)
    if entry is not None and entry[0] is scene and entry[1] == fingerprint:
        if entry[4] or _keepable(scene, entry[3]):
            if not entry[4]:
                _PLANS[key] = entry[:4] + (True,)
            return entry[3]
    plan = ScenePlan(scene)
    _PLANS.pop(key, None)
    if plan.static and len(scene.contacts) <= MAX_PLAN_CONTACTS:
        plan.packed.weight = np.array(plan.packed.weight)  # its own: not the scene's array, changed in place later
        if len(_PLANS) >= MAX_PLANS:
            try:  # the oldest out (another thread may be changing the table meanwhile)
                _PLANS.pop(next(iter(_PLANS)), None)
            except (RuntimeError, StopIteration):
                pass
        kept = (tuple(scene.contacts), tuple(scene.forces), tuple(scene.joints), tuple(scene.driven),
                scene.applied_force)
        _PLANS[key] = (scene, fingerprint, kept, plan, False)  # checked (`_keepable`) when it comes again
    return plan


def forget_plans() -> None:
    """Drop every kept plan (tests; memory)."""
    _PLANS.clear()


__all__ = ["ScenePlan", "scene_plan", "forget_plans", "MAX_PLANS", "MAX_PLAN_CONTACTS"]
