"""benchmarks/bench_stops.py --quick: for every method, a stop holding at 5 % of t_end ends the
run there — at the first sample past the dropped ball's closed-form fall time, having integrated
no further than that (the CPU-time ratio, issue 22's at most 10 %, is the benchmark's: it
exits 1 beyond; times are not asserted here)."""
from pathlib import Path
from scripts import load_script


ROOT = Path(__file__).resolve().parents[2]


def _bench_stops():
    return load_script(ROOT / "benchmarks" / "bench_stops.py")


def test_a_stop_at_five_percent_costs_a_small_part_of_the_run_for_every_method():
    bench = _bench_stops()
    rows = [bench.measure(method, options, repeat=1) for method, options in bench.cases(quick=True).items()]
    for row in rows:
        spacing = next(iter(row["options"].values()))  # the step or output_dt the stop is tried at
        assert row["status"] == "stopped" and 0.0 <= row["t_stop"] - row["t_star"] <= spacing * (1 + 1e-9), row
        # the work done, not the time: the stop ends the integration itself (not the result trimmed after)
        assert row["reached_full"] >= bench.T_END * (1 - 1e-9), row
        assert row["reached_stopped"] <= row["t_stop"] + 2 * spacing + 1e-9 * bench.T_END, row
    assert "| event-driven | output_dt = 0.0001 |" in bench.table(rows)
