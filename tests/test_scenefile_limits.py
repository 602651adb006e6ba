"""Scene files bounded: nesting depth, integer size, names, the length of error messages, the
time a table takes to load; and the options of a file checked as the library checks them
(issue 29's input cases, each a test, through `nonsmooth-rod run` where the CLI is the point)."""
from __future__ import annotations

import json
import time
from pathlib import Path

import pytest

from nonsmooth_rod.cli import main
from nonsmooth_rod.scenefile import load_scene
from nonsmooth_rod.validation import InputError

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "scenes"
BALL = (EXAMPLES / "bouncing_ball.toml").read_text()


def refused(tmp_path, text: str, suffix: str = ".toml", sets=()) -> str:
    """The one line `nonsmooth-rod run` prints when it refuses the file (exit status 2)."""
    path = tmp_path / f"scene{suffix}"
    path.write_text(text)
    argv = ["run", str(path), "--out", str(tmp_path / "out"), "--no-plot", "--quiet"]
    for assignment in sets:
        argv += ["--set", assignment]
    import contextlib
    import io

    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main(argv)
    lines = err.getvalue().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("nonsmooth-rod: error: "), err.getvalue()[:500]
    return lines[0]


def test_deeply_nested_toml_is_one_line(tmp_path):
    assert "nested too deep" in refused(tmp_path, "x = " + "[" * 5000 + "]" * 5000)


def test_deeply_nested_json_is_one_line(tmp_path):
    assert "nested too deep" in refused(tmp_path, '{"x": ' + "[" * 100_000 + "]" * 100_000 + "}", ".json")


def test_nesting_that_parses_is_still_bounded(tmp_path):
    line = refused(tmp_path, BALL.replace('title = "', 'description = ' + "[" * 40 + "]" * 40 + '\ntitle = "', 1))
    assert "description[0]" in line and "nested more than 16 levels" in line


@pytest.mark.parametrize("suffix", [".toml", ".json"])
def test_a_400_digit_integer_is_one_line(tmp_path, suffix):
    digits = "1" * 400
    if suffix == ".toml":
        line = refused(tmp_path, BALL, sets=[f"simulation.moreau-jean.h={digits}"])
    else:
        data = load_scene(EXAMPLES / "bouncing_ball.toml").data
        text = json.dumps(data).replace('"h": 0.001', f'"h": {digits}')
        line = refused(tmp_path, text, suffix)
    assert "simulation.moreau-jean.h" in line and "integer too large" in line and len(line) < 300


def test_a_name_ending_in_a_newline_is_refused(tmp_path):
    line = refused(tmp_path, BALL.replace('name = "floor"', 'name = "floor\\n"', 1))
    assert "contacts[0].name" in line and "\\n" in line


def test_a_huge_bad_value_is_quoted_by_a_short_prefix(tmp_path):
    huge = "x" * 20_000_000
    started = time.perf_counter()
    line = refused(tmp_path, BALL, sets=[f'gravity="{huge}"'])
    assert "gravity" in line and len(line) < 300
    assert time.perf_counter() - started < 20  # was 21 s for a 31 MB line


@pytest.mark.parametrize("assignment, fragment", [
    ('simulation.moreau-jean.h="1e-3"', "h (step size) must be a number, got '1e-3'"),
    ("simulation.moreau-jean.h=true", "h (step size) must be a number, got True"),
    ("simulation.moreau-jean.h=1000000000000000000000000000000", "integer too large"),
    ('simulation.moreau-jean.allow_energy_gain="false"', "allow_energy_gain must be true or false"),
    ('simulation.moreau-jean.solver_options={tol="x"}', "solver_options.tol must be a number"),
    ("simulation.moreau-jean.solver_options={max_iter=1e30}", "solver_options.max_iter must be a whole number"),
    ("simulation.moreau-jean.solver_options={max_iter=nan}", "solver_options.max_iter must be a whole number"),
    ("simulation.moreau-jean.solver_options=[1,2]", "solver_options must be a table"),
    ("simulation.event-driven.method=Radau", "simulation.event-driven.method: unknown key"),
    ("simulation.regularized.stiffness=1e300", "stiffness must lie in [1, 1e+15]"),
])
def test_options_of_a_file_are_refused_by_the_cli_in_one_line(tmp_path, assignment, fragment):
    sets = [assignment]
    if "regularized" in assignment:
        sets.append("simulation.method=regularized")
    assert fragment in refused(tmp_path, BALL, sets=sets)


def test_event_driven_ode_method_from_a_file_runs(tmp_path):
    path = tmp_path / "ball.toml"
    path.write_text(BALL)
    code = main(["run", str(path), "--out", str(tmp_path / "out"), "--no-plot", "--quiet",
                 "--set", "simulation.method=event-driven", "--set", "simulation.event-driven.ode_method=Radau",
                 "--set", "simulation.t_end=0.2"])
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert code == 0 and summary["status"] == "ok" and summary["options"]["ode_method"] == "Radau"


def test_a_tabulated_force_loads_in_linear_time(tmp_path):
    # 10⁵ rows: quadratic loading (16 000 rows took 30 s) would take ~20 minutes
    base = load_scene(EXAMPLES / "pushed_block.toml").data
    n = 100_000
    base["forces"] = [{"kind": "tabulated", "name": "push", "body": "block",
                       "times": [k * 1e-3 for k in range(n)], "forces": [[1.0, 0.5]] * n}]
    path = tmp_path / "table.json"
    path.write_text(json.dumps(base))
    started = time.perf_counter()
    scene_file = load_scene(path)
    assert time.perf_counter() - started < 15
    force = scene_file.scene.forces[0]
    assert len(force.times) == n and force.forces[-1] == (1.0, 0.5)


def test_a_bad_row_of_a_table_is_named_once():
    data = load_scene(EXAMPLES / "pushed_block.toml").data
    data["forces"] = [{"kind": "tabulated", "name": "push", "body": "block", "times": [0.0, 1.0, 2.0],
                       "forces": [[1.0, 0.5], [1.0, "x"], [0.0, 0.0]]}]
    from nonsmooth_rod.scenefile import parse_scene

    with pytest.raises(InputError) as err:
        parse_scene(data, source="my.json")
    assert str(err.value) == "my.json: forces.push.forces[1][1]: must be a number, got 'x'"
