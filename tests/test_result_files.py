"""save / load / to_dataframe of any result, also one made in Python without a scene file."""
import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod import toys
from nonsmooth_rod.result_files import load, restart, save, to_dataframe
from nonsmooth_rod.validation import InputError


def test_a_python_made_result_round_trips_bit_for_bit(tmp_path):
    toy = toys.RockingBlock()
    result = nr.simulate(toy.scene(), *toy.initial_state(), 0.4, h=1e-3)
    save(result, tmp_path)
    again = load(tmp_path)
    for field in ("t", "q", "v", "normal_force", "tangential_force"):
        np.testing.assert_array_equal(getattr(again.trajectory, field), getattr(result.trajectory, field))
    assert again.trajectory.modes.tolist() == [[str(m) for m in row] for row in result.trajectory.modes]
    assert again.contact_names == result.contact_names and again.status == result.status
    assert [(i.t, i.contact) for i in again.impacts] == [(i.t, i.contact) for i in result.impacts]
    np.testing.assert_array_equal(again.impacts[0].v_after, result.impacts[0].v_after)
    assert {c: [p.as_dict() for p in ps] for c, ps in again.phases.items()} == \
        {c: [p.as_dict() for p in ps] for c, ps in result.phases.items()}
    assert list(to_dataframe(again).columns[:4]) == ["t", "body0.x", "body0.y", "body0.theta"]
    assert again.scene_file is None
    with pytest.raises(InputError, match="restart needs the scene"):
        restart(again, 0.1)


def test_load_refuses_a_folder_of_something_else(tmp_path):
    (tmp_path / "summary.json").write_text('{"schema": "nonsmooth-rod/summary/1"}')
    with pytest.raises(InputError, match=r"holds the results of `nonsmooth-rod simulate` .*plot"):
        load(tmp_path)


def _ball_run(t_end, name="ball"):
    ball = toys.BouncingBall()
    scene = ball.scene()
    scene = nr.Scene([nr.RigidBody(b.mass, b.inertia, name=name) for b in scene.bodies], scene.contacts,
                     gravity=scene.gravity)
    return nr.simulate(scene, *ball.initial_state(), t_end, h=1e-3, solver="lemke")


def test_a_folder_mixed_by_a_killed_run_is_refused_in_one_line(tmp_path):
    """Killed between trajectory.csv and summary.json: the new trajectory sits with the old
    summary. Each save gets its own run id, and load refuses the pair."""
    first, second = tmp_path / "first", tmp_path / "second"
    ids = {save(_ball_run(0.2), first)["run_id"], save(_ball_run(0.3), second)["run_id"]}
    assert len(ids) == 2 and all(len(i) == 32 for i in ids)
    load(first)  # consistent: loads
    (first / "trajectory.csv").write_bytes((second / "trajectory.csv").read_bytes())
    with pytest.raises(InputError, match=r"mixed results: trajectory.csv is not the file summary.json") as err:
        load(first)
    assert "\n" not in str(err.value)


def test_the_next_save_removes_a_killed_runs_temp_files_but_not_a_live_ones(tmp_path):
    import fcntl

    stale = tmp_path / ".trajectory.csv.k1ll3d_x.tmp"
    stale.write_bytes(b"0" * 100_000)  # a killed writer: nobody holds its lock
    stale_gif = tmp_path / ".animation.gif.k1ll3d_y.tmp.gif"  # the GIF writer's temporary keeps .gif
    stale_gif.write_bytes(b"GIF89a")
    live = tmp_path / ".summary.json.wr1t1ng_.tmp"
    live.write_text("{")
    mine = tmp_path / ".notes.txt"  # not one of our temporary names
    mine.write_text("keep")
    with open(live, "rb") as holder:
        fcntl.flock(holder, fcntl.LOCK_EX)  # another run writing it right now
        save(_ball_run(0.1), tmp_path)
    assert not stale.exists() and not stale_gif.exists() and live.exists() and mine.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == [".notes.txt", ".summary.json.wr1t1ng_.tmp",
                                                          "summary.json", "trajectory.csv"]


def test_a_full_disk_names_the_file_and_leaves_no_temp(tmp_path, no_space_for):
    from nonsmooth_rod.io import OutputError

    no_space_for("trajectory.csv", "summary.json")
    with pytest.raises(OutputError, match=r"^cannot write .*trajectory.csv: No space left on device$"):
        save(_ball_run(0.1), tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_flat_api_results_keep_body_names_and_describe_the_scene(tmp_path):
    result = _ball_run(0.2, name="A")
    summary = save(result, tmp_path)
    assert list(to_dataframe(result).columns[:3]) == ["t", "A.x", "A.y"]
    assert (tmp_path / "trajectory.csv").read_text().startswith("t,A.x,A.y,A.theta,A.vx,A.vy,A.omega,")
    assert summary["scene"]["bodies"] == ["A"]
    params, ball = summary["params"], toys.BouncingBall()
    assert params["bodies"] == [{"name": "A", "mass": ball.mass, "inertia": ball.scene().bodies[0].inertia}]
    assert params["contacts"][0]["body"] == "A" and params["contacts"][0]["kind"] == "disk-on-line"
    assert params["initial"]["A"]["q"] == list(ball.initial_state()[0])
    assert summary["options"] == {"h": 1e-3, "solver": "lemke", "t0": 0.0, "t_end": 0.2, "save_every": None,
                                  "stop": None}
    assert load(tmp_path).trajectory.q.shape[1] == 3


def test_repeated_body_names_fall_back_to_numbered_columns():
    body = nr.RigidBody(1.0, 0.01)  # named "body", twice
    line = nr.Line()
    contacts = [nr.DiskOnLine(i, (0.0, 0.0), line, 0.1, nr.ContactLaw.of(0.3), f"c{i}") for i in (0, 1)]
    result = nr.simulate(nr.Scene([body, body], contacts), [0, 0.1, 0, 1, 0.1, 0], [0] * 6, 0.01, h=1e-3)
    assert list(to_dataframe(result).columns[1:8:6]) == ["body0.x", "body1.x"]


def test_a_flat_api_run_with_a_segment_describes_it_in_the_scene_file_layout(tmp_path):
    import json

    table = nr.Segment((-1.0, 0.0), (0.0, 0.0), name="table")
    scene = nr.Scene([nr.RigidBody(1.0, 0.005)], [nr.DiskOnSegment(0, (0.0, 0.0), table, 0.1, name="edge"),
                                                  nr.PointOnSegment(0, (0.0, -0.1), table, name="low"),
                                                  nr.SegmentEndOnEdge(0, (-0.1, -0.1), (0.1, -0.1), table, "b",
                                                                      name="rim")])
    result = nr.simulate(scene, np.array([-0.5, 0.2, 0.0]), np.zeros(3), 0.01, "moreau-jean", h=1e-3)
    result.save(tmp_path / "out")
    params = json.loads((tmp_path / "out" / "summary.json").read_text())["params"]
    assert params["segments"] == [{"name": "table", "a": [-1.0, 0.0], "b": [0.0, 0.0]}]
    kinds = [(c["kind"], c["segment"], c.get("radius")) for c in params["contacts"]]
    assert kinds == [("disk-on-segment", "table", 0.1), ("point-on-segment", "table", None),
                     ("segment-end-on-edge", "table", None)]
    assert params["contacts"][2]["edge_start"] == [-0.1, -0.1] and params["contacts"][2]["end"] == "b"
