"""benchmarks/bench_sweep.py --quick runs and reports sane numbers (no speed is asserted here)."""
from __future__ import annotations

import math
from pathlib import Path
from scripts import load_script

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_sweep.py"


def test_bench_sweep_quick(capsys):
    bench = load_script(BENCH)
    report = bench.main(["--quick", "--skip-map"])
    assert report["yardstick_us"] > 0
    # The event-driven reference is far dearer per point than the compiled Moreau–Jean path.
    per = report["per_point_ms"]
    assert per["event-driven"] > per["moreau-jean h=1e-3"] > 0 and per["moreau-jean h=2e-3"] > 0
    for entry in report["simulate_ratio"].values():
        assert math.isfinite(entry["ratio"]) and entry["ratio"] >= 0.5
    assert "simulate() at h = 0.001" in capsys.readouterr().out
