"""`sweep SCENE.toml --axis ...` and `fit SCENE.toml --measured ... --free ...` from the command
line: files written, --json on stdout, and every bad input refused in one line with exit 2."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from nonsmooth_rod.cli import main

SCENES = Path(__file__).resolve().parents[2] / "examples" / "scenes"
LADDER, ROD = str(SCENES / "ladder.toml"), str(SCENES / "paper_rod.toml")


def test_sweep_of_a_scene_writes_its_map(tmp_path, capsys):
    out = tmp_path / "m"
    code = main(["sweep", LADDER, "--axis", "contacts.foot.law.mu_s=0.2,0.4", "--axis", "contacts.top.law.mu_s=0,0.2",
                 "--set", "contacts.*.law.mu_d=0", "--outcome", "held,foot.first_slip", "--jobs", "1",
                 "--out", str(out)])
    assert code == 0
    header = (out / "map.csv").read_text().splitlines()[0].split(",")
    assert header == ["contacts.foot.law.mu_s", "contacts.top.law.mu_s", "regime", "status", "held",
                      "foot.first_slip", "message"]
    assert (out / "map.png").exists() and json.loads((out / "sweep.json").read_text())["counts"]["points"] == 4
    assert "points/s" in capsys.readouterr().out


def _events(tmp_path, text) -> str:
    path = tmp_path / "events.toml"
    path.write_text(text)
    return str(path)


EVENTS = '[[events]]\nkind = "impact"\ncontact = "B"\nt = 0.3752\nsigma = 0.001\n'


def test_fit_prints_json_and_writes_its_files(tmp_path, capsys):
    code = main(["fit", ROD, "--measured", _events(tmp_path, EVENTS), "--free", "contacts.A.law.mu_d=0:0.28",
                 "--out", str(tmp_path / "f"), "--json"])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["method"] == "event-driven" and summary["free"][0]["path"] == "contacts.A.law.mu_d"
    assert summary["free"][0]["identifiable"] and 0 <= summary["free"][0]["estimate"] <= 0.28
    assert abs(summary["residuals"][0]["residual"]) < 1e-3
    assert (tmp_path / "f" / "fit.json").exists() and (tmp_path / "f" / "fit.png").exists()


def test_fit_with_a_posterior_writes_the_chain_summary(tmp_path, capsys):
    pytest.importorskip("emcee")
    ball = str(SCENES / "bouncing_ball.toml")
    events = ('[[events]]\nkind = "impact"\ncontact = "floor"\nt = 0.4515\nsigma = 0.002\n'
              '[[events]]\nkind = "impact"\ncontact = "floor"\nt = 0.9045\nsigma = 0.002\n')
    code = main(["fit", ball, "--measured", _events(tmp_path, events), "--free", "contacts.floor.law.restitution",
                 "--set", "simulation.t_end=0.95", "--posterior", "--walkers", "4", "--posterior-steps", "8",
                 "--out", str(tmp_path / "f"), "--json", "--no-plot"])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    post = summary["posterior"]
    assert post["walkers"] == 4 and post["steps"] == 8 and post["samples"] == 4 * (8 - 2)
    key = post["free"][0]
    assert key["path"] == "contacts.floor.law.restitution" and 0 <= key["q16"] <= key["median"] <= key["q84"] <= 1
    # t2 = t1 (1 + 2e): the estimate (0.5016) and the chain (walkers within a few of its sd) agree
    assert abs(key["mean"] - summary["free"][0]["estimate"]) < 3 * summary["free"][0]["uncertainty"]
    assert json.loads((tmp_path / "f" / "fit.json").read_text())["posterior"]["walkers"] == 4


BAD_SWEEPS = [
    (["--axis", "contacts.nothing.law.mu_s=0.1:0.2:3"], "no entry named 'nothing'"),
    (["--axis", "title=1,2"], "not a number"),
    (["--axis", "contacts.foot.law.mu_s=0.1:0.2:0"], "the count N must lie in"),
    (["--axis", "contacts.foot.law.bogus=1,2"], "unknown key"),
    (["--axis", "contacts.foot.law.mu_s"], "expected PATH=START:STOP:N"),
    (["--axis", "contacts.foot.law.mu_s=0.1:0.2:3", "--mu-s", "0.3"], "option of the rod's sweep"),
    (["--axis", "contacts.foot.law.mu_s=0.1:0.2:3", "--g", "3"], "--g is an option of the rod's sweep"),
    (["--axis", "contacts.foot.law.mu_s=0.1:0.2:3", "--mass", "1"], "--mass is an option of the rod's sweep"),
    (["--axis", "contacts.foot.law.mu_s=0.5,0.6", "--outcome", "colour"], "not an outcome"),
    (["--axis", "contacts.foot.law.mu_s=0.5,0.6", "--map-axes", "gravity,contacts.foot.law.mu_s"], "not an axis"),
]


@pytest.mark.parametrize("extra,message", BAD_SWEEPS)
def test_bad_maps_are_refused_in_one_line(tmp_path, capsys, extra, message):
    assert main(["sweep", LADDER, *extra, "--jobs", "1", "--out", str(tmp_path / "m")]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1, err


def test_an_axis_without_a_scene_is_refused(capsys):
    assert main(["sweep", "--axis", "contacts.foot.law.mu_s=0.1,0.2"]) == 2
    assert "give SCENE.toml first" in capsys.readouterr().err


BAD_EVENTS = [
    ('[[events]]\nkind = "impact"\ncontact = "C"\nt = 0.3\nsigma = 0.001\n', "no contact named 'C'"),
    ('[[events]]\nkind = "bounce"\ncontact = "B"\nt = 0.3\nsigma = 0.001\n', "kind 'bounce'"),
    ('[[events]]\nkind = "impact"\ncontact = "B"\nt = 0.3\nsigma = 0\n', "sigma must be positive"),
    ('[[events]]\nkind = "impact"\ncontact = "B"\nt = 0.3\n', "missing sigma"),
    ('[[events]]\nkind = "impact"\ncontact = "B"\nt = "0.3"\nsigma = 0.001\n', "t must be a number"),
    ('[[events]]\nkind = "impact"\ncontact = "B"\nt = 0.3\nsigma = true\n', "sigma must be a number"),
    ('[[events]]\nkind = "impact"\ncontact = "B"\nt = -0.3\nsigma = 0.001\n', "t must be non-negative"),
    (EVENTS + EVENTS, "increasing times"),
]


@pytest.mark.parametrize("text,message", BAD_EVENTS)
def test_bad_measured_events_are_refused_in_one_line(tmp_path, capsys, text, message):
    assert main(["fit", ROD, "--measured", _events(tmp_path, text), "--free", "contacts.A.law.mu_d",
                 "--out", str(tmp_path / "f")]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1, err


BAD_TRAJECTORIES = [
    ("t,rod.x\nsigma,0.001\n0.0,0.1\n0.1,0.1\n", None),  # accepted: the control case
    ("t,rod.colour\nsigma,0.001\n0.0,0.1\n", "unknown column 'rod.colour'"),
    ("t,rod.x\nsigma,0.001\n0.1,0.1\n0.1,0.1\n", "strictly increasing"),
    ("t,rod.x\nsigma,-1\n0.0,0.1\n", "must be > 0"),
    ("t,rod.x\n0.0,0.1\n0.1,0.1\n", "line 2 must be 'sigma'"),
]


@pytest.mark.parametrize("text,message", BAD_TRAJECTORIES)
def test_bad_measured_trajectories_are_refused_in_one_line(tmp_path, capsys, text, message):
    from nonsmooth_rod.studies.measurements import read_measurements
    from nonsmooth_rod.validation import InputError

    path = tmp_path / "traj.csv"
    path.write_text(text)
    if message is None:
        m = read_measurements([path], ["rod"], ["A", "B"])
        assert m.count == 2 and m.sigma == {"rod.x": 0.001}
        return
    with pytest.raises(InputError, match=message.replace("(", r"\(")):
        read_measurements([path], ["rod"], ["A", "B"])


BAD_FREE = [
    (["--free", "contacts.Z.law.mu_s"], "no entry named 'Z'"),
    (["--free", "title"], "not a number"),
    (["--free", "contacts.A.law.mu_s=0.5:0.1"], "LO < HI"),
    ([], "name at least one scene key"),
    (["--free", "contacts.A.law.mu_d", "--posterior", "--walkers", "3"], "walkers must be an even number"),
    (["--free", "contacts.A.law.mu_d", "--posterior", "--posterior-steps", "1"], "steps must be at least 2"),
]


@pytest.mark.parametrize("extra,message", BAD_FREE)
def test_bad_free_keys_are_refused_in_one_line(tmp_path, capsys, extra, message):
    assert main(["fit", ROD, "--measured", _events(tmp_path, EVENTS), *extra, "--out", str(tmp_path / "f")]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1, err
