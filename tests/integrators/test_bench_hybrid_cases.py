"""benchmarks/bench_hybrid_cases.py's quick mode (issue 28's "25 hidden-style cases"): on three of
the 25 rods, one of each phase sequence of ball A, the hybrid method at h = 5e-2 and
error-controlled Moreau–Jean at tol = 1e-6 have the event-driven reference's phase sequence, and
at tol = 1e-6 every phase boundary and ball B's impact are within 1e-5 s of the reference's."""
import csv
from pathlib import Path

from scripts import load_script

ROOT = Path(__file__).resolve().parents[2]


def _bench():
    return load_script(ROOT / "benchmarks" / "bench_hybrid_cases.py")


def test_quick_run_has_the_references_phases_and_boundaries_within_1e_5_s_at_tol_1e_6(tmp_path, capsys):
    bench = _bench()
    assert bench.main(["--quick", "--out", str(tmp_path)]) == 0  # 1 on a wrong sequence or a tol run off by > 10 tol
    rows = list(csv.DictReader((tmp_path / "hybrid_cases.csv").open()))
    assert [(r["run"], float(r["value"]), int(r["case"])) for r in rows] == \
        [("hybrid", 5e-2, i) for i in bench.QUICK_CASES] + [("tol", 1e-6, i) for i in bench.QUICK_CASES]
    # the three cases cover the three sequences the 25 have (slip−; stick, slip+; stick, slip−, slip+)
    assert len({r["reference_phases"] for r in rows}) == 3
    for r in rows:
        assert r["phases"] == r["reference_phases"]
        if r["run"] == "tol":
            assert float(r["boundary_error_s"]) <= 1e-5 and float(r["impact_error_s"]) <= 1e-5
    assert "| Moreau–Jean tol = 1e-06 | 3/3 |" in capsys.readouterr().out


def test_positions_by_span_against_the_reference(capsys):
    """--positions: case 0 (ball A sticks 0.30 s, then slips forward) at tol = 1e-5 keeps x_O, y_O
    and θ within tol of the event-driven reference in every span (measured ≤ 1.3e-6; before the
    sticking contact's positions were extrapolated, 1.7e-5 … 3.7e-5: set by the largest window,
    not by tol), and the break-away and ball B's impact within tol; one row a case."""
    bench = _bench()
    assert bench.main(["--h", "--tol", "1e-5", "--cases", "0", "--positions"]) == 0
    out = capsys.readouterr().out
    row = next(line for line in out.splitlines() if line.startswith("| tol = 1e-05, window 0.01 | 0 |"))
    cells = [float(cell) for cell in row.strip("|").split("|")[2:]]
    spans, boundary, impact = cells[:len(bench.SPANS)], cells[len(bench.SPANS)], cells[len(bench.SPANS) + 1]
    assert len(spans) == 4 and all(0.0 < e <= 1e-5 for e in spans), spans
    assert boundary <= 1e-5 and impact <= 1e-5


def test_fixed_step_row_has_the_references_phases(tmp_path, capsys):
    """--fixed-h: Moreau–Jean at h = 1e-3, its break-aways confirmed by the smooth phase
    (integrators/stick_decisions.py), on case 0 (stick 0.30 s, then slip+): the reference's
    phases, its break-away at the predicted time and ball B's impact within a step."""
    bench = _bench()
    assert bench.main(["--h", "--fixed-h", "1e-3", "--cases", "0", "--out", str(tmp_path)]) == 0
    row = next(csv.DictReader((tmp_path / "hybrid_cases.csv").open()))
    assert row["run"] == "fixed" and row["phases"] == row["reference_phases"] == "stick slip+"
    assert float(row["boundary_error_s"]) <= 1e-3 and float(row["impact_error_s"]) <= 1e-3
    assert "| Moreau–Jean h = 0.001 | 1/1 |" in capsys.readouterr().out
