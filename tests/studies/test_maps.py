"""Maps of any scene: the ladder's hold/slide boundary and the belt oscillator's stick–slip
regimes against their closed forms; resuming; the CSV and sweep.json."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from nonsmooth_rod.studies.maps import sweep
from nonsmooth_rod.toys.belt import BeltOscillator
from nonsmooth_rod.toys.indeterminate import Ladder

SCENES = Path(__file__).resolve().parents[2] / "examples" / "scenes"

FLOOR, WALL = "contacts.foot.law.mu_s", "contacts.top.law.mu_s"
LADDER_ANGLE = math.radians(60.0)  # examples/scenes/ladder.toml: foot at (1, 0), top at (0, √3)
REFINE = 8


def ladder_critical_floor_mu(mu_wall: float) -> float:
    """The least floor μs that holds: tan β ≥ (1 − μ1 μ2)/(2 μ1) ⇔ μ1 ≥ 1/(2 tan β + μ2)."""
    return 1.0 / (2.0 * math.tan(LADDER_ANGLE) + mu_wall)


@pytest.fixture(scope="module")
def ladder_map(tmp_path_factory):
    out = tmp_path_factory.mktemp("ladder")
    return sweep(SCENES / "ladder.toml", [f"{FLOOR}=0.1:0.5:9", f"{WALL}=0:0.4:5"], out,
                 sets=["contacts.*.law.mu_d=0"], refine=REFINE, jobs=1, plot=True)


def test_the_ladder_holds_where_the_closed_form_says(ladder_map):
    assert len(ladder_map.rows) == 45
    for r in ladder_map.rows:
        toy = Ladder(LADDER_ANGLE, r[FLOOR], 0.0, r[WALL], 0.0, length=2.0)
        assert bool(r["held"]) == toy.holds(), r
        assert r["regime"] == ("foot: stick; top: stick" if toy.holds() else "foot: slip+; top: slip+")


def test_the_ladder_boundary_matches_the_closed_form_on_every_grid_line(ladder_map):
    along_floor = [b for b in ladder_map.boundaries if b["axis"] == FLOOR]
    assert sorted(b[WALL] for b in along_floor) == pytest.approx([0.0, 0.1, 0.2, 0.3, 0.4])
    width = 0.05 / 2**REFINE
    for b in along_floor:
        exact = ladder_critical_floor_mu(b[WALL])
        assert b["hi"] - b["lo"] == pytest.approx(width, rel=1e-9)
        # the simulated boundary lies in the bisected bracket (the hold test is exact statics)
        assert b["lo"] - 1e-9 <= exact <= b["hi"] + 1e-9, (b, exact)
    # along the wall axis the boundary is crossed only by floor values inside a wall line's span
    assert (ladder_map.out_dir / "boundaries.csv").exists() and (ladder_map.out_dir / "map.png").exists()


def test_the_map_folder_records_the_scene_and_resumes(ladder_map, tmp_path):
    record = json.loads((ladder_map.out_dir / "sweep.json").read_text())
    assert record["axes"] == [FLOOR, WALL] and record["counts"]["points"] == 45
    assert record["scene"]["contacts"][0]["law"]["mu_d"] == 0.0
    header = (ladder_map.out_dir / "map.csv").read_text().splitlines()[0].split(",")
    assert header[:4] == [FLOOR, WALL, "regime", "status"]
    again = sweep(SCENES / "ladder.toml", [f"{FLOOR}=0.1:0.5:9", f"{WALL}=0:0.4:5"], ladder_map.out_dir,
                  sets=["contacts.*.law.mu_d=0"], jobs=1, plot=False)
    assert again.computed == 0 and again.reused == 45
    assert [r["regime"] for r in again.rows] == [r["regime"] for r in ladder_map.rows]


BELT_SPEED = "lines.belt.velocity,initial.block.v.0"  # the block starts riding the belt
T_END, H = 1.2, 1e-3


def test_the_belt_oscillator_map_has_its_stick_slip_regimes(tmp_path):
    result = sweep(SCENES / "belt_oscillator.toml", [f"{BELT_SPEED}=0.04:0.4:7", "contacts.*.law.mu_s=0.4:0.8:5"],
                   tmp_path, sets=["contacts.*.law.mu_d=0.3"], refine=6, jobs=1, plot=True)
    kinds = set()
    for r in result.rows:
        toy = BeltOscillator(belt_speed=r[BELT_SPEED], mu_s=r["contacts.*.law.mu_s"], mu_d=0.3)
        t_slip, t_restick = toy.first_slip_time, toy.first_slip_time + toy.slip_time
        # Moreau–Jean's re-stick comes early by at most 2 (1 + 1/r) h (docs/toys.md, r = ω y0/v_b);
        # a corner's onset lies within 2 h of the block's
        early = 2 * (1 + toy.belt_speed / (toy.omega * toy.slip_amplitude)) * H + 2 * H
        if abs(t_slip - T_END) < 3 * H or abs(t_restick - T_END) < early + H:
            continue  # the end of the run cuts a phase within a step: either reading is right
        if t_slip > T_END:
            expected = "stick"
        elif t_restick > T_END:
            expected = "stick slip-"
        else:
            expected = "stick slip- stick"
        kinds.add(expected)
        assert r["regime"].split(";")[0] == f"left: {expected}" or r["regime"].startswith(f"left: {expected} "), r
        assert bool(r["held"]) == (expected == "stick")
        if t_slip < T_END:
            assert r["left.first_slip"] == pytest.approx(t_slip, abs=2 * H)
        if t_restick < T_END:
            assert t_restick - early <= r["left.first_stick"] <= t_restick + 2 * H
    assert kinds == {"stick", "stick slip-", "stick slip- stick"}
    # the stick | stick-slip boundary along the belt speed: v = μs m g / (k t_end)
    onsets = [b for b in result.boundaries if b["axis"] == BELT_SPEED and b["regime_hi"].startswith("left: stick slip-")
              and b["regime_lo"].startswith("left: stick;")]
    assert onsets
    for b in onsets:
        toy = BeltOscillator(mu_s=b["contacts.*.law.mu_s"], mu_d=0.3)
        exact = toy.slip_onset_position / T_END
        assert b["lo"] - 2 * H * exact / T_END <= exact <= b["hi"] + 2 * H * exact / T_END, (b, exact)
