"""`nonsmooth-rod benchmark --quick`: the files it writes and the numbers in them."""
from __future__ import annotations

import math
import time

import numpy as np
import pytest
from PIL import Image

from nonsmooth_rod.rod import study
from nonsmooth_rod.cli import main
from nonsmooth_rod.io import read_csv


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench")
    t0 = time.perf_counter()
    assert main(["benchmark", "--quick", "--quiet", "--out", str(out)]) == 0
    return out, time.perf_counter() - t0


def test_quick_benchmark_writes_every_file_with_its_provenance(quick):
    out, _ = quick
    for name in ("work_precision.png", "work_precision.csv", "stability.md", "stability.csv", "bistable_map.csv"):
        assert (out / name).stat().st_size > 0
    import json

    meta = json.loads((out / "provenance.json").read_text())
    assert meta["quick"] is True and meta["provenance"]["version"] and meta["provenance"]["numpy"]
    with Image.open(out / "work_precision.png") as im:
        assert im.format == "PNG" and im.size[0] > im.size[1] > 400  # two panels side by side
    header = (out / "work_precision.csv").read_text().splitlines()[0]
    assert header == "method,setting,case,knob,cpu_s,work,impact_error_s,x_O_error_m,phases_ok,status"


def test_work_precision_numbers_are_measured_against_the_reference(quick):
    out, _ = quick
    data = read_csv(out / "work_precision.csv")
    rows = [dict(zip(data, vals)) for vals in zip(*data.values())]
    assert len(rows) == len(study.sweep_specs(quick=True)) == 24
    assert {r["method"] for r in rows} == set(study.METHOD_NAMES)
    assert {int(r["case"]) for r in rows} == {1, 2, 3}
    by = {(r["method"], r["setting"], int(r["case"]), r["knob"]): r for r in rows}
    for case in (1, 2, 3):
        ed = by[("event-driven", "DOP853", case, "rtol=1e-08")]
        assert ed["status"] == "ok" and ed["phases_ok"] == "True"
        assert ed["impact_error_s"] < 1e-8 and ed["x_O_error_m"] < 1e-7
        # Moreau–Jean converges with order one: ten times smaller h, about ten times smaller error.
        coarse = by[("moreau-jean", "lemke", case, "h=0.01")]
        fine = by[("moreau-jean", "lemke", case, "h=0.001")]
        assert 5 < coarse["impact_error_s"] / fine["impact_error_s"] < 20
        assert fine["impact_error_s"] < 0.5e-3  # within half a step of h = 1e-3
        assert fine["work"] > 300 and fine["cpu_s"] > 0
        # The hybrid method: fourth order between the reference's events, nine steps of 5e-2 s.
        hybrid = by[("hybrid", "RK4", case, "h=0.05")]
        assert hybrid["status"] == "ok" and hybrid["phases_ok"] == "True"
        assert hybrid["impact_error_s"] < 1e-5 and hybrid["x_O_error_m"] < 1e-5 and hybrid["work"] > 4 * 5
        reg = by[("regularized", "stribeck/LSODA", case, "epsilon=1e-05")]
        assert reg["phases_ok"] == "True" and reg["impact_error_s"] < 5e-4
    # ε = 1e-3 creeps through case 3's stick phase: wrong phases.
    assert by[("regularized", "stribeck/LSODA", 3, "epsilon=0.001")]["phases_ok"] == "False"


def test_stability_files_say_why_a_run_is_wrong(quick):
    out, _ = quick
    data = read_csv(out / "stability.csv")
    rows = [dict(zip(data, vals)) for vals in zip(*data.values())]
    wrong = {(r["method"], int(r["case"]), r["knob"]): r["reasons"] for r in rows if r["right"] == "False"}
    assert "creep at stick" in wrong[("regularized", 3, "epsilon=0.001")]
    # Event-driven watches each step's indicators whole (their interior extrema), so even rtol
    # 1e-4 sees case 2's short break-away window (T/N > μs from 0.104 s to 0.21 s).
    assert not any(method == "event-driven" for method, _, _ in wrong)
    right = [r for r in rows if r["right"] == "True"]
    assert all(r["reasons"] == "" and r["finished"] == "True" for r in right)
    md = (out / "stability.md").read_text()
    assert "| event-driven | DOP853 | 1 | 2/2 | 2/2 |" in md
    assert "bistable start" in md and "Painlevé" in md and "Zeno" in md
    assert "Reproduce: `nonsmooth-rod benchmark --quick`" in md


def test_a_run_over_its_time_limit_is_killed_and_recorded(tmp_path):
    refs = {3: study.reference(3)}
    slow = study.RunSpec("regularized", "stribeck/RK45", 3, "epsilon", 1e-8,
                         (("friction_curve", "stribeck"), ("ode_method", "RK45"), ("rtol", 1e-8)))
    fast = study.RunSpec("switched", "rk4", 3, "h", 1e-3, (("ode_method", "rk4"),))
    t0 = time.perf_counter()
    slow_rec, fast_rec = study.run_specs([slow, fast], refs, time_limit=1.0, workers=2)
    # the slow run alone would take minutes: ending well before that is the limit at work (the
    # bound is loose on purpose — it is not a speed test; children may spawn on a loaded machine)
    assert time.perf_counter() - t0 < 60.0
    assert slow_rec["status"] in ("time-limit", "killed")
    assert math.isnan(slow_rec["impact_error_s"])
    assert fast_rec["status"] == "ok" and fast_rec["impact_error_s"] < 1e-4
    finished, right, reasons = study.verdict(slow_rec, refs[3].problem)
    assert not finished and "time limit" in reasons


@pytest.mark.parametrize("argv, message", [
    (["--cases", "4"], "paper case"),
    (["--methods", "event-driven,magic"], "unknown method"),
    (["--cases", "one"], "--cases"),
    (["--time-limit", "-1"], "--time-limit"),
])
def test_bad_benchmark_input_is_one_line(argv, message, tmp_path, capsys):
    assert main(["benchmark", "--quick", "--out", str(tmp_path), *argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0]
    assert not (tmp_path / "work_precision.csv").exists()


def test_measure_reads_creep_and_impact_error_off_a_run():
    from nonsmooth_rod.rod.problem import RodProblem
    from nonsmooth_rod.rod.simulation import simulate

    ref = study.reference(3)
    run = simulate(RodProblem.paper(3), "moreau-jean", h=1e-3)
    m = study.measure(run, ref)
    assert m["impact_error_s"] == pytest.approx(abs(run.impact["t"] - 0.381775), abs=2e-6)
    # Moreau–Jean keeps v_C = 0 at each step, but integrates positions of the centre of mass:
    # the contact point drifts by O(h) over the rolling phase (0.27 mm at h = 1e-3).
    assert 1e-4 < m["creep_m"] < 5e-4
    m4 = study.measure(simulate(RodProblem.paper(3), "moreau-jean", h=1e-4), ref)
    assert m["creep_m"] / m4["creep_m"] == pytest.approx(10.0, rel=0.1)
    assert m["max_penetration_m"] < 1e-6 and np.isfinite(m["energy_growth_J"])


def test_error_control_is_in_the_chart_with_every_step_it_evaluated():
    from nonsmooth_rod.rod import study
    from nonsmooth_rod.rod.simulation import simulate

    assert any(s.knob == "tol" and s.method == "moreau-jean" for s in study.FULL_SWEEPS)
    ref = study.reference(2)
    spec = study.RunSpec("moreau-jean", "lemke, tol", 2, "tol", 1e-3, (("solver", "lemke"),))
    record = study.run_one(spec, ref)
    assert record["status"] == "ok" and record["phases_ok"]
    assert record["impact_error_s"] <= 1e-3  # the tolerance holds on the located event time
    stats = simulate(ref.problem, "moreau-jean", tol=1e-3, solver="lemke").result.stats
    assert record["work"] == stats["step_evaluations"] > stats["steps"]  # the rejected and doubled steps count
