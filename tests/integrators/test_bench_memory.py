"""benchmarks/bench_memory.py --quick: the peak memory of a run follows what it keeps, near the
driver's estimate, and a stop at 5 % of t_end costs a small part of the whole run."""
import importlib.util
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _bench_memory():
    spec = importlib.util.spec_from_file_location("bench_memory", ROOT / "benchmarks" / "bench_memory.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _library_case_in_a_fresh_process(steps, save_every) -> dict:
    """bench_memory.library_case in a process of its own: in this one, memory that earlier tests
    freed is reused by the allocator and hides the run's growth."""
    import json
    import os
    import subprocess

    code = (f"import importlib.util, json, sys; spec = importlib.util.spec_from_file_location('b', {str(ROOT / 'benchmarks' / 'bench_memory.py')!r}); "
            "b = importlib.util.module_from_spec(spec); spec.loader.exec_module(b); "
            f"print(json.dumps(b.library_case({steps}, {save_every!r})))")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.splitlines()[-1])


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_peak_memory_follows_what_is_kept_and_a_stop_ends_early():
    bench = _bench_memory()
    every, thinned = (_library_case_in_a_fresh_process(200_000, save_every) for save_every in (None, 0.1))
    assert thinned["samples"] == 201 and every["samples"] == 200_001
    # thinning while running: the peak follows the samples kept (the window of rows stays)
    assert thinned["growth"] < 0.6 * every["growth"]
    # the estimate within a generous band here (allocator noise on 20 MB; 20 % at 1e6–1e7 steps)
    for case in (every, thinned):
        assert 0.5 < case["estimate"] / case["growth"] < 2.0, case
    full, stopped = bench.stop_cost(200_000)
    assert stopped < 0.25 * full  # measured ~0.08 (docs/performance.md)
    assert "| library | 2e+05 | 0.1 | 201 |" in bench.table([every, thinned])
