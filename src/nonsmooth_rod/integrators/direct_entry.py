"""The compiled loop's entry called without numba's search for its overload, where that is safe.

numba's dispatcher finds the overload of each call from its arguments' types: it fingerprints
every argument, and `run_steps` takes the Model, Work and Records named tuples, ~45 arrays
(measured: a call of no step 6.7 µs through the dispatcher, 3.1 µs through the overload's own
entry point, which only unboxes them — more than 50 steps of a one-contact scene cost). A short
run of a kept scene (integrators/scene_plans.py) passes the same model, and the same lent work
and records, run after run: those are called through the overload their first call used.

Why that is the right overload: after a call, when the dispatcher holds exactly one overload, that
call used it (a call whose types had none compiled one; with two or more, the dispatcher keeps
choosing). An argument's numba type never changes (an array's dtype, dimensions, layout and flags
are fixed; the loop's tuples are never rebuilt in place), and the other arguments are built the
same way every run (Python ints, float64 and int64 vectors). The objects met are held (`_known`), so
an id stands for one object while it is known; the set is small and cleared when full, and only
small ones are held (a long run's records, or a large scene's model, would keep megabytes alive).
"""
from __future__ import annotations

MAX_KNOWN = 32  # objects (models, works, records) known to have the entry's types
MAX_KNOWN_BYTES = 1 << 19  # objects held only up to about this size (twice the records a scene's plan lends)


class DirectEntry:
    """`run_steps(kernels, ...)`: kernels.run_steps(...), through the one compiled overload's
    entry point for arguments an earlier call passed to that overload."""

    __slots__ = ("_state",)

    def __init__(self):
        # (dispatcher, its overload's entry point, {id: object known to have its types}), replaced
        # whole, never changed in place: a thread reads one consistent state
        self._state = (None, None, {})

    def run_steps(self, kernels, k_start, k_end, params, iparams, model, work, out, extra):
        dispatcher = kernels.run_steps
        known_dispatcher, entry, known = self._state
        if (dispatcher is known_dispatcher and known.get(id(model)) is model and known.get(id(work)) is work
                and known.get(id(out)) is out):
            return entry(k_start, k_end, params, iparams, model, work, out, extra)
        status = dispatcher(k_start, k_end, params, iparams, model, work, out, extra)
        self._learn(dispatcher, model, work, out)
        return status

    def _learn(self, dispatcher, model, work, out) -> None:
        """After a call through the dispatcher: know its arguments when it holds one overload."""
        entry = one_overload_entry(dispatcher)
        if entry is None:
            self._state = (None, None, {})
            return
        # their largest arrays: the contacts' table and memory, the records' states and impulses
        if model[2].nbytes + work[2].nbytes + out[0].nbytes + out[2].nbytes > MAX_KNOWN_BYTES:
            return  # a large scene or a long run: the search is a small part of its call
        known_dispatcher, known_entry, known = self._state
        same = known_dispatcher is dispatcher and known_entry is entry and len(known) + 3 <= MAX_KNOWN
        known = dict(known) if same else {}
        for obj in (model, work, out):
            known[id(obj)] = obj
        self._state = (dispatcher, entry, known)


def one_overload_entry(dispatcher):
    """The entry point of `dispatcher`'s one compiled overload (the one every call since used,
    when its arguments are built the same way), or None: none yet, several, or no dispatcher (an
    interpreted twin, or the plain function without numba)."""
    overloads = getattr(dispatcher, "overloads", None)
    if overloads is None or len(overloads) != 1:
        return None
    entry = getattr(next(iter(overloads.values())), "entry_point", None)
    return entry if callable(entry) else None


__all__ = ["DirectEntry", "one_overload_entry"]
