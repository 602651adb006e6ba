"""What a run keeps and where it stops, decided while it runs: one rule for every method.

The samples kept: the run's first, then the first sample of each `save_every` slot (slots of
the time since the run's start), and its last. Stop conditions — callables (t, q, v) -> bool —
are tried at each kept sample, in order; the run ends at the first where one holds, with status
"stopped" and a "stop" event there. Moreau–Jean (its windows, its error-controlled run), the
event-driven reference, the hybrid method and the regularized method all keep and stop by
these, while they run: memory follows what is kept, and a stop early in the run costs that
early part.
"""
from __future__ import annotations

import math

import numpy as np

from ..results import Event

# A sample on a slot's start to round-off counts in that slot (t0 + k·save_every computed).
SLOT_TOL = 1e-9


def save_slots(offsets, save_every: float):
    """The `save_every` slot of each time offset from the run's start."""
    return np.floor(offsets / save_every + SLOT_TOL)


def thinned_count(samples: float, duration: float, save_every: float | None) -> float:
    """How many of `samples` a run of `duration` keeps with `save_every` (the memory estimates)."""
    return samples if save_every is None else min(samples, duration / save_every + 1.0)


# What keeps fewer samples of a method that samples every output_dt (the driver's memory refusal says it).
OUTPUT_DT_KNOB = "a coarser output_dt or a shorter t_end"


def output_dt_samples(options, duration: float, save_every: float | None) -> float:
    """How many samples a run that samples every `options.output_dt` keeps (or one per
    save_every, thinned as it runs): the event-driven reference's and the regularized method's."""
    return thinned_count(duration / options.output_dt, duration, save_every) + 2


def stop_holds(stops, t, q, v) -> bool:
    """Whether any stop condition holds at (t, q, v) (each sees copies: none can change the run)."""
    return any(bool(cond(float(t), q.copy(), v.copy())) for cond in stops)


def first_hold(stops, ts, qs, vs) -> int | None:
    """The index of the first sample (ts[k], qs[k], vs[k]) where a stop condition holds, or None.
    qs, vs: the caller's copies (a condition may write into its rows: not the run's state), so
    that a sample costs a condition's call and nothing more (a compiled step can cost less)."""
    if not stops:
        return None
    times = [float(t) for t in ts]
    for k in range(len(times)):
        t, q, v = times[k], qs[k], vs[k]
        for cond in stops:
            if cond(t, q, v):
                return k
    return None


def stop_message(t: float) -> str:
    return f"a stop condition held at t = {t:.9g} s"


def stop_event(t: float) -> Event:
    return Event(float(t), "stop", "", {})


class Thinning:
    """The kept samples and the stops of one run, fed its samples in time order as it goes.

    `keeps(ts)` marks which of the next samples are kept (the first of the run and the first of
    each slot); the caller keeps the last sample it did not keep (`kept[-1]` False) in case the
    run ends there. `first_stop(ts, qs, vs)` is the index of the first kept sample where a stop
    condition holds, or None.
    """

    def __init__(self, t0: float, save_every: float | None, stops=()):
        self.t0, self.save_every, self.stops = float(t0), save_every, list(stops)
        self._slot = math.nan  # the slot of the last sample offered (none yet)

    def keeps(self, ts) -> np.ndarray:
        ts = np.atleast_1d(np.asarray(ts, dtype=float))
        if self.save_every is None:
            keep = np.ones(ts.shape, dtype=bool)
            if ts.size:
                self._slot = 0.0
            return keep
        slots = save_slots(ts - self.t0, self.save_every)
        keep = slots != np.r_[self._slot, slots[:-1]]
        if ts.size:
            self._slot = float(slots[-1])
        return keep

    def first_stop(self, ts, qs, vs) -> int | None:
        """`first_hold` with this run's stop conditions (qs, vs: the caller's copies)."""
        return first_hold(self.stops, ts, qs, vs)


def grid_blocks(t0: float, dt: float, a: float, b: float, block: int = 1 << 14):
    """The sample times t0 + k·dt in [a, b), in blocks of at most `block` (a long step, a long rest,
    is sampled without an array of all its times)."""
    k = max(0, math.ceil((a - t0) / dt) - 1)
    k_end = math.ceil((b - t0) / dt) + 1
    while k < k_end:
        ts = t0 + np.arange(k, min(k + block, k_end)) * dt
        ts = ts[(ts >= a) & (ts < b)]
        if ts.size:
            yield ts
        k += block


__all__ = ["Thinning", "save_slots", "thinned_count", "stop_holds", "first_hold", "stop_message", "stop_event", "grid_blocks",
           "SLOT_TOL"]
