"""The hybrid method's steps and step watch (hybrid._StepWatch) run in one compiled call up to the
first step the watch must look at closely. A prediction of the smooth phase (Hybrid.first_event:
the stick decisions of fixed-step Moreau–Jean, the break-away planning of error-controlled
Moreau–Jean) watches tens of steps in which nothing happens, and the watch's per-step Python (a
step's stages and objects, each indicator's band, parabola and sign tests) was most of its cost:
~15 µs a step, ~0.2 ms of a rod prediction (docs/performance.md "Stick decisions").

The screen makes the watch's own tests (watch_tests.py: its start band, whether a step is looked
at — a sample not safe, a dip of the parabola through the samples —, the functions the watch
calls, compiled in here) on the same numbers in the
same order (so the same floats): a step it passes is one the watch passes, and the first step it
flags is handed to the watch itself, with the start bands it would have had there. A NaN among a
step's samples flags it too (the watch then decides, as before).
"""
from __future__ import annotations

import numpy as np

from .._jit import jit, jit_inline
from ..model.dynamics import runge_kutta_into
from .watch_tests import looked_at, start_band


@jit
def screened_steps_into(table, ints, watched, offsets, minv, free, y, steps, times, a, b, mid, c_mid, t_start,
                        sign, noise, band_exit, s_start, dip_fraction, states, outs) -> int:
    """Runge–Kutta steps of `steps` from y (ModeSystem.runge_kutta's, states[i] and outs[i] step
    i's), times[i] step i's start, up to the first step the watch's tests flag: its index (the
    number of steps: none flagged), or −1 − i where step i's mode solve declines. band_exit (the
    watch's, in place) as the watch leaves it after the steps before the one returned; s_start:
    the safe values (sign × values) at y; t_start: the watch's start; mid: the stage sampled,
    at times[i] + c_mid steps[i]; the watched values are outs' from 2 n_dof on."""
    n, s, k, at = steps.shape[0], b.shape[0], sign.shape[0], 2 * minv.shape[0]
    previous, exits = s_start.copy(), band_exit.copy()
    ts, samples = np.empty(3), np.empty(3)  # a step's three sample times, an indicator's values there
    for i in range(n):
        if not runge_kutta_into(table, ints, watched, offsets, minv, free, y if i == 0 else states[i - 1, s],
                                steps[i], a, b, states[i], outs[i]):
            return -1 - i
        ts[0], ts[1], ts[2] = times[i], times[i] + c_mid * steps[i], times[i + 1]
        flagged = False
        for j in range(k):
            samples[0], samples[1] = previous[j], sign[j] * outs[i, mid, at + j]
            samples[2] = sign[j] * outs[i, s, at + j]
            start_band(ts, samples, t_start, noise[j], exits, j)
            flagged = flagged or _flags(ts, samples, dip_fraction)
        if flagged:
            return i
        for j in range(k):
            band_exit[j] = exits[j]
            previous[j] = sign[j] * outs[i, s, at + j]
    return n


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _flags(ts, samples, dip_fraction) -> bool:
    """Whether the watch looks at an indicator's step closely (watch_tests.looked_at), or a sample is NaN."""
    s0, s1, s2 = samples[0], samples[1], samples[2]
    return looked_at(ts[0], ts[1], ts[2], s0, s1, s2, dip_fraction)[0] or s0 != s0 or s1 != s1 or s2 != s2
