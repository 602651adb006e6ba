"""benchmarks/bench_stick_decisions.py with one repeat: every scene's row, with the predictions a
run makes — one on the rod (its one break-away), none on the belt oscillator (its statically
indeterminate stick is declined by the compiled mode solve) nor on a 50-step block run (timings
are not asserted)."""
from pathlib import Path

from scripts import load_script

ROOT = Path(__file__).resolve().parents[2]


def test_one_repeat_prints_every_scene_and_its_predictions(capsys):
    assert load_script(ROOT / "benchmarks" / "bench_stick_decisions.py").main(["--repeats", "1"]) == 0
    rows = [line.strip("|").split("|") for line in capsys.readouterr().out.splitlines()[2:]]
    assert [int(r[-1]) for r in rows] == [1, 1, 0, 0]
    assert all(float(r[1]) > 0 and float(r[2]) > 0 for r in rows)
