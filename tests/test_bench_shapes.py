"""benchmarks/bench_shapes.py --quick: the tower with found contacts runs the very run of the tower
with the touching contacts declared by hand, and holds (no speed is asserted here)."""
from __future__ import annotations

import re
from pathlib import Path
from scripts import load_script

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_shapes.py"


def test_bench_shapes_quick(capsys):
    bench = load_script(BENCH)
    assert bench.main(["--quick", "--boxes", "3"]) == 0  # 0: the two runs agree to 1e-12 m
    out = capsys.readouterr().out
    creeps = [float(x) for x in re.findall(r"creep ([0-9.e+-]+) m", out)]
    assert len(creeps) == 2 and max(creeps) < 1e-10
    assert "finding the contacts costs" in out


def test_bench_shapes_peers_quick(capsys):
    """--peers --quick: the tower, the dominoes and a heap of 20 boxes, ours (and the peers when
    installed), each of ours with its deepest overlap — under a step of travel (1 ms) at the speed
    of a fall from the heap's top layer (1.5 m)."""
    bench = load_script(BENCH)
    assert bench.main(["--peers", "--quick"]) == 0
    out = capsys.readouterr().out
    overlaps = [float(x) for x in re.findall(r"ok, deepest overlap ([0-9.e+-]+) m", out)]
    assert len(overlaps) == 3 and max(overlaps) < 1e-3 * (2 * 9.81 * 1.5) ** 0.5, out
