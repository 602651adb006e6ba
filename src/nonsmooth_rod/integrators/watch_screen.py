"""The hybrid method's steps and step watch (hybrid._StepWatch) run in one compiled call up to the
first step the watch must look at closely. A prediction of the smooth phase (Hybrid.first_event:
the stick decisions of fixed-step Moreau–Jean, the break-away planning of error-controlled
Moreau–Jean) watches tens of steps in which nothing happens, and the watch's per-step Python (a
step's stages and objects, each indicator's band, parabola and sign tests) was most of its cost:
~15 µs a step, ~0.2 ms of a rod prediction (docs/performance.md "Stick decisions").

The screen makes the watch's own tests — `_Watch._start_band`, `hybrid._parabola_minimum`, the
dip and sign tests of `_StepWatch.first_event_sampled` — on the same numbers with the same
operations in the same order (so the same floats): a step it passes is one the watch passes, and
the first step it flags is handed to the watch itself, with the start bands it would have had
there. A NaN flags its step (the watch then decides, as before).
"""
from __future__ import annotations

from .._jit import jit, jit_inline
from ..model.dynamics import runge_kutta_into

_TINY = 5e-324  # event_driven._TINY (a test checks): a start value counted as just on the safe side


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
    for i in range(n):
        if not runge_kutta_into(table, ints, watched, offsets, minv, free, y if i == 0 else states[i - 1, s],
                                steps[i], a, b, states[i], outs[i]):
            return -1 - i
        t1 = times[i] + c_mid * steps[i]
        flagged = False
        for j in range(k):
            s0 = _banded(times[i], previous[j], t_start, noise[j], exits, j)
            s1 = _banded(t1, sign[j] * outs[i, mid, at + j], t_start, noise[j], exits, j)
            s2 = _banded(times[i + 1], sign[j] * outs[i, s, at + j], t_start, noise[j], exits, j)
            flagged = flagged or _flags(times[i], t1, times[i + 1], s0, s1, s2, dip_fraction)
        if flagged:
            return i
        for j in range(k):
            band_exit[j] = exits[j]
            previous[j] = sign[j] * outs[i, s, at + j]
    return n


@jit
def _banded(t, value, t_start, noise, exits, j):
    """_Watch._start_band on one sample (in time order): counted safe until the indicator first
    leaves its round-off band after the start (that sample's time kept in exits[j])."""
    if t >= exits[j]:
        return value
    if t > t_start and abs(value) > noise:
        exits[j] = t
        return value
    return _TINY if _TINY > value else value


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _flags(t0, t1, t2, s0, s1, s2, dip_fraction) -> bool:
    """Whether _StepWatch.first_event_sampled looks at an indicator's step closely: a sample not
    safe, or a dip (hybrid._parabola_minimum's vertex at most dip_fraction of the smaller end)."""
    if not (s0 > 0.0 and s1 > 0.0 and s2 > 0.0):
        return True
    d01, d12 = (s1 - s0) / (t1 - t0), (s2 - s1) / (t2 - t1)
    curvature = (d12 - d01) / (t2 - t0)
    if not curvature > 0.0:
        return False
    t_v = 0.5 * (t0 + t1) - d01 / (2.0 * curvature)
    if not (t0 < t_v and t_v < t2):
        return False
    vertex = s0 + d01 * (t_v - t0) + curvature * (t_v - t0) * (t_v - t1)
    return vertex <= dip_fraction * (s2 if s2 < s0 else s0)
