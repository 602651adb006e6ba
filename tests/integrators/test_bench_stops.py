"""benchmarks/bench_stops.py --quick: for every method, a stop holding at 5 % of t_end costs a
small part of the whole run (issue 22: at most 10 %; the benchmark exits 1 beyond), and ends
at the first sample past the dropped ball's closed-form fall time."""
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
        # the benchmark's 10 %, with room for one unrepeated measure on a loaded machine
        assert row["stopped_s"] < 0.2 * row["full_s"], row
    assert "| event-driven | output_dt = 0.0001 |" in bench.table(rows)
