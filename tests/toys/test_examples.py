"""Every toy example runs as `python examples/NAME.py --out DIR` would and writes its figure;
the numbers it prints agree with the closed forms it quotes."""
import re
from pathlib import Path

import pytest
from scripts import load_script

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
NAMES = sorted(p.stem for p in EXAMPLES.glob("*.py"))


def _load(name):
    return load_script(EXAMPLES / f"{name}.py")


def test_every_toy_has_an_example():
    assert {"bouncing_ball", "block_on_incline", "pushed_block", "disk_on_incline", "belt_stick_slip",
            "rocking_block", "painleve_rod", "ball_collisions"} <= set(NAMES)


# What each example must print: its measured agreement with the closed form.
PRINTED = {
    "ball_collisions": [r"cradle, gaps 0 m: Moreau-Jean \[-0.33333333  0.66666667  0.66666667\]",
                        r"cradle, gaps 0.01 m: Moreau-Jean \[0. 0. 1.\]"],
    "bouncing_ball": [r"event-driven: 1\d impacts, status 'zeno', max impact-time error \d\.\de-1[45] s"],
    "block_on_incline": [r"max \|a − closed form\| = \d\.\de-1[3-6] m/s²"],
    "pushed_block": [r"event-driven: onset 0\.490500 s"],
    "disk_on_incline": [r"max relative acceleration error \d\.\de-1[3-6]"],
    "belt_stick_slip": [r"event-driven: first slip error [-+]\d\.\d\de-1\d s"],
    "rocking_block": [r"event-driven: ratios 0\.850000, 0\.850000, 0\.850000"],
    "painleve_rod": [r"event-driven: status 'painleve' at t = 0\.11444\d s, θ = 37\.3773\d\d°"],
    # within a step of the closed form
    "shaken_block": [r"rocks first at 0\.053\d+ s, closed form 0\.053341 s \(error [-+]\d\.\de-0[5-9] s\)"],
}


@pytest.mark.parametrize("name", NAMES)
def test_example_writes_its_figure_and_reports(name, tmp_path, capsys):
    module = _load(name)
    assert module.__doc__ and f"python examples/{name}.py" in module.__doc__
    module.main(["--out", str(tmp_path)])
    figure = tmp_path / f"{name}.png"
    assert figure.stat().st_size > 20_000
    out = capsys.readouterr().out
    assert f"wrote {figure}" in out
    for pattern in PRINTED.get(name, []):
        assert re.search(pattern, out), (pattern, out)
