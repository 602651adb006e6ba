"""`nonsmooth-rod plot` and `nonsmooth-rod sweep`: files written, data read back, one-line errors."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from nonsmooth_rod.cli import main
from nonsmooth_rod.io import read_csv
from nonsmooth_rod.rod.plotting import (
    DATA_GID,
    MARKER_GID,
    axis,
    drawn_series,
    lines_and_markers,
    load_run_dir,
    panel_figure,
)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """An event-driven and a Moreau–Jean run of the paper's case 3, written by simulate."""
    root = tmp_path_factory.mktemp("runs")
    ed, mj = root / "ed", root / "mj"
    assert main(["simulate", "--mu-s", "0.4", "--mu-d", "0.3", "--no-plot", "--quiet", "--out", str(ed)]) == 0
    assert main(["simulate", "--mu-s", "0.4", "--mu-d", "0.3", "--method", "moreau-jean", "--h", "1e-3",
                 "--no-plot", "--quiet", "--out", str(mj)]) == 0
    return ed, mj


def _png_size(path):
    with Image.open(path) as im:
        assert im.format == "PNG"
        return im.size


def test_plot_folder_writes_the_panel_in_png_and_svg(runs, tmp_path, capsys):
    ed, _ = runs
    assert main(["plot", str(ed), "--out", str(tmp_path), "--dpi", "50"]) == 0
    printed = capsys.readouterr().out.split()
    assert printed == [str(tmp_path / "panel.png"), str(tmp_path / "panel.svg")]
    assert _png_size(tmp_path / "panel.png") == (1000, 380)
    assert (tmp_path / "panel.svg").read_text().lstrip().startswith("<?xml")


def test_folder_round_trip_draws_the_csv_values(runs):
    ed, mj = runs
    data, markers = load_run_dir(ed), load_run_dir(mj)
    table = read_csv(ed / "trajectory.csv")
    # Case 3 at θ0 = 60°: rolling until T/N = −μs at t_r2 = 0.30199 s, then sliding (v_C > 0).
    assert data.rolling.t_r2 == pytest.approx(0.30199, abs=1e-5) and data.rolling.t_r1 is None
    assert [ph.mode for ph in data.phases] == ["stick", "slip+"]
    fig = panel_figure(data, markers)
    t, theta_dot = drawn_series(axis(fig, "theta_dot"), DATA_GID)
    np.testing.assert_array_equal(t, table["t"])
    np.testing.assert_array_equal(theta_dot, table["theta_dot"])
    _, xm = drawn_series(axis(fig, "x_O"), MARKER_GID)
    np.testing.assert_array_equal(xm, read_csv(mj / "trajectory.csv")["x_O"])


def test_compare_puts_moreau_jean_as_markers_whatever_the_order(runs, tmp_path):
    ed, mj = runs
    lines, markers = lines_and_markers(load_run_dir(mj), load_run_dir(ed, rolling=False))
    assert (lines.method, markers.method) == ("event-driven", "moreau-jean")
    assert lines.rolling is not None and lines.source == str(ed)
    assert main(["plot", str(mj), "--compare", str(ed), "--out", str(tmp_path), "--format", "png",
                 "--dpi", "40", "--quiet"]) == 0
    assert _png_size(tmp_path / "panel.png") == (800, 304)
    assert not (tmp_path / "panel.svg").exists()


def test_frames_and_gif(runs, tmp_path):
    ed, _ = runs
    assert main(["plot", str(ed), "--no-panel", "--frames", "4", "--gif", "--format", "png", "--dpi", "40",
                 "--out", str(tmp_path), "--quiet"]) == 0
    assert not (tmp_path / "panel.png").exists()
    w, h = _png_size(tmp_path / "frames.png")
    assert w > 2 * h  # four poses side by side
    with Image.open(tmp_path / "rod.gif") as im:
        assert im.n_frames == 40


def test_paper_figures_without_a_folder(tmp_path):
    assert main(["plot", "--paper-figures", "--no-panel", "--format", "png", "--dpi", "30",
                 "--out", str(tmp_path), "--quiet"]) == 0
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["fig18-21_cases.png", "fig22_hypotheses_mu0.1.png", "fig23_hypotheses_mu0.257.png",
                     "fig24_hypotheses_mu0.3.png", "fig25_impact_detail.png"]
    assert _png_size(tmp_path / "fig18-21_cases.png") == (390, 255)  # 13 × 8.5 in at 30 dpi


@pytest.mark.parametrize("args, fragment", [
    (["plot"], "give a results folder"),
    (["plot", "{tmp}/nowhere"], "does not exist"),
    (["plot", "{tmp}"], "trajectory.csv not found"),
    (["plot", "{ed}", "--frames", "1"], "--frames must lie in [2, 48]"),
    (["plot", "{ed}", "--format", "jpg"], "must be among"),
    (["plot", "{ed}", "--compare", "{tmp}/nowhere"], "does not exist"),
    (["plot", "{ed}", "--no-panel"], "nothing to draw"),
    (["plot", "--paper-figures", "--gif"], "give its results folder"),
    (["sweep", "--mu-s", "0.1:0.3", "--out", "{tmp}/s"], "expected START:STOP:N"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--mu-d-ratio", "1.5", "--out", "{tmp}/s"], "[0, 1]"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--theta0-deg", "0:90:4", "--out", "{tmp}/s"], "(0, 90)"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--method", "rk4", "--out", "{tmp}/s"], "unknown method"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--jobs", "0", "--out", "{tmp}/s"], "--jobs"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--mu-d", "0.1", "--mu-d-ratio", "0.5"], "not allowed with"),
    (["sweep", "--mu-s", "1:0:3", "--out", "{tmp}/s"], "runs backwards"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--mu-d", "0.3:0.1:3", "--out", "{tmp}/s"], "runs backwards"),
    (["sweep", "--mu-s", "0.1,0.2,0.1", "--out", "{tmp}/s"], "given twice"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--format", "png,svg,png", "--out", "{tmp}/s"], "format twice"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--mu-d-ratio", "0.5:1.2:3", "--out", "{tmp}/s"], "[0, 1]"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--ball-radius", "0.01:nan:3", "--out", "{tmp}/s"], "finite"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--restitution", "0,2", "--out", "{tmp}/s"], "[0, 1]"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--executor", "spark", "--out", "{tmp}/s"], "--executor"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--scheduler", "tcp://x:1", "--out", "{tmp}/s"], "needs --executor dask"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--map-axes", "mu_s,density", "--out", "{tmp}/s"], "cannot map axis"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--check", "-1", "--out", "{tmp}/s"], "--check"),
    (["sweep", "--mu-s", "1e308", "--out", "{tmp}/s"], "--mu-s: values must lie in [0, 100]"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--length", "1e308", "--out", "{tmp}/s"], "values must lie in (0, 100]"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--density", "1e308,7800", "--out", "{tmp}/s"], "(0, 100000]"),
    (["sweep", "--mu-s", "0.1:0.3:3", "--ball-radius", "0.001,0.02", "--out", "{tmp}/s"], "rod diameter"),
])
def test_bad_input_is_one_line_and_exit_2(runs, tmp_path, capsys, args, fragment):
    ed, _ = runs
    argv = [a.format(tmp=tmp_path, ed=ed) for a in args]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("nonsmooth-rod: error:") and fragment in err


def test_compare_of_another_problem_is_refused(runs, tmp_path, capsys):
    ed, _ = runs
    other = tmp_path / "other"
    assert main(["simulate", "--mu-s", "0.12", "--mu-d", "0.1", "--no-plot", "--quiet", "--out", str(other)]) == 0
    assert main(["plot", str(ed), "--compare", str(other), "--out", str(tmp_path)]) == 2
    assert "differs in mu_s, mu_d" in capsys.readouterr().err


def test_sweep_cli_writes_csv_map_and_resumes(tmp_path, capsys):
    out = tmp_path / "map"
    argv = ["sweep", "--mu-s", "0.24:0.32:5", "--mu-d-ratio", "0.7", "--theta0-deg", "60", "--jobs", "2",
            "--out", str(out)]
    assert main(argv) == 0
    report = capsys.readouterr().out
    assert "5 computed, 0 from an earlier run" in report and "max T/N = 0.2900" in report
    table = read_csv(out / "regime_map.csv")
    assert list(table) == ["mu_s", "mu_d", "theta0_deg", "scenario", "status", "t_transition", "t_impact",
                           "theta_impact", "theta_dot_impact", "x_O_dot_impact", "phases"]
    assert "points/s" in report and "accuracy vs event-driven" in report
    assert list(table["scenario"]) == ["slide-at-start", "slide-at-start", "roll-until-r1", "roll-until-r2",
                                       "roll-until-r2"]
    np.testing.assert_allclose(table["mu_d"], 0.7 * table["mu_s"], rtol=1e-15)
    assert _png_size(out / "regime_map.png")[0] > 500
    assert main(argv + ["--quiet", "--no-plot"]) == 0
    assert capsys.readouterr().out == ""
    assert read_csv(out / "regime_map.csv")["t_impact"].tolist() == table["t_impact"].tolist()


def test_sweep_over_mu_d_and_theta0_grid(tmp_path):
    out = tmp_path / "grid2"
    assert main(["sweep", "--mu-s", "0.2,0.3", "--mu-d", "0.1,0.25", "--theta0-deg", "45,60", "--jobs", "1",
                 "--out", str(out), "--quiet", "--format", "png"]) == 0
    table = read_csv(out / "regime_map.csv")
    # μd = 0.25 > μs = 0.2 is left out: 3 points per θ0.
    assert len(table["mu_s"]) == 6
    th = read_csv(out / "thresholds.csv")
    assert th["theta0_deg"].tolist() == [45.0, 60.0]
    # At 45° T/N(0) = 0.3665 is the maximum: μs = 0.3 slides from the start; at 60° it rolls.
    got = {(r[0], r[1], r[2]): r[3] for r in zip(table["mu_s"], table["mu_d"], table["theta0_deg"], table["scenario"])}
    assert got[(0.3, 0.25, 45.0)] == "slide-at-start" and got[(0.3, 0.25, 60.0)] == "roll-until-r2"
    assert (out / "regime_map.png").exists()


def test_sweep_cli_over_a_geometry_axis_with_the_map_axes(tmp_path, capsys):
    out = tmp_path / "geo"
    assert main(["sweep", "--mu-s", "0.2,0.3", "--length", "0.3,0.41", "--map-axes", "mu_s,length", "--jobs", "1",
                 "--check", "2", "--out", str(out), "--dpi", "40"]) == 0
    report = capsys.readouterr().out
    assert "length = 0.3" in report and "accuracy vs event-driven" in report
    table = read_csv(out / "regime_map.csv")
    assert list(table)[:4] == ["mu_s", "mu_d", "theta0_deg", "length"] and len(table["mu_s"]) == 4
    assert _png_size(out / "regime_map.png")[0] > 200


def test_sweep_cli_on_a_dask_scheduler(tmp_path, capsys):
    distributed = pytest.importorskip("distributed")
    out = tmp_path / "dask"
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        argv = ["sweep", "--mu-s", "0.24:0.32:5", "--theta0-deg", "50,60", "--executor", "dask", "--scheduler",
                cluster.scheduler_address, "--check", "2", "--no-plot", "--out", str(out)]
        assert main(argv) == 0
    report = capsys.readouterr().out
    assert "10 computed" in report and "scenario 2/2" in report
    table = read_csv(out / "regime_map.csv")
    assert table["theta0_deg"].tolist() == [50.0] * 5 + [60.0] * 5


from nonsmooth_rod.rod.regime import _classify_chunk as _CLASSIFY_CHUNK  # noqa: E402

SMALL_SWEEP = ["sweep", "--mu-s", "0.2:0.3:8", "--check", "0", "--no-plot", "--quiet"]


def _sweep_table(out):
    table = read_csv(out / "regime_map.csv")
    return {k: v.tolist() for k, v in table.items()}


def _one_line(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    return err


def test_sweep_on_a_full_disk_ends_in_one_line_and_resumes(tmp_path, capsys, monkeypatch):
    import builtins
    import errno

    from nonsmooth_rod.studies import runner

    clean, out = tmp_path / "clean", tmp_path / "full"
    assert main(SMALL_SWEEP + ["--jobs", "1", "--out", str(clean)]) == 0
    real_open = builtins.open

    class FillingDisk:  # the map's appends: three rows fit, then the disk is full
        def __init__(self, fh):
            self.fh, self.rows = fh, 0

        def write(self, text):
            self.rows += 1
            if self.rows > 3:
                raise OSError(errno.ENOSPC, "No space left on device")
            return self.fh.write(text)

        def __getattr__(self, name):
            return getattr(self.fh, name)

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.fh.close()

    def open_on_a_full_disk(path, mode="r", *args, **kwargs):
        fh = real_open(path, mode, *args, **kwargs)
        return FillingDisk(fh) if str(path).endswith("regime_map.csv") and "a" in mode else fh

    monkeypatch.setattr(runner, "open", open_on_a_full_disk, raising=False)  # the sweeps' row sink
    assert main(SMALL_SWEEP + ["--jobs", "1", "--out", str(out)]) == 1
    assert _one_line(capsys) == f"nonsmooth-rod: cannot write {out / 'regime_map.csv'}: No space left on device"
    assert len(read_csv(out / "regime_map.csv")["mu_s"]) == 3
    monkeypatch.undo()
    assert main(SMALL_SWEEP + ["--jobs", "1", "--out", str(out)]) == 0  # resumes: the other five points
    assert _sweep_table(out) == _sweep_table(clean)


def _killed_at_the_fourth_point(base, settings, columns, chunk):
    import os
    import signal

    if any(abs(pt[0] - (0.2 + 3 * 0.1 / 7)) < 1e-12 for pt in chunk):
        os.kill(os.getpid(), signal.SIGKILL)  # the worker dies as under the OOM killer
    return _CLASSIFY_CHUNK(base, settings, columns, chunk)


def test_a_killed_sweep_worker_ends_the_sweep_in_one_line_and_resume_finishes_it(tmp_path, capsys, monkeypatch):
    import fcntl

    from nonsmooth_rod.rod import regime

    clean, out = tmp_path / "clean", tmp_path / "killed"
    assert main(SMALL_SWEEP + ["--jobs", "1", "--out", str(clean)]) == 0
    monkeypatch.setattr(regime, "_classify_chunk", _killed_at_the_fourth_point)  # the forked workers inherit it
    assert main(SMALL_SWEEP + ["--jobs", "2", "--out", str(out)]) == 1
    err = _one_line(capsys)
    assert err.startswith("nonsmooth-rod: a worker process died") and "run the same sweep again to resume" in err
    with open(out / ".sweep.lock", "a") as lock:  # free at once: no surviving worker holds it
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        fcntl.flock(lock, fcntl.LOCK_UN)
    monkeypatch.undo()
    assert main(SMALL_SWEEP + ["--jobs", "2", "--out", str(out)]) == 0
    assert _sweep_table(out) == _sweep_table(clean)
