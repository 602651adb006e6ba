"""The step watch's tests on an indicator's samples (integrators/watch_tests.py), shared by the
Python watches and the compiled screen (tests/integrators/test_watch_screen.py checks that the
screen finds the watch's events to the bit): against closed forms."""
from __future__ import annotations

import math

import numpy as np
import pytest

from nonsmooth_rod.integrators.watch_tests import TINY, looked_at, start_band

pytestmark = pytest.mark.no_compiled_loop  # plain Python here (the screen compiles them)


def test_a_dip_is_the_closed_form_minimum_of_the_parabola_through_three_samples():
    """s(t) = 2 (t − 0.37)² + 0.05 sampled at 0.2, 0.3, 0.5 (all safe): its vertex at t = 0.37, of
    value 0.05 = 0.5967 × the smaller end s(0.5) = 0.0838 — a dip for a fraction of 0.60, not for
    0.59; none for a parabola opening downwards or one whose vertex is outside the samples."""
    def s(t):
        return 2.0 * (t - 0.37) ** 2 + 0.05

    samples = (0.2, 0.3, 0.5, s(0.2), s(0.3), s(0.5))
    looked, dip, t_v = looked_at(*samples, 0.60)
    assert looked and dip and t_v == pytest.approx(0.37, abs=1e-14)
    assert looked_at(*samples, 0.59)[:2] == (False, False)
    assert looked_at(0.2, 0.3, 0.5, 1.0 - s(0.2), 1.0 - s(0.3), 1.0 - s(0.5), 1.0)[:2] == (False, False)
    assert looked_at(0.4, 0.5, 0.6, s(0.4), s(0.5), s(0.6), 1.0)[:2] == (False, False)


def test_a_step_is_looked_at_where_a_sample_is_not_safe():
    """A sample ≤ 0 (falling through zero, bending down: no dip); a NaN as Python's min of the
    three reads it (first: looked at; later: passed — the compiled screen flags it too)."""
    assert looked_at(0.0, 0.1, 0.2, 1.0, 0.5, -1e-3, 0.5)[:2] == (True, False)
    assert looked_at(0.0, 0.1, 0.2, math.nan, 1.0, 1.0, 0.5)[0]
    assert not looked_at(0.0, 0.1, 0.2, 1.0, math.nan, 1.0, 0.5)[0]


def test_an_indicator_starting_at_zero_is_safe_until_it_leaves_its_band():
    """Samples of an indicator starting at 0 (−1e-16, round-off, then growing): counted TINY (safe)
    while within its band after the start, read as they are from the first sample outside it,
    whose time is kept; a later call leaves samples at or after that time alone."""
    exits = np.full(2, math.inf)
    ts, s = [0.0, 0.1, 0.2, 0.3], [0.0, -1e-16, -1e-6, -2e-6]
    start_band(ts, s, 0.0, 1e-12, exits, 1)
    assert s == [TINY, TINY, -1e-6, -2e-6] and exits[1] == 0.2 and exits[0] == math.inf
    later = [-3e-6, -1e-16]
    start_band([0.4, 0.5], later, 0.0, 1e-12, exits, 1)
    assert later == [-3e-6, -1e-16]
