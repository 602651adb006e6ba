"""benchmarks/bench_solvers.py --quick runs and prints both tables (timings are not asserted)."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

ROOT = Path(__file__).resolve().parents[2]


def test_bench_solvers_quick_runs():
    import nonsmooth_rod

    # the copy this process imports (installed or src/): another copy would compile the kernels again
    env = dict(os.environ, PYTHONPATH=str(Path(nonsmooth_rod.__file__).resolve().parents[1]))
    result = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "bench_solvers.py"), "--quick"],
                            capture_output=True, text=True, timeout=300, env=env)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert any(line.startswith("pgs ") for line in lines)
    table = lines[lines.index(next(line for line in lines if line.startswith("pgs sweep on a row"))) + 2:]
    assert [int(line.split()[0]) for line in table] == [1, 3, 9, 49, 199]
