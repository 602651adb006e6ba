"""`nonsmooth-rod run`: every shipped scene file through the CLI against its closed form, the files it
writes (and reads back), exit statuses and one-line errors."""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from nonsmooth_rod import toys
from nonsmooth_rod.cli import main
from nonsmooth_rod.io import read_csv
from nonsmooth_rod.result_files import SUMMARY_SCHEMA, load, restart, to_dataframe
from nonsmooth_rod.rod.hypotheses import rolling_hypothesis
from nonsmooth_rod.rod.problem import RodProblem

SCENES = Path(__file__).resolve().parents[2] / "examples" / "scenes"
H = 1e-3  # every shipped scene steps at h = 1e-3


def run(tmp_path, name, *extra, expect=0):
    out = tmp_path / name
    assert main(["run", str(SCENES / f"{name}.toml"), "--out", str(out), "--quiet", "--no-plot", *extra]) == expect
    return json.loads((out / "summary.json").read_text()), read_csv(out / "trajectory.csv")


def slope(cols, body, angle):
    """Displacement of a body's centre of mass along a line of inclination `angle`."""
    x, y = cols[f"{body}.x"], cols[f"{body}.y"]
    return (x - x[0]) * math.cos(angle) + (y - y[0]) * math.sin(angle)


def modes(summary, contact):
    return [p["mode"] for p in summary["phases"][contact]]


def test_every_shipped_scene_has_a_test():
    tested = {"bouncing_ball", "block_on_incline", "pushed_block", "disk_on_incline", "belt_oscillator",
              "rocking_block", "painleve_rod", "ladder", "ball_collisions", "paper_rod", "ball_off_table",
              "box_off_table", "pendulum_wall", "shaken_block", "dominoes",
              "woodpecker", "woodpecker_linearised",
              "slider_crank"}  # (the last three: tests/toys, file = toy to 1e-12)
    assert {p.stem for p in SCENES.glob("*.toml")} == tested


def test_box_off_table_pivots_where_the_moment_of_friction_is_no_longer_balanced(tmp_path):
    """Found contacts through the CLI: the block's back corner lifts (the pivot on the table's
    edge starts) when its centre of mass is μd h/2 before the edge, both contacts sliding."""
    s, c = run(tmp_path, "box_off_table")
    assert modes(s, "block.v1/table.side+") == ["slip+", "open"]
    assert modes(s, "block.v0/table.side+") == ["slip+", "open"]
    assert modes(s, "table.b/block.e0") == ["open", "slip+", "open"] and modes(s, "block.v3/floor") == ["open"]
    mu_d, height, x0, v0 = 0.2, 0.2, -0.25, 1.2
    a = mu_d * 9.81
    t_pivot = (v0 - math.sqrt(v0 * v0 - 2 * a * (-mu_d * height / 2 - x0))) / a
    assert s["phases"]["block.v0/table.side+"][0]["t_end"] == pytest.approx(t_pivot, abs=3 * H)
    assert c["block.y"][-1] < 0.5  # off the table (its top at 0.8 m)


def test_dominoes_topple_at_1_1_times_the_tipping_impulse_and_not_at_0_9(tmp_path):
    """The file's push is 1.1 J* (its comment's closed form, toys.Dominoes): the whole row falls;
    at 0.9 J* (d0's v scaled by 9/11) d0 rocks back and no other domino moves."""
    toy = toys.Dominoes(push_ratio=1.1)
    _, v0 = toy.initial_state()
    from nonsmooth_rod.scenefile import load_scene

    assert load_scene(SCENES / "dominoes.toml").v0[:3] == pytest.approx(v0[:3], rel=1e-8)
    _, c = run(tmp_path, "dominoes")
    assert all(c[f"d{k}.theta"][-1] < -math.atan2(0.005, 0.025) for k in range(20))
    scaled = [float(x) * 9 / 11 for x in v0[:3]]
    _, c = run(tmp_path, "dominoes", "--set", f"initial.d0.v=[{scaled[0]!r}, {scaled[1]!r}, {scaled[2]!r}]",
               "--set", "simulation.t_end=1.0")
    assert max(c["d0.theta"]) > 0.0 and min(c["d0.theta"]) > -math.atan2(0.005, 0.025)  # rocks, never tips
    assert np.abs(c["d1.theta"]).max() < 1e-12


def test_pendulum_striking_a_wall_rebounds_to_the_closed_form_angle(tmp_path):
    """Released horizontal about its pin, the rod strikes the wall at the bottom: ω⁺ = −e ω⁻ and
    it rises to acos(1 − e²) from the vertical (first order in h: 4.3e-4 relative at 1e-3)."""
    s, c = run(tmp_path, "pendulum_wall")
    (impact,) = s["impacts"]
    assert impact["contact"] == "tip"
    assert impact["v_after"]["rod"][2] / impact["v_before"]["rod"][2] == pytest.approx(-0.5, abs=1e-4)
    after = c["t"] > impact["t"]
    assert np.max(c["rod.theta"][after]) + math.pi / 2 == pytest.approx(math.acos(0.75), rel=1e-3)
    bottom = np.argmin(np.abs(c["rod.theta"][~after] + math.pi / 2))
    assert c["pivot.Fy"][bottom] == pytest.approx(2.5 * 9.81, rel=2e-2)  # m l ω² + m g at the bottom


def test_bouncing_ball_impact_times(tmp_path):
    s, _ = run(tmp_path, "bouncing_ball")
    ball = toys.BouncingBall()
    t1, t2 = ball.impact_times(2)
    assert s["impacts"][0]["t"] == pytest.approx(t1, abs=1e-9)  # gap crossing interpolated: 2e-12 measured
    assert s["impacts"][1]["t"] == pytest.approx(t2, abs=H)  # 5e-4 measured: O(h) after one impact
    assert s["impacts"][0]["v_before"]["ball"][1] == pytest.approx(-ball.impact_speed, rel=H)


def test_block_on_incline_holds_and_a_launched_block_stops(tmp_path):
    toy = toys.BlockOnIncline()
    s, c = run(tmp_path, "block_on_incline")
    assert toy.holds and modes(s, "left") == ["stick"] and modes(s, "right") == ["stick"]
    assert np.max(np.abs(slope(c, "block", toy.angle))) < 1e-12
    launched = toys.BlockOnIncline(v0=1.0)
    a = launched.angle
    s, c = run(tmp_path, "block_on_incline", f"--set=initial.block.v=[{math.cos(a)!r}, {math.sin(a)!r}, 0.0]")
    assert modes(s, "left") == ["slip+", "stick"]
    assert s["phases"]["left"][0]["t_end"] == pytest.approx(launched.stop_time, abs=H)
    np.testing.assert_allclose(slope(c, "block", a), launched.slope_position(c["t"]), atol=1e-5)  # 7e-7 m measured


def test_pushed_block_onset_and_slide(tmp_path):
    toy = toys.PushedBlock()
    s, c = run(tmp_path, "pushed_block")
    assert modes(s, "left") == ["stick", "slip+"]
    assert s["phases"]["left"][0]["t_end"] == pytest.approx(toy.onset_time, abs=H)
    t_end = c["t"][-1]
    np.testing.assert_allclose(c["block.x"], toy.position(c["t"]), atol=H * toy.velocity(t_end))


def test_disk_rolls_down_the_incline(tmp_path):
    toy = toys.DiskOnIncline()
    s, c = run(tmp_path, "disk_on_incline")
    assert toy.rolls and modes(s, "contact") == ["stick"]
    t = c["t"]
    np.testing.assert_allclose(slope(c, "disk", toy.angle), 0.5 * toy.slope_acceleration * t**2,
                               atol=1e-12, rtol=1e-9)
    np.testing.assert_allclose(c["disk.omega"], toy.angular_acceleration * t, atol=1e-9)


def test_belt_oscillator_stick_slip_times(tmp_path):
    toy = toys.BeltOscillator()
    s, _ = run(tmp_path, "belt_oscillator")
    left = s["phases"]["left"]
    assert modes(s, "left") == ["stick", "slip-", "stick"]
    assert left[0]["t_end"] == pytest.approx(toy.first_slip_time, abs=H)
    assert left[1]["t_end"] - left[1]["t_start"] == pytest.approx(toy.slip_time, abs=2 * H)


def test_rocking_block_first_impact(tmp_path):
    toy = toys.RockingBlock()
    s, _ = run(tmp_path, "rocking_block")
    first = s["impacts"][0]
    before, after = first["v_before"]["block"][2], first["v_after"]["block"][2]
    assert first["contact"] == "right"
    assert -before == pytest.approx(toy.first_impact_rate, rel=2 * H)  # 8e-4 measured
    assert after / before == pytest.approx(toy.ratio, rel=10 * H)  # end-of-step velocity: 6e-3 measured


def test_painleve_rod_stops_at_the_band_edge_with_exit_status_1(tmp_path, capsys):
    s, c = run(tmp_path, "painleve_rod", expect=1)
    assert s["status"] == "painleve" and not s["success"]
    assert c["rod.theta"][-1] == pytest.approx(toys.PainleveRod().painleve_band()[0], abs=1e-8)
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "painleve" in err


def test_ball_off_table_leaves_the_edge_at_the_rolling_closed_form(tmp_path):
    """A disk rolls off the end of a table segment, pivots on its edge and leaves it at
    cos φ* = (2 + (1 + k) v0²/(g R)) / (3 + k) (the file's comment derives it), within 3 steps."""
    h, k, v0, radius, g = 1e-4, 0.5, 0.5, 0.1, 9.81
    s, c = run(tmp_path, "ball_off_table", f"--set=simulation.moreau-jean.h={h}")
    assert modes(s, "edge") == ["stick", "open"]
    leaving = math.acos((2 + (1 + k) * v0**2 / (g * radius)) / (3 + k))
    t_open = s["phases"]["edge"][1]["t_start"]
    phi = np.arctan2(c["disk.x"], c["disk.y"])  # from the vertical through the table's end (0, 0)
    assert abs(np.interp(t_open, c["t"], phi) - leaving) <= 3 * h * math.sqrt(g * math.cos(leaving) / radius)
    after = c["t"] > t_open + 0.05
    assert np.all(c["edge.N"][after] == 0.0) and c["disk.y"][-1] < 0.0  # falls past the table


def test_ladder_statics_and_slide(tmp_path):
    s, c = run(tmp_path, "ladder")
    mg, beta = 9.81, math.radians(60)
    assert modes(s, "foot") == ["stick"] and np.max(np.abs(c["ladder.x"] - c["ladder.x"][0])) < 1e-12
    assert c["foot.N"][-1] == pytest.approx(mg, rel=1e-12)
    assert c["top.N"][-1] == pytest.approx(mg / (2 * math.tan(beta)), rel=1e-12)
    assert c["foot.T"][-1] == pytest.approx(-mg / (2 * math.tan(beta)), rel=1e-12)  # holds the foot in
    assert 1 / (2 * math.tan(beta)) > 0.2  # so mu_s = 0.2 cannot hold it
    s, c = run(tmp_path, "ladder", "--set", "contacts.foot.law.mu_s=0.2", "--set", "contacts.foot.law.mu_d=0.1")
    assert modes(s, "foot") == ["slip+"] and c["ladder.x"][-1] > c["ladder.x"][0] + 0.05


def test_ball_collision_swaps_velocities(tmp_path):
    row = toys.BallRow()
    s, c = run(tmp_path, "ball_collisions")
    assert s["impacts"][0]["t"] == pytest.approx(row.first_impact_time(), abs=1e-12)
    np.testing.assert_allclose([c["ball0.vx"][-1], c["ball1.vx"][-1]], row.two_ball_outcome(), atol=1e-12)


def test_paper_rod_starts_slipping_at_t_r1(tmp_path):
    s, _ = run(tmp_path, "paper_rod")
    t_r1 = rolling_hypothesis(RodProblem.paper()).t_r1
    assert modes(s, "A")[:2] == ["stick", "slip-"]
    assert s["phases"]["A"][0]["t_end"] == pytest.approx(t_r1, abs=H)
    assert s["impacts"][0]["contact"] == "B" and s["status"] == "ok"  # stop = "B" ended the run there


def test_files_columns_and_summary(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", str(SCENES / "belt_oscillator.toml"), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "start [s]" in printed and "slip-" in printed  # rich did not eat '[s]' as markup
    assert {p.name for p in out.iterdir()} == {"trajectory.csv", "summary.json", "scene.toml", "figure.png"}
    header = (out / "trajectory.csv").read_text().splitlines()[0].split(",")
    assert header == ["t", "block.x", "block.y", "block.theta", "block.vx", "block.vy", "block.omega",
                      "left.N", "left.T", "left.mode", "right.N", "right.T", "right.mode"]
    s = json.loads((out / "summary.json").read_text())
    assert s["schema"] == SUMMARY_SCHEMA and s["scene"]["contacts"] == ["left", "right"]
    assert set(s["provenance"]) == {"version", "command", "python", "numpy", "scipy", "numba", "created"}
    assert (out / "figure.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_json_mode_prints_only_the_summary(tmp_path, capsys):
    assert main(["run", str(SCENES / "disk_on_incline.toml"), "--out", str(tmp_path), "--json", "--no-plot"]) == 0
    assert json.loads(capsys.readouterr().out)["schema"] == SUMMARY_SCHEMA


def test_save_load_round_trip_and_restart(tmp_path):
    out = tmp_path / "bouncing_ball"
    run(tmp_path, "bouncing_ball", "--set", "contacts.floor.law.restitution=0.8")
    again = load(out)
    cols = read_csv(out / "trajectory.csv")
    np.testing.assert_array_equal(again.trajectory.q[:, 1], cols["ball.y"])
    assert again.scene_file.scene.contacts[0].law.impact.restitution == 0.8  # the override is kept
    df = to_dataframe(again)
    assert list(df.columns)[:3] == ["t", "ball.x", "ball.y"] and len(df) == len(cols["t"])
    # restart after the first impact: the next comes 2 e v1 / g later (e = 0.8)
    ball = toys.BouncingBall(restitution=0.8)
    later = restart(out, 0.6, t_end=1.5)
    assert later.t[0] == pytest.approx(0.6, abs=1e-12)
    assert later.message == "reached t_end = 1.5 s"  # the integrator ran 0.9 s: its clock is shifted back
    assert later.impacts[0].t == pytest.approx(ball.impact_times(2)[1], abs=3 * H)


@pytest.mark.parametrize("args, fragment", [
    (["run", "nope.toml"], "cannot read the scene file"),
    (["run", str(SCENES / "ladder.toml"), "--set", "contacts.foot.law.mu_d=0.9"], "contacts.foot.law.mu_d: 0.9 exceeds"),
    (["run", str(SCENES / "ladder.toml"), "--set", "contacts.knee.law.mu_s=1"], "no entry named 'knee'"),
    (["run", str(SCENES / "ladder.toml"), "--set", "simulation.moreau-jean.h=nan"], "simulation.moreau-jean.h"),
    (["animate", "nowhere"], "no summary.json"),
    (["run", str(SCENES / "ladder.toml"), "--out", __file__], "--out"),
])
def test_bad_input_is_one_line_and_exit_2(tmp_path, capsys, args, fragment):
    assert main(args + (["--out", str(tmp_path)] if args[0] == "run" and "--out" not in args else [])) == 2
    captured = capsys.readouterr()
    assert fragment in captured.err and captured.err.count("\n") == 1 and "Traceback" not in captured.err


def test_switching_method_by_set_takes_that_methods_own_options(tmp_path):
    s, c = run(tmp_path, "ladder", "--set", "simulation.method=event-driven")
    assert s["method"] == "event-driven" and s["options"]["rtol"] == 1e-10 and "h" not in s["options"]
    mg, beta = 9.81, math.radians(60)
    assert modes(s, "foot") == ["stick"]
    assert c["foot.N"][-1] == pytest.approx(mg, rel=1e-9)
    assert c["top.N"][-1] == pytest.approx(mg / (2 * math.tan(beta)), rel=1e-9)


def test_restart_of_a_pushed_block_sees_the_push_at_absolute_time(tmp_path):
    run(tmp_path, "pushed_block")
    toy = toys.PushedBlock()
    later = restart(tmp_path / "pushed_block", 0.6, t_end=1.0)
    assert later.t[0] == pytest.approx(0.6, abs=1e-12) and later.t[-1] == pytest.approx(1.0, abs=1e-12)
    # restarted from 0 the push would be 10 N/s · (t − 0.6) < μs m g: the block would stick again
    np.testing.assert_allclose(later.trajectory.q[:, 0], toy.position(later.t), atol=H * toy.velocity(1.0))


def _one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    return err


def test_run_and_simulate_never_overwrite_each_others_folder(tmp_path, capsys):
    """Both default to ./results: each refuses the other's folder in one line, --force replaces it."""
    out = tmp_path / "results"
    assert main(["simulate", "--t-end", "0.05", "--no-plot", "--quiet", "--out", str(out)]) == 0
    rod_summary = (out / "summary.json").read_text()
    assert main(["run", str(SCENES / "bouncing_ball.toml"), "--no-plot", "--quiet", "--out", str(out)]) == 2
    assert "holds the results of `nonsmooth-rod simulate`" in _one_error_line(capsys)
    assert (out / "summary.json").read_text() == rod_summary  # untouched
    assert main(["animate", str(out)]) == 2
    assert "`nonsmooth-rod plot " in _one_error_line(capsys)
    assert main(["run", str(SCENES / "bouncing_ball.toml"), "--no-plot", "--quiet", "--out", str(out), "--force"]) == 0
    assert json.loads((out / "summary.json").read_text())["schema"] == SUMMARY_SCHEMA
    assert main(["simulate", "--t-end", "0.05", "--no-plot", "--quiet", "--out", str(out)]) == 2
    assert "holds the results of `nonsmooth-rod run`" in _one_error_line(capsys)
    assert main(["plot", str(out)]) == 2
    assert f"`nonsmooth-rod animate {out}`" in _one_error_line(capsys)


def test_a_full_disk_ends_in_one_line_naming_the_file_with_exit_1(tmp_path, capsys, no_space_for):
    no_space_for("trajectory.csv")
    out = tmp_path / "full"
    assert main(["run", str(SCENES / "bouncing_ball.toml"), "--no-plot", "--quiet", "--out", str(out)]) == 1
    assert _one_error_line(capsys) == f"nonsmooth-rod: cannot write {out / 'trajectory.csv'}: No space left on device"
    assert main(["simulate", "--t-end", "0.05", "--no-plot", "--quiet", "--out", str(out)]) == 1
    assert _one_error_line(capsys).endswith("trajectory.csv: No space left on device")
    assert list(out.iterdir()) == []  # no temp file left behind
