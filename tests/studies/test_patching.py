"""A map's fast path (studies/patching.py): a point's scene patched into the parsed base is the
scene the full parse gives, so every outcome is the same bit for bit; what cannot be patched, or
what the scene refuses, goes through the full parse."""
from __future__ import annotations

import copy
import math
from pathlib import Path

import pytest

from nonsmooth_rod.studies import maps, patching
from nonsmooth_rod.studies.maps import run_point, scene_data, sweep
from nonsmooth_rod.studies.patching import PointScenes
from nonsmooth_rod.studies.paths import with_values

SCENES = Path(__file__).resolve().parents[2] / "examples" / "scenes"
FLOOR, WALL = "contacts.foot.law.mu_s", "contacts.top.law.mu_s"
CRITICAL_FLOOR_MU = 1.0 / (2.0 * math.tan(math.radians(60.0)))  # the frictionless-wall ladder holds above it


@pytest.fixture(scope="module")
def ladder():
    data, source = scene_data(SCENES / "ladder.toml", ["contacts.*.law.mu_d=0"])
    return data, source, maps._base_run(data, source)


def same_row(a: dict, b: dict) -> bool:
    """Equal keys and values, NaN equal to NaN (a float compared by its bits' value)."""
    return a.keys() == b.keys() and all(
        a[k] == b[k] or (isinstance(a[k], float) and math.isnan(a[k]) and math.isnan(b[k])) for k in a)


def rows_both_ways(data, source, names, paths, points):
    fast, slow = PointScenes(data, source, paths), PointScenes(data, source, paths, fast=False)
    assert fast.fast and not slow.fast
    return [(run_point(data, source, paths, p, names, fast), run_point(data, source, paths, p, names, slow))
            for p in points]


def test_patched_laws_run_the_ladder_as_the_full_parse_does(ladder):
    data, source, names = ladder
    points = [(0.1, 0.0), (CRITICAL_FLOOR_MU - 0.01, 0.0), (CRITICAL_FLOOR_MU + 0.01, 0.0), (0.45, 0.3)]
    pairs = rows_both_ways(data, source, names, (FLOOR, WALL), points)
    for fast, slow in pairs:
        assert same_row(fast, slow), (fast, slow)
    point = {FLOOR: 0.3, WALL: 0.1}
    assert PointScenes(data, source, (FLOOR, WALL)).scene_file(point).data == with_values(data, point)
    # and they are the physics: the ladder slides below the critical floor μs, holds above it
    assert [bool(f["held"]) for f, _ in pairs] == [False, False, True, True]


def test_every_contact_and_two_keys_moving_together(ladder):
    data, source, names = ladder
    for paths, points in ((("contacts.*.law.mu_s",), [(0.2,), (0.4,)]),
                          ((f"{FLOOR},{WALL}",), [(0.25,), (0.35,)])):
        for fast, slow in rows_both_ways(data, source, names, paths, points):
            assert same_row(fast, slow), (fast, slow)


def test_a_refused_point_says_what_the_full_parse_says(ladder):
    data, source, names = ladder
    (fast, slow), = rows_both_ways(data, source, names, ("contacts.foot.law.mu_d",), [(0.7,)])
    assert fast["regime"] == "refused" and same_row(fast, slow)
    assert "mu_d" in fast["message"] and "exceeds mu_s" in fast["message"]


def test_mu_d_left_to_its_default_follows_mu_s():
    data, source = scene_data(SCENES / "ladder.toml")
    data = copy.deepcopy(data)
    del data["contacts"][0]["law"]["mu_d"]  # the file's default: μd = μs
    scenes = PointScenes(data, source, (FLOOR,))
    law = scenes.scene_file({FLOOR: 0.3}).scene.contacts[0].law
    assert law.friction.mu_s == law.friction.mu_d == 0.3
    assert scenes.base.scene.contacts[0].law.friction.mu_d == 0.5  # the base is left as it was


def test_initial_state_and_run_settings_are_patched(ladder):
    data, source, names = ladder
    paths = ("initial.ladder.q.0", "simulation.t_end")  # x: the top off the wall (0.6), into it (0.4)
    pairs = rows_both_ways(data, source, names, paths, [(0.5, 0.05), (0.6, 0.1), (0.4, 0.1)])
    for fast, slow in pairs:
        assert same_row(fast, slow), (fast, slow)
    assert pairs[2][0]["regime"] == "refused" and "top" in pairs[2][0]["message"]
    sf = PointScenes(data, source, paths).scene_file({paths[0]: 0.6, paths[1]: 0.1})
    assert sf.t_end == 0.1 and sf.q0[0] == 0.6


def test_other_paths_take_the_full_parse(ladder):
    data, source, _ = ladder
    assert not PointScenes(data, source, ("bodies.ladder.mass",)).fast
    assert not PointScenes(data, source, (f"{FLOOR},bodies.ladder.mass",)).fast
    assert not patching.patchable("contacts.foot.offset.0")
    sf = PointScenes(data, source, ("bodies.ladder.mass",)).scene_file({"bodies.ladder.mass": 2.0})
    assert sf.scene.bodies[0].mass == 2.0


def test_a_whole_map_is_the_same_with_the_fast_path_off(tmp_path, monkeypatch):
    axes = [f"{FLOOR}=0.2:0.4:3", f"{WALL}=0:0.2:2"]
    fast = sweep(SCENES / "ladder.toml", axes, tmp_path / "fast", sets=["contacts.*.law.mu_d=0"], jobs=1,
                 plot=False)
    monkeypatch.setattr(maps, "point_scenes", lambda data, source, paths: PointScenes(data, source, paths, False))
    slow = sweep(SCENES / "ladder.toml", axes, tmp_path / "slow", sets=["contacts.*.law.mu_d=0"], jobs=1,
                 plot=False)
    assert len(fast.rows) == len(slow.rows) == 6
    for a, b in zip(fast.rows, slow.rows):
        assert same_row(a, b), (a, b)
    assert (tmp_path / "fast" / "map.csv").read_text() == (tmp_path / "slow" / "map.csv").read_text()
