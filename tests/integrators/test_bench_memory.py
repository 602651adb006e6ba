"""benchmarks/bench_memory.py --quick: the peak memory of a run follows what it keeps, near the
driver's estimate, and a stop at 5 % of t_end costs a small part of the whole run."""
import sys
from pathlib import Path

import pytest
from scripts import load_script

ROOT = Path(__file__).resolve().parents[2]


def _bench_memory():
    return load_script(ROOT / "benchmarks" / "bench_memory.py")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_peak_memory_follows_what_is_kept_and_a_stop_ends_early():
    bench = _bench_memory()
    # each in a fresh process: in this one, memory earlier tests freed is reused and hides the growth
    every, thinned = (bench.library_case_fresh(200_000, save_every) for save_every in (None, 0.1))
    assert thinned["samples"] == 201 and every["samples"] == 200_001
    # thinning while running: the peak follows the samples kept (the window of rows stays)
    assert thinned["growth"] < 0.6 * every["growth"]
    # the estimate within a generous band here (allocator noise on 20 MB; 20 % at 1e6–1e7 steps)
    for case in (every, thinned):
        assert 0.5 < case["estimate"] / case["growth"] < 2.0, case
    full, stopped = bench.stop_cost(200_000)
    assert stopped < 0.25 * full  # measured ~0.08 (docs/performance.md)
    assert "| library | 2e+05 | 0.1 | 201 |" in bench.table([every, thinned])
