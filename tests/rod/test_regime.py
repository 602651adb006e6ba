"""Regime map: simulated scenarios against the rolling hypothesis' thresholds; resuming."""
from __future__ import annotations

import json
import math
import shutil

import numpy as np
import pytest

from nonsmooth_rod.rod import regime, regime_figure
from nonsmooth_rod.rod.problem import RodGeometry, RodProblem
from nonsmooth_rod.rod.plotting import axis
from nonsmooth_rod.rod.regime import (
    CSV_COLUMNS,
    REFERENCE,
    Grid,
    SweepSettings,
    parse_range,
    predicted_scenario,
    read_rows,
    scenario_of,
    sweep,
    thresholds,
)
from nonsmooth_rod.results import Phase
from nonsmooth_rod.validation import InputError

BASE = RodProblem.paper()
MU_S = np.linspace(0.20, 0.42, 12)  # step 0.02: spans T/N(0) ≈ 0.263 and max T/N ≈ 0.290


@pytest.fixture(scope="module")
def small_sweep(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep")
    return sweep(BASE, Grid(MU_S, np.array([60.0]), mu_d_ratio=0.75), out, REFERENCE, jobs=2, plot=True)


def test_thresholds_at_60_degrees():
    th = thresholds(BASE, 60.0)
    assert th.T_over_N_initial == pytest.approx(0.2628, abs=1e-4)
    assert th.T_over_N_max == pytest.approx(0.2900, abs=1e-4)   # the paper's "≈ 0.29"
    assert th.t_max == pytest.approx(0.1584, abs=1e-3)
    # Rolling to the impact needs μs ≥ |T/N| at the horizontal: ≈ 1.97, far beyond steel on steel.
    assert th.T_over_N_min == pytest.approx(-1.968, abs=1e-3)
    assert th.rolling.T_over_N[-1] == pytest.approx(th.T_over_N_min, abs=1e-9)


def test_scenarios_agree_with_the_analytic_thresholds(small_sweep):
    rows = small_sweep.grid_rows
    assert [r["mu_s"] for r in rows] == pytest.approx(MU_S)
    th = small_sweep.thresholds[0]
    bounds = (th.T_over_N_initial, th.T_over_N_max, -th.T_over_N_min)
    step = MU_S[1] - MU_S[0]
    checked = 0
    for r in rows:
        expected, t_expected = predicted_scenario(th.rolling, r["mu_s"])
        if min(abs(r["mu_s"] - b) for b in bounds) < step:
            continue  # within one grid step of a boundary: either side is acceptable
        checked += 1
        assert r["scenario"] == expected, r
        if expected == "slide-at-start":
            assert r["t_transition"] == 0.0
        else:  # the rolling phase is exact in both: transition times agree to the event tolerance
            assert r["t_transition"] == pytest.approx(t_expected, abs=1e-6)
        assert 0.34 < r["t_impact"] < 0.39
    assert checked >= 9
    # Each boundary lies between the two grid points where the simulated scenario changes.
    scen = [r["scenario"] for r in rows]
    changes = [(MU_S[k], MU_S[k + 1], scen[k], scen[k + 1]) for k in range(len(rows) - 1) if scen[k] != scen[k + 1]]
    assert [(a, b) for _, _, a, b in changes] == [("slide-at-start", "roll-until-r1"),
                                                 ("roll-until-r1", "roll-until-r2")]
    for (lo, hi, _, _), bound in zip(changes, bounds[:2]):
        assert lo < bound <= hi


def test_roll_to_impact_needs_mu_s_beyond_the_horizontal_ratio(tmp_path):
    res = sweep(BASE, Grid(np.array([1.90, 2.05]), np.array([60.0]), mu_d_ratio=0.75), tmp_path,
                REFERENCE, jobs=1, plot=False)
    assert [r["scenario"] for r in res.grid_rows] == ["roll-until-r2", "roll-to-impact"]
    rolled = res.grid_rows[1]
    assert math.isnan(rolled["t_transition"])
    assert rolled["phases"].startswith("stick 0.000000..") and ";" not in rolled["phases"]
    # Rolling to the horizontal takes the rolling hypothesis' t_h = 0.38082 s.
    assert rolled["t_impact"] == pytest.approx(res.thresholds[0].rolling.t_horizontal, abs=1e-6)


def test_at_30_degrees_the_start_is_the_maximum_so_no_r1_region(tmp_path):
    th = thresholds(BASE, 30.0)
    assert th.T_over_N_max == pytest.approx(th.T_over_N_initial, abs=1e-6)  # ≈ 0.410
    res = sweep(BASE, Grid(np.array([0.39, 0.43]), np.array([30.0]), mu_d_ratio=0.75), tmp_path,
                jobs=1, plot=False)
    assert [r["scenario"] for r in res.grid_rows] == ["slide-at-start", "roll-until-r2"]


def test_map_cells_and_boundaries(small_sweep):
    from nonsmooth_rod.rod.regime_figure import regime_map_figure

    fig = regime_map_figure(small_sweep.grid_rows, Grid(MU_S, np.array([60.0]), mu_d_ratio=0.75), BASE,
                            small_sweep.thresholds)
    ax = axis(fig, "map")
    mesh = ax.collections[0]
    names, code = regime_figure._scenario_codes(small_sweep.grid_rows)
    cells = np.asarray(mesh.get_array()).ravel()
    assert [names[int(c)] for c in cells] == [r["scenario"] for r in small_sweep.grid_rows]
    for gid, value in (("T_over_N_initial", 0.26278), ("T_over_N_max", 0.29003)):
        (line,) = [ln for ln in ax.get_lines() if ln.get_gid() == gid]
        assert line.get_xdata()[0] == pytest.approx(value, abs=1e-5)
    times = axis(fig, "times")
    (tr,) = [ln for ln in times.get_lines() if ln.get_gid() == "t_transition:60"]
    np.testing.assert_array_equal(tr.get_ydata(), [r["t_transition"] for r in small_sweep.grid_rows])
    assert (small_sweep.out_dir / "regime_map.png").stat().st_size > 10_000


@pytest.mark.parametrize("cut", [15, -5])  # inside the numbers; inside the phases text
def test_resume_after_truncation_gives_the_same_csv(small_sweep, tmp_path, cut):
    src = small_sweep.out_dir
    full = (src / "regime_map.csv").read_text()
    work = tmp_path / "resume"
    shutil.copytree(src, work)
    lines = full.splitlines(keepends=True)
    # Header, three rows and part of a fourth: what an interrupted append leaves behind.
    (work / "regime_map.csv").write_text("".join(lines[:4]) + lines[4][:cut])
    res = sweep(BASE, Grid(MU_S, np.array([60.0]), mu_d_ratio=0.75), work, REFERENCE, jobs=2, plot=False)
    assert (res.reused, res.computed) == (3, 9)
    assert (work / "regime_map.csv").read_text() == full


def test_interrupted_sweep_keeps_its_rows_and_resumes(tmp_path, monkeypatch):
    grid = Grid(np.array([0.22, 0.28, 0.34, 0.40]), np.array([60.0]), mu_d_ratio=0.75)
    real = regime.classify_point
    calls = []

    def interrupting(*args, **kwargs):
        if len(calls) == 2:
            raise KeyboardInterrupt
        calls.append(args)
        return real(*args, **kwargs)

    monkeypatch.setattr(regime, "classify_point", interrupting)
    with pytest.raises(KeyboardInterrupt):
        sweep(BASE, grid, tmp_path, jobs=1, plot=False)
    rows, bad = read_rows(tmp_path / "regime_map.csv")
    assert len(rows) == 2 and bad == 0
    monkeypatch.setattr(regime, "classify_point", real)
    res = sweep(BASE, grid, tmp_path, jobs=1, plot=False)
    assert (res.reused, res.computed) == (2, 2)
    assert [r["scenario"] for r in res.grid_rows] == ["slide-at-start", "roll-until-r1", "roll-until-r2",
                                                      "roll-until-r2"]


def test_other_settings_refuse_the_folder(small_sweep, tmp_path):
    work = tmp_path / "other"
    shutil.copytree(small_sweep.out_dir, work)
    with pytest.raises(InputError, match="other settings"):
        sweep(BASE, Grid(MU_S, np.array([60.0]), mu_d_ratio=0.75), work,
              SweepSettings(method="moreau-jean", h=1e-3), jobs=1, plot=False)
    (work / "sweep.json").unlink()
    with pytest.raises(InputError, match="without sweep.json"):
        sweep(BASE, Grid(MU_S, np.array([60.0]), mu_d_ratio=0.75), work, REFERENCE, jobs=1, plot=False)


def test_csv_columns(small_sweep):
    header = (small_sweep.out_dir / "regime_map.csv").read_text().splitlines()[0]
    assert tuple(header.split(",")) == CSV_COLUMNS


def test_grid_points_and_ranges():
    assert parse_range("0.1:0.3:3", "x") == pytest.approx([0.1, 0.2, 0.3])
    assert parse_range("0.5", "x") == pytest.approx([0.5])
    assert parse_range("0.1,0.4", "x") == pytest.approx([0.1, 0.4])
    for bad in ("0.1:0.3", "0.1:0.3:0", "0.1:0.3:2.5", "a:b:3", "nan", "0.1:0.2:1", "1:0:3", "0.3:0.1:3",
                "0.1,0.2,0.1", "inf", "0:inf:3", "0.1:0.1:3", "0.1:0.3:-2"):
        with pytest.raises(InputError):
            parse_range(bad, "x")
    # A μd grid keeps only μd ≤ μs.
    pts = Grid(np.array([0.1, 0.3]), np.array([60.0]), mu_d=np.array([0.05, 0.2])).points()
    assert pts == [(0.1, 0.05, 60.0), (0.3, 0.05, 60.0), (0.3, 0.2, 60.0)]
    # Several ratios and an extra axis: one column each, the first column varying fastest.
    g = Grid(np.array([0.1, 0.2]), np.array([60.0]), mu_d_ratio=np.array([0.5, 1.0]),
             extra={"restitution": [0.0, 0.5]})
    assert g.columns == ("mu_s", "mu_d", "theta0_deg", "mu_d_ratio", "restitution")
    assert g.points()[:3] == [(0.1, 0.05, 60.0, 0.5, 0.0), (0.1, 0.1, 60.0, 1.0, 0.0), (0.2, 0.1, 60.0, 0.5, 0.0)]
    assert len(g.points()) == 8
    for bad in ({"colour": [1.0]}, {"restitution": [1.5]}, {"ball_radius": [-0.01]}, {"density": [1.0, 1.0]}):
        with pytest.raises(InputError):
            Grid(np.array([0.1]), np.array([60.0]), mu_d_ratio=0.5, extra=bad)
    with pytest.raises(InputError):
        Grid(np.array([0.1]), np.array([95.0]), mu_d_ratio=0.5)
    with pytest.raises(InputError):
        Grid(np.array([0.1]), np.array([60.0]), mu_d_ratio=1.2)


def test_scenario_of_phase_sequences():
    ph = lambda *modes: [Phase(m, k, k + 1) for k, m in enumerate(modes)]  # noqa: E731
    assert scenario_of(ph("slip-", "slip+")) == "slide-at-start"
    assert scenario_of(ph("stick", "slip-", "slip+")) == "roll-until-r1"
    assert scenario_of(ph("stick", "slip+")) == "roll-until-r2"
    assert scenario_of(ph("stick")) == "roll-to-impact"
    assert scenario_of(ph("stick"), "painleve") == "painleve"


def test_a_second_sweep_into_a_busy_folder_is_refused(tmp_path):
    grid = Grid(np.array([0.3]), np.array([60.0]), mu_d_ratio=0.75)
    with regime.folder_lock(tmp_path):
        with pytest.raises(InputError, match="another sweep is writing"):
            sweep(BASE, grid, tmp_path, jobs=1, plot=False)
    res = sweep(BASE, grid, tmp_path, jobs=1, plot=False)  # free again once the first is done
    assert res.computed == 1 and (tmp_path / regime.LOCK_NAME).exists()  # the lock stays; free again


# --------------------------------------------------------------------------- the fast default path
THETAS = np.array([35.0, 45.0, 55.0, 65.0, 75.0])
MU_FINE = np.linspace(0.10, 0.50, 41)  # step 0.01


@pytest.fixture(scope="module")
def theta_map(tmp_path_factory):
    """Moreau–Jean (the default, h = 1e-3) over μs × θ0, with the accuracy check."""
    out = tmp_path_factory.mktemp("theta_map")
    return sweep(BASE, Grid(MU_FINE, THETAS, mu_d_ratio=0.75), out, jobs=2, plot=False, check_points=6)


def test_map_boundaries_match_the_analytic_thresholds_at_every_theta0(theta_map):
    """At every θ0 the scenario changes exactly between the two grid points that bracket
    |T/N(0)| (slide-at-start → rolling) and max T/N (roll-until-r1 → roll-until-r2)."""
    step = MU_FINE[1] - MU_FINE[0]
    for th in theta_map.thresholds:
        rows = [r for r in theta_map.grid_rows if r["theta0_deg"] == th.theta0_deg]
        assert [r["mu_s"] for r in rows] == pytest.approx(MU_FINE)
        start, peak = abs(th.T_over_N_initial), th.T_over_N_max
        for r in rows:
            ms = r["mu_s"]
            if ms < start - 1e-12:
                assert r["scenario"] == "slide-at-start", (th.theta0_deg, r)
            elif ms > max(start, peak) + 1e-12:
                assert r["scenario"] == "roll-until-r2", (th.theta0_deg, r)
            elif ms > start + 1e-12:  # between T/N(0) and max T/N: r1 (none when the start is the max)
                assert r["scenario"] == "roll-until-r1", (th.theta0_deg, r)
        # Each boundary is resolved at the grid's resolution: no point within half a step is needed.
        assert min(abs(MU_FINE - start)) < step and min(abs(MU_FINE - peak)) < step


def test_times_agree_with_the_rolling_hypothesis_to_the_stated_tolerance(theta_map):
    tol = SweepSettings().time_tolerance
    for th in theta_map.thresholds:
        for r in (r for r in theta_map.grid_rows if r["theta0_deg"] == th.theta0_deg):
            expected, t_expected = predicted_scenario(th.rolling, r["mu_s"])
            if r["scenario"] == expected and expected != "slide-at-start":
                assert abs(r["t_transition"] - t_expected) <= tol, r


def test_accuracy_check_is_reported_in_sweep_json(theta_map):
    acc = theta_map.accuracy
    assert acc["checked"] == 6 and acc["scenario_agree"] == 6 and acc["within_tolerance"]
    assert acc["max_abs_error_t_transition_s"] <= acc["time_tolerance_s"] == pytest.approx(3 * SweepSettings().h)
    record = json.loads((theta_map.out_dir / "sweep.json").read_text())
    assert record["accuracy"] == json.loads(json.dumps(acc))
    assert set(record["provenance"]) == {"version", "command", "python", "numpy", "scipy", "numba", "created"}
    assert record["grid"]["theta0_deg"] == THETAS.tolist() and record["grid"]["mu_d_ratio"] == [0.75]
    assert record["counts"]["points"] == MU_FINE.size * THETAS.size


def test_tables_in_memory_csv_and_parquet_agree(theta_map):
    pd = pytest.importorskip("pandas")
    pytest.importorskip("pyarrow")
    frame = theta_map.frame
    assert list(frame.columns) == list(CSV_COLUMNS) and len(frame) == MU_FINE.size * THETAS.size
    from_csv = pd.read_csv(theta_map.out_dir / "regime_map.csv", keep_default_na=False,
                           na_values={c: [""] for c in CSV_COLUMNS if c not in regime.TEXT_COLUMNS})
    from_parquet = pd.read_parquet(theta_map.out_dir / "regime_map.parquet")
    pd.testing.assert_frame_equal(from_parquet, frame)
    pd.testing.assert_frame_equal(from_csv, frame, check_dtype=False)
    # Ball B's impact state is recorded: θ at the impact of equal balls is zero (axis horizontal).
    assert np.nanmax(np.abs(frame["theta_impact"])) < 0.02


def test_geometry_and_restitution_axes(tmp_path):
    grid = Grid(np.array([0.2, 0.3]), np.array([60.0]), mu_d_ratio=0.75,
                extra={"ball_radius": [0.015, 0.025], "restitution": [0.0, 0.3]})
    res = sweep(BASE, grid, tmp_path, jobs=1, plot=True, check_points=0)
    assert res.columns[:5] == ("mu_s", "mu_d", "theta0_deg", "ball_radius", "restitution")
    assert len(res.grid_rows) == 8 and len(res.thresholds) == 4
    # The thresholds depend on the ball radius, not on e; each group's own body is simulated.
    by_r = {t.params["ball_radius"]: t.T_over_N_max for t in res.thresholds}
    assert by_r[0.015] != pytest.approx(by_r[0.025], abs=1e-4)
    for t in res.thresholds:
        body = RodProblem.from_geometry(RodGeometry(ball_radius=t.params["ball_radius"]))
        assert t.T_over_N_max == pytest.approx(thresholds(body, 60.0).T_over_N_max, rel=1e-12)
    th_csv = (tmp_path / "thresholds.csv").read_text().splitlines()[0].split(",")
    assert th_csv[:3] == ["theta0_deg", "ball_radius", "restitution"]
    assert (tmp_path / "regime_map.png").exists()
    with pytest.raises(InputError, match="rod diameter"):
        sweep(BASE, Grid(np.array([0.2]), np.array([60.0]), mu_d_ratio=0.75, extra={"ball_radius": [0.002, 0.02]}),
              tmp_path / "bad", jobs=1, plot=False)


def test_any_concurrent_futures_executor_and_resume(tmp_path):
    from concurrent.futures import ThreadPoolExecutor

    grid = Grid(np.array([0.22, 0.28, 0.34, 0.40]), np.array([50.0, 60.0]), mu_d_ratio=0.75)
    serial = sweep(BASE, grid, tmp_path / "serial", jobs=1, plot=False, check_points=0)
    with ThreadPoolExecutor(2) as pool:
        threaded = sweep(BASE, grid, tmp_path / "threads", executor=pool, plot=False, check_points=2)
    assert (tmp_path / "threads" / "regime_map.csv").read_text() == (tmp_path / "serial" / "regime_map.csv").read_text()
    assert threaded.accuracy["checked"] == 2 and serial.accuracy["checked"] == 0


def test_dask_local_cluster_with_resume(tmp_path):
    distributed = pytest.importorskip("distributed")
    grid = Grid(np.linspace(0.2, 0.4, 8), np.array([45.0, 60.0, 70.0]), mu_d_ratio=0.75)
    reference = sweep(BASE, grid, tmp_path / "ref", jobs=1, plot=False, check_points=0)
    work = tmp_path / "dask"
    with distributed.Client(processes=False, n_workers=1, threads_per_worker=2, dashboard_address=None) as client:
        first = sweep(BASE, grid, work, executor=client.get_executor(), plot=False, check_points=2)
        lines = (work / "regime_map.csv").read_text().splitlines(keepends=True)
        (work / "regime_map.csv").write_text("".join(lines[:10]) + lines[10][:7])  # killed mid-write
        again = sweep(BASE, grid, work, executor=client.get_executor(), plot=False, check_points=2)
    assert first.computed == 24 and (again.reused, again.computed) == (9, 15)
    assert (work / "regime_map.csv").read_text() == (tmp_path / "ref" / "regime_map.csv").read_text()
    assert again.accuracy == first.accuracy and first.accuracy["within_tolerance"]
    assert reference.grid_rows == again.grid_rows or all(
        a["scenario"] == b["scenario"] for a, b in zip(reference.grid_rows, again.grid_rows))


def test_every_cell_of_the_map_is_filled_for_unrounded_tilts(tmp_path):
    from nonsmooth_rod.rod.regime_figure import regime_map_figure

    grid = Grid(np.array([0.2, 0.3, 0.4]), np.linspace(40.0, 50.0, 4), mu_d_ratio=0.75)  # 43.333…°
    res = sweep(BASE, grid, tmp_path, jobs=1, plot=False, check_points=0)
    mesh = axis(regime_map_figure(res.grid_rows, grid, BASE, res.thresholds), "map").collections[0]
    cells = mesh.get_array()
    assert cells.size == 12 and not np.ma.is_masked(cells)


@pytest.mark.parametrize("y", ["mu_d_ratio", "theta0_deg"])
def test_map_over_two_axes_shows_every_point_of_that_plane(tmp_path, y):
    from nonsmooth_rod.rod.regime_figure import axes_map_figure

    mu = np.array([0.2, 0.27, 0.3, 0.4])
    grid = Grid(mu, np.array([45.0, 60.0]), mu_d_ratio=np.array([0.5, 0.8, 1.0]))
    res = sweep(BASE, grid, tmp_path, jobs=1, plot=False, check_points=0)
    ax = axis(axes_map_figure(res.grid_rows, grid, BASE, x="mu_s", y=y), "map")
    cells = ax.collections[0].get_array()
    names, _ = regime_figure._scenario_codes(res.grid_rows)
    held = "theta0_deg" if y == "mu_d_ratio" else "mu_d_ratio"
    plane = [r for r in res.grid_rows if r[held] == min(r2[held] for r2 in res.grid_rows)]
    assert cells.size == len(plane) == 4 * (3 if y == "mu_d_ratio" else 2) and not np.ma.is_masked(cells)
    # Row-major over (y, μs): the plane's rows sorted the same way.
    plane.sort(key=lambda r: (r[y], r["mu_s"]))
    assert [names[int(c)] for c in np.asarray(cells).ravel()] == [r["scenario"] for r in plane]
    # With μs along x the boundaries are drawn: |T/N(0)| at 60° is 0.2628.
    (start,) = [ln for ln in ax.get_lines() if ln.get_gid() == "T_over_N_initial"]
    if y == "mu_d_ratio":
        assert start.get_xdata()[0] == pytest.approx(thresholds(BASE, 45.0).T_over_N_initial, abs=1e-9)
    else:
        assert list(start.get_xdata()) == pytest.approx([thresholds(BASE, t).T_over_N_initial for t in (45, 60)])
    with pytest.raises(InputError, match="cannot map axis"):
        axes_map_figure(res.grid_rows, grid, BASE, x="mu_s", y="mu_d")


_RACER = """
import os, sys, time
from pathlib import Path
from nonsmooth_rod.rod.regime import folder_lock
from nonsmooth_rod.validation import InputError

folder, held = Path(sys.argv[1]), 0
(folder / f"ready.{os.getpid()}").touch()
deadline = time.time() + 60.0
while len(list(folder.glob("ready.*"))) < 3 and time.time() < deadline:  # all three start together,
    time.sleep(0.001)                                                    # however slow their imports
start = time.time()
while time.time() < start + 1.5:
    try:
        with folder_lock(folder):
            try:  # the one holder's mark: a second holder finds it there
                os.close(os.open(folder / "holder", os.O_CREAT | os.O_EXCL | os.O_WRONLY))
            except FileExistsError:
                sys.exit(3)
            held += 1
            time.sleep(0.0005)
            os.unlink(folder / "holder")
    except InputError:
        pass
print(held)
"""


def test_three_racing_sweeps_never_hold_the_folder_lock_together(tmp_path):
    """The lock file stays on disk: unlinked on release, a sweep that had opened the old file and
    one creating a new file could both hold "the" lock (measured: within a second of racing)."""
    import os
    import subprocess
    import sys
    import time

    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    racers = [subprocess.Popen([sys.executable, "-c", _RACER, str(tmp_path)], env=env,
                               stdout=subprocess.PIPE, text=True) for _ in range(3)]
    outputs = [p.communicate(timeout=120)[0] for p in racers]
    assert [p.returncode for p in racers] == [0, 0, 0], "two sweeps held the lock at once"
    assert sum(int(o) for o in outputs) > 100  # they really raced for it
    assert (tmp_path / regime.LOCK_NAME).exists()
