"""benchmarks/bench_scenes.py --quick runs and prints its table (timings are not asserted)."""
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_bench_scenes_quick_runs():
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    result = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "bench_scenes.py"), "--quick", "--only",
                             "ladder", "--no-compile-time"], capture_output=True, text=True, env=env, timeout=300)
    assert result.returncode == 0, result.stderr
    lines = [line for line in result.stdout.splitlines() if line.startswith("ladder")]
    assert [line.split()[2] for line in lines] == ["lemke", "pgs"]
    assert all(line.split()[-1] == "True" for line in lines)  # compiled
