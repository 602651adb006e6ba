"""The step watch's tests on one indicator's samples — its start band, the parabola through three
samples and whether a step is looked at closely — written once for the Python watches
(event_driven._Watch, hybrid._StepWatch) and the compiled screen of a prediction's steps
(watch_screen.py): plain Python when Python calls them, compiled into the screen (_jit.jitable),
so both make the same tests on the same numbers with the same operations (the same floats).
"""
from __future__ import annotations

from .._jit import jitable

TINY = 5e-324  # a start value counted as just on the safe side


@jitable
def start_band(ts, s, t_start, noise, exits, j):
    """Count indicator j's safe values s at times ts (in time order; in place) safe from the
    watch's start until the indicator first leaves its round-off band `noise` after t_start
    (that sample's time kept in exits[j]): an indicator starting at zero is not an event there."""
    for k in range(len(ts)):
        if ts[k] >= exits[j]:
            return
        if ts[k] > t_start and abs(s[k]) > noise:
            exits[j] = ts[k]
            return
        s[k] = TINY if TINY > s[k] else s[k]  # (Python's max(s, TINY), NaN and −0.0 alike)


@jitable
def looked_at(t0, t1, t2, s0, s1, s2, dip_fraction):
    """(looked at, dip, t): whether a step is looked at closely from an indicator's three safe
    samples — a sample not safe (Python's min of the three: a NaN after the first is passed), or a
    dip: the parabola through them has an interior minimum, at t, at most dip_fraction of the
    smaller end. (One call a sample triple: the Python watch calls it for every indicator and step.)"""
    least = s1 if s1 < s0 else s0
    least = s2 if s2 < least else least
    d01, d12 = (s1 - s0) / (t1 - t0), (s2 - s1) / (t2 - t1)
    curvature = (d12 - d01) / (t2 - t0)
    if not curvature > 0.0:
        return not least > 0.0, False, 0.0
    t_v = 0.5 * (t0 + t1) - d01 / (2.0 * curvature)
    if not (t0 < t_v and t_v < t2):
        return not least > 0.0, False, 0.0
    vertex = s0 + d01 * (t_v - t0) + curvature * (t_v - t0) * (t_v - t1)
    dip = vertex <= dip_fraction * (s2 if s2 < s0 else s0)
    return dip or not least > 0.0, dip, t_v
