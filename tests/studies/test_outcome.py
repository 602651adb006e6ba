"""A run's outcome: events read from its phases (a slip reversal is not an onset), the regime
word, whether it held."""
from __future__ import annotations

import math

import numpy as np
import pytest

from nonsmooth_rod.results import Impact, Phase, SimulationResult, Trajectory
from nonsmooth_rod.studies.outcome import contact_events, held, outcome_row, regime_of

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)


def _result(phases, impacts=(), status="stopped"):
    t = np.array([0.0, 0.375])
    z = np.zeros((2, 3))
    traj = Trajectory(t, z, z, z, np.zeros((2, 2)), np.zeros((2, 2)), np.full((2, 2), "stick"))
    return SimulationResult("event-driven", status, "", traj, ["A", "B"], impacts=list(impacts), phases=phases)


ROD = {"A": [Phase("stick", 0, 0.104), Phase("slip-", 0.104, 0.302), Phase("slip+", 0.302, 0.375)],
       "B": [Phase("open", 0, 0.375)]}
IMPACT = Impact(0.375, "B", np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(2), np.zeros(2))


def test_the_rods_events_regime_and_row():
    r = _result(ROD, [IMPACT])
    assert contact_events(r) == [("slip", "A", 0.104), ("impact", "B", 0.375)]
    assert regime_of(r) == "A: stick slip- slip+; B: open" and not held(r)
    row = outcome_row(r, ["A", "B"])
    assert row["A.first_slip"] == 0.104 and row["B.first_impact"] == 0.375 and math.isnan(row["A.first_stick"])


def test_a_slide_from_the_start_and_a_restick_and_a_lift_off():
    r = _result({"A": [Phase("slip+", 0, 0.2), Phase("stick", 0.2, 0.3), Phase("open", 0.3, 0.375)],
                 "B": [Phase("stick", 0, 0.375)]})
    assert contact_events(r) == [("slip", "A", 0.0), ("stick", "A", 0.2), ("lift-off", "A", 0.3)]


def test_held_means_every_contact_stuck_throughout_a_successful_run():
    still = {"A": [Phase("stick", 0, 0.375)], "B": [Phase("stick", 0, 0.375)]}
    assert held(_result(still)) and not held(_result(still, status="failed"))
