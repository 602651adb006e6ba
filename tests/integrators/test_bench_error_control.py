"""benchmarks/bench_error_control.py's quick mode: the rod at tol = 1e-3 and 1e-4 meets its
tolerance against the event-driven reference, the hybrid method at h = 5e-2 locates the impact
within 1e-5 s, and its table, CSV and chart are written."""
import csv
from pathlib import Path
from scripts import load_script

ROOT = Path(__file__).resolve().parents[2]


def _bench():
    return load_script(ROOT / "benchmarks" / "bench_error_control.py")


def test_quick_run_meets_the_tolerances_and_writes_its_files(tmp_path, capsys):
    assert _bench().main(["--quick", "--out", str(tmp_path)]) == 0  # 1 if a tol run missed its tolerance
    rows = list(csv.DictReader((tmp_path / "error_control.csv").open()))
    assert [(r["knob"], float(r["value"])) for r in rows] == [("h", 1e-3), ("h", 1e-4), ("tol", 1e-3), ("tol", 1e-4),
                                                              ("hybrid h", 5e-2)]
    hybrid = rows[-1]  # Runge–Kutta of order 4 between events: nine steps locate the impact within 1e-5 s
    assert float(hybrid["impact_error_s"]) <= 1e-5 and float(hybrid["x_O_error_m"]) <= 1e-5
    for r in rows:
        if r["knob"] == "tol":
            assert float(r["impact_error_s"]) <= float(r["impact_error_estimate_s"])
    assert (tmp_path / "error_control.png").stat().st_size > 1000
    assert "| tol = 0.0001 |" in capsys.readouterr().out
