"""`nonsmooth-rod simulate`: files, summary schema, JSON mode and one-line errors."""
import json
import subprocess
import sys

import numpy as np
import pytest

from nonsmooth_rod.cli import main
from nonsmooth_rod.io import read_csv

COLUMNS = ["t", "theta", "theta_dot", "theta_ddot", "x_O", "x_O_dot", "x_O_ddot", "N", "T", "mode"]


def test_default_run_writes_table_files_and_figure(tmp_path, capsys):
    code = main(["simulate", "--out", str(tmp_path)])
    assert code == 0
    out = capsys.readouterr().out
    for word in ("stick", "slip-", "slip+", "impact of ball B", "t_r1"):
        assert word in out
    traj = read_csv(tmp_path / "trajectory.csv")
    assert list(traj) == COLUMNS
    assert set(traj["mode"]) == {"stick", "slip-", "slip+"}
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["schema"] == "nonsmooth-rod/summary/1"
    assert summary["params"]["mu_s"] == 0.28 and summary["params"]["mu_d"] == 0.20
    for key in ("theta0_deg", "restitution", "ball_radius", "mass", "xi", "inertia", "g", "length",
                "rod_diameter", "density"):
        assert key in summary["params"]
    assert summary["method"] == "event-driven" and summary["status"] == "ok"
    assert [p["mode"] for p in summary["phases"]] == ["stick", "slip-", "slip+"]
    assert summary["impact"]["t"] == pytest.approx(summary["phases"][-1]["t_end"])
    assert summary["rolling_hypothesis"]["T_over_N_max"] == pytest.approx(0.29, abs=0.005)
    assert summary["steps"] > 0 and summary["cpu_time_s"] >= 0
    png = (tmp_path / "figure.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 20_000
    assert not list(tmp_path.glob(".*.tmp"))  # atomic writes leave no temporaries


def test_json_mode_prints_only_the_summary(tmp_path, capsys):
    code = main(["simulate", "--mu-s", "0.4", "--mu-d", "0.3", "--json", "--no-plot", "--out", str(tmp_path)])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert [p["mode"] for p in summary["phases"]] == ["stick", "slip+"]
    assert not (tmp_path / "figure.png").exists()


def test_direct_mass_properties(tmp_path, capsys):
    code = main(["simulate", "--mass", "0.604", "--xi", "0.205", "--inertia", "0.022983", "--quiet",
                 "--no-plot", "--out", str(tmp_path)])
    assert code == 0
    assert capsys.readouterr().out == ""
    params = json.loads((tmp_path / "summary.json").read_text())["params"]
    assert params["length"] == pytest.approx(0.41)


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["--mu-s", "0.2", "--mu-d", "0.3"], "exceeds mu_s"),
        (["--mu-s", "nan"], "finite"),
        (["--mu-s", "abc"], "not a number"),
        (["--theta0-deg", "95"], "theta0-deg"),
        (["--restitution", "-0.1"], "restitution"),
        (["--mass", "-1", "--xi", "0.2", "--inertia", "0.02"], "--mass must be positive"),
        (["--mass", "1"], "go together"),
        (["--density", "0"], "density"),
        (["--method", "rk4"], "unknown method"),
        (["--method", "moreau-jean", "--h", "0"], "--h must be positive"),
        (["--method", "moreau-jean", "--h", "nan"], "--h: must be a finite number"),
        (["--method", "moreau-jean", "--solver", "magic"], "unknown --solver 'magic'; choose from: lemke, pgs, enum"),
        (["--method", "event-driven", "--solver", "magic"], "unknown --solver 'magic'"),
        (["--method", "hybrid", "--solver", "magic"], "unknown --solver 'magic'"),
        (["--method", "moreau-jean", "--theta", "0.3"], "gain energy"),
        (["--t-end", "-1"], "--t-end must be positive"),
        (["--bogus"], "unrecognized arguments"),
    ],
)
def test_bad_input_gives_one_line_and_exit_2(tmp_path, capsys, args, fragment):
    code = main(["simulate", "--no-plot", "--out", str(tmp_path), *args])
    assert code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("nonsmooth-rod: error:")
    assert fragment in err
    assert not (tmp_path / "summary.json").exists()


def test_console_script_runs_moreau_jean(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "nonsmooth_rod.cli", "simulate", "--method", "moreau-jean", "--h", "1e-3",
         "--json", "--no-plot", "--out", str(tmp_path)],
        capture_output=True, text=True, timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout)
    assert summary["method"] == "moreau-jean"
    assert [p["mode"] for p in summary["phases"]] == ["stick", "slip-", "slip+"]
    traj = read_csv(tmp_path / "trajectory.csv")
    # N and T are the step's impulses divided by h: N stays near the weight scale, positive.
    assert np.all(traj["N"][1:] > 0)


def test_tol_chooses_moreau_jeans_steps(tmp_path, capsys):
    """--tol: error control (docs/error_control.md); the impact of case 2 within it of the
    event-driven reference's 0.375302 s."""
    code = main(["simulate", "--method", "moreau-jean", "--tol", "1e-4", "--json", "--no-plot", "--out", str(tmp_path)])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert [p["mode"] for p in summary["phases"]] == ["stick", "slip-", "slip+"]
    assert summary["impact"]["t"] == pytest.approx(0.3753022758552653, abs=1e-4)
    assert summary["settings"]["tol"] == 1e-4 and summary["settings"]["h"] == 1e-2
    assert main(["simulate", "--method", "moreau-jean", "--tol", "0", "--no-plot", "--out", str(tmp_path / "b")]) == 2
