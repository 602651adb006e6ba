"""Scene files with driven obstacles and bodies (`motion` tables) and a gravity vector: what they
build, and one line naming the key (CLI exit 2) for every malformed motion."""
import copy
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from nonsmooth_rod import toys
from nonsmooth_rod.model.motion import DrivenBody, Harmonic, Tabulated
from nonsmooth_rod.scenefile import apply_override, load_scene, parse_scene
from nonsmooth_rod.validation import InputError

SCENES = Path(__file__).resolve().parents[1] / "examples" / "scenes"

PLATE = {
    "schema": "nonsmooth-rod/scene/1",
    "bodies": [{"name": "ball", "shape": "ball", "radius": 0.05, "mass": 1.0},
               {"name": "shaker", "mass": 5.0, "inertia": 0.1,
                "motion": {"kind": "table", "times": [0.0, 1.0], "positions": [[0.0, 0.0], [0.0, 0.1]]}}],
    "lines": [{"name": "plate", "motion": {"kind": "harmonic", "amplitude": [0.0, 0.01], "frequency_hz": 8.0,
                                           "phase_deg": 90.0}}],
    "segments": [{"name": "step", "a": [1.0, 0.0], "b": [2.0, 0.0],
                  "motion": {"kind": "harmonic", "amplitude": [0.01, 0.0], "frequency_hz": 1.0}}],
    "contacts": [{"kind": "disk-on-line", "name": "floor", "body": "ball", "radius": 0.05, "line": "plate"},
                 {"kind": "disk-on-disk", "name": "top", "body_a": "ball", "body_b": "shaker", "radius_a": 0.05,
                  "radius_b": 0.2}],
    "gravity": [1.0, -9.0],
    "initial": {"ball": {"q": [0.0, 0.06, 0.0]}, "shaker": {"q": [0.0, -1.0, 0.0]}},
    "simulation": {"t_end": 0.01, "h": 1e-3},
}


def _with(path: str, value):
    data = copy.deepcopy(PLATE)
    apply_override(data, f"{path}={value}")
    return data


def test_the_shaken_block_file_builds_the_toys_scene():
    sf = load_scene(SCENES / "shaken_block.toml")
    block = toys.ShakenBlock(half_width=0.05, half_height=0.25, mu_s=0.8)
    assert [c.line for c in sf.scene.contacts] == [c.line for c in block.scene().contacts]
    q0, v0 = block.initial_state()
    np.testing.assert_allclose(sf.q0, q0, rtol=0, atol=1e-15)
    np.testing.assert_allclose(sf.v0, v0, rtol=1e-15)


def test_motions_and_the_gravity_vector_read_from_a_file():
    sf = parse_scene(copy.deepcopy(PLATE))
    assert sf.scene.gravity_vector == (1.0, -9.0) and list(sf.scene.weight[:2]) == [1.0, -9.0]
    assert sf.lines["plate"].motion == Harmonic((0.0, 0.01), 8.0, math.pi / 2)
    assert sf.segments["step"].motion == Harmonic((0.01, 0.0), 1.0)
    assert sf.scene.driven == [DrivenBody(1, Tabulated((0.0, 1.0), ((0.0, 0.0), (0.0, 0.1))))]
    assert parse_scene(_with("gravity", "9.81")).scene.gravity_vector == (0.0, -9.81)  # a number: g downward


BAD = [
    ("lines.plate.motion.kind", '"wobble"', "lines.plate.motion.kind: must be one of harmonic, table"),
    ("lines.plate.motion.amplitude", "[0, 0.01, 0.1]", "lines.plate.motion.amplitude: must be a list of 2 numbers"),
    ("lines.plate.motion.frequency_hz", "nan", "lines.plate.motion.frequency_hz: must be finite"),
    ("lines.plate.motion.frequency_hz", "-1", "lines.plate.motion.frequency_hz: must be non-negative"),
    ("lines.plate.motion.times", "[0, 1]", "lines.plate.motion.times: unknown key"),
    ("lines.plate.motion", "1", "lines.plate.motion: must be a table"),
    ("segments.step.motion.amplitude", '"big"', "segments.step.motion.amplitude: must be a list of 2 numbers"),
    ("bodies.shaker.motion.times", "[0, 0]", "bodies.shaker.motion.times: must increase strictly"),
    ("bodies.shaker.motion.times", "[1, 0]", "bodies.shaker.motion.times: must increase strictly"),
    ("bodies.shaker.motion.times", "[]", "bodies.shaker.motion.times: must be a non-empty list"),
    ("bodies.shaker.motion.times", "[0, inf]", "bodies.shaker.motion.times[1]: must be finite"),
    ("bodies.shaker.motion.positions", "[[0, 0]]", "bodies.shaker.motion.positions: must be a list of 2 positions"),
    ("bodies.shaker.motion.positions", "[[0, 0], [0, nan]]", "bodies.shaker.motion.positions[1][1]: must be finite"),
    ("bodies.shaker.motion.positions", "[[0, 0, 0, 0], [0, 0, 0, 0]]",
     "bodies.shaker.motion.positions[0]: must be a list of 2 numbers"),
    ("lines.plate.motion.frequency_hz", "1e200", "lines.plate.motion: motion amplitude × (2π frequency_hz)² overflows"),
    ("gravity", "[0, 1, 2]", "gravity: must be a list of 2 numbers"),
    ("gravity", "[0, inf]", "gravity[1]: must be finite"),
    ("gravity", "-9.81", "gravity: must be non-negative"),
]


@pytest.mark.parametrize("path, value, message", BAD, ids=[f"{p}={v}" for p, v, _ in BAD])
def test_bad_motions_are_one_line_naming_the_key(path, value, message):
    with pytest.raises(InputError) as err:
        parse_scene(_with(path, value), source="my.toml")
    text = str(err.value)
    assert text.startswith("my.toml: ") and message in text and "\n" not in text, text


def test_a_bad_motion_exits_2_with_one_line_and_other_methods_refuse_driven_scenes(tmp_path):
    scene = tmp_path / "bad.toml"
    text = (SCENES / "shaken_block.toml").read_text()
    scene.write_text(text.replace('kind = "harmonic"', 'kind = "shake"'))
    run = subprocess.run([sys.executable, "-m", "nonsmooth_rod.cli", "run", str(scene), "--out", str(tmp_path / "o")],
                         capture_output=True, text=True)
    assert run.returncode == 2 and "lines.floor.motion.kind: must be one of harmonic, table" in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1
    for method in ("event-driven", "regularized"):
        with pytest.raises(InputError, match=rf"method '{method}' does not handle driven obstacles or bodies "
                                             r"\(contact 'left' moves by a prescribed motion\)"):
            from nonsmooth_rod.scenefile import simulate_scene

            sf = load_scene(SCENES / "shaken_block.toml", [f'simulation.method="{method}"'])
            simulate_scene(sf)


def test_a_run_without_a_file_describes_its_motions_as_the_file_would():
    import nonsmooth_rod as nr
    from nonsmooth_rod.result_files import scene_description

    sf = parse_scene(copy.deepcopy(PLATE))
    result = nr.simulate(sf.scene, sf.q0, sf.v0, 0.002, h=1e-3)
    data = scene_description(result)
    assert data["gravity"] == (1.0, -9.0)
    assert data["lines"][0]["motion"] == {"kind": "harmonic", "amplitude": [0.0, 0.01], "frequency_hz": 8.0,
                                          "phase_deg": pytest.approx(90.0)}
    assert data["bodies"][1]["motion"] == PLATE["bodies"][1]["motion"] and "motion" not in data["bodies"][0]


SPLINE = {"kind": "table", "times": [0.0, 0.5, 1.0, 2.0], "positions": [[0.0, 0.0], [0.0, 0.1], [0.1, 0.0], [0.0, 0.0]],
          "interpolation": "spline"}


def test_a_spline_table_reads_from_a_file_and_is_described_as_the_file_would():
    import nonsmooth_rod as nr
    from nonsmooth_rod.result_files import scene_description

    data = copy.deepcopy(PLATE)
    data["bodies"][1]["motion"] = copy.deepcopy(SPLINE)
    sf = parse_scene(data)
    assert sf.scene.driven == [DrivenBody(1, Tabulated(SPLINE["times"], SPLINE["positions"], "spline"))]
    assert parse_scene(_with("bodies.shaker.motion.interpolation", '"linear"')).scene.driven[0].motion.interpolation \
        == "linear"
    result = nr.simulate(sf.scene, sf.q0, sf.v0, 0.002, h=1e-3)
    assert scene_description(result)["bodies"][1]["motion"] == SPLINE


SPLINE_BAD = [
    ("bodies.shaker.motion.interpolation", '"cubic"',
     "bodies.shaker.motion.interpolation: must be one of linear, spline; got 'cubic'"),
    ("bodies.shaker.motion.interpolation", "3", "bodies.shaker.motion.interpolation: must be a string"),
    ("bodies.shaker.motion.interpolation", '"spline"',
     "bodies.shaker.motion: a spline motion table needs at least 4 rows (not-a-knot cubic), got 2"),
    ("lines.plate.motion.interpolation", '"spline"', "lines.plate.motion.interpolation: unknown key"),
]


@pytest.mark.parametrize("path, value, message", SPLINE_BAD, ids=[f"{p}={v}" for p, v, _ in SPLINE_BAD])
def test_a_bad_interpolation_is_one_line_naming_the_key(path, value, message):
    with pytest.raises(InputError) as err:
        parse_scene(_with(path, value), source="my.toml")
    text = str(err.value)
    assert text.startswith("my.toml: ") and message in text and "\n" not in text, text


def test_a_bad_interpolation_exits_2_with_one_line(tmp_path, capsys):
    from nonsmooth_rod.cli import main

    scene = tmp_path / "bad.toml"
    text = (SCENES / "shaken_block.toml").read_text()
    scene.write_text(text.replace('{ kind = "harmonic", amplitude = [0.02, 0.0], frequency_hz = 2.0, phase_deg = 0.0 }',
                                  '{ kind = "table", times = [0, 1], positions = [[0, 0], [0.1, 0]], '
                                  'interpolation = "cubic" }'))
    assert main(["run", str(scene), "--out", str(tmp_path / "o"), "--no-plot", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "lines.floor.motion.interpolation: must be one of linear, spline" in err
    assert len(err.strip().splitlines()) == 1
