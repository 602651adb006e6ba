"""benchmarks/bench_woodpecker.py --quick prints the toy's cycle next to Siconos' and the
three-coordinate models' (the numbers themselves are tested in tests/toys/test_woodpecker.py)."""
from __future__ import annotations

import re
from pathlib import Path
from scripts import load_script

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_woodpecker.py"


def test_bench_woodpecker_quick(capsys):
    bench = load_script(BENCH)
    assert bench.main(["--quick"]) == 0
    out = capsys.readouterr().out
    periods = [float(p) for p in re.findall(r"period ([0-9.]+) s", out)]
    assert len(periods) == 5
    siconos, toy, toy_linearised, linearised, exact = periods
    assert abs(linearised - siconos) < 1e-3 and abs(toy - exact) < 2e-3 and exact < 0.95 * siconos
    assert abs(toy_linearised - siconos) < 1e-2 * siconos and abs(toy_linearised - linearised) < 1e-2 * linearised
    assert re.search(r"toy linearised.*cycle beak upper lower lower upper", out)
    assert "cycle beak upper lower lower upper" in out and "cycle beak lower lower" in out
