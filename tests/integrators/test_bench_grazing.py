"""benchmarks/bench_grazing.py's quick mode: fixed-step Moreau–Jean's T/N overshoot at the rod's
grazing peak (issue 28) and the part of it that is the error of the state itself — what
docs/error_control.md ("Stick decisions at fixed steps") says a decision on the end-of-step
state cannot remove."""
import csv
from pathlib import Path

import pytest
from scripts import load_script

ROOT = Path(__file__).resolve().parents[2]


def _bench():
    return load_script(ROOT / "benchmarks" / "bench_grazing.py")


def test_quick_run_measures_a_first_order_overshoot_of_which_the_state_is_a_part(tmp_path, capsys):
    assert _bench().main(["--quick", "--out", str(tmp_path)]) == 0
    rows = list(csv.DictReader((tmp_path / "grazing_overshoot.csv").open()))
    assert [float(r["h"]) for r in rows] == [1e-3, 5e-4]
    discrete = [float(r["discrete_per_h"]) for r in rows]
    state = [float(r["end_state_per_h"]) for r in rows]
    # first order: the overshoot per unit h is the same at both steps (measured 0.2248, 0.2250 and
    # 0.0652, 0.0663 s⁻¹: the 0.2246)
    assert discrete[0] == pytest.approx(0.225, abs=0.005) and discrete[1] == pytest.approx(discrete[0], rel=0.02)
    assert state[1] == pytest.approx(state[0], rel=0.05)
    # the end-of-step state's own T/N still overshoots, by more than δ = 1e-5 at h = 1e-3
    assert 1e-3 * state[0] > 1e-5 and state[0] < discrete[0]
    assert "| 0.001 |" in capsys.readouterr().out
