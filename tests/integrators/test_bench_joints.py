"""benchmarks/bench_joints.py --quick: a double pendulum's joints stay at round-off (the full run,
10⁶ steps, is the issue's check: docs/joints.md)."""
from pathlib import Path
from scripts import load_script

ROOT = Path(__file__).resolve().parents[2]


def _bench():
    return load_script(ROOT / "benchmarks" / "bench_joints.py")


def test_quick_run_keeps_the_joints_at_round_off(capsys):
    assert _bench().main(["--quick"]) == 0
    out = capsys.readouterr().out
    drift = float(out.split("largest joint violation over ")[1].split(": ")[1].split(" m")[0])
    assert drift < 1e-13  # round-off of coordinates of order 1 m, far inside the 1e-9 limit
    # first order in h: 0.43 h relative (docs/joints.md), so 4.3e-5 at h = 1e-4, above the closed form
    error = float(out.split("relative error ")[1].split(" ")[0])
    assert 1e-5 < error < 1e-4
