"""Fits: the rod's (μs, μd) recovered from noisy event times at the rate statistics predicts;
μd reported not identifiable when the rod never slips; a block's (μs, μd) from a noisy
trajectory. Synthetic measurements come from the event-driven reference at the true values."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from nonsmooth_rod.result_files import trajectory_columns
from nonsmooth_rod.scenefile import parse_scene, simulate_scene
from nonsmooth_rod.studies.fitting import fit
from nonsmooth_rod.studies.maps import scene_data
from nonsmooth_rod.studies.measurements import Measurements
from scripts import load_script

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "examples" / "scenes"
ROD = SCENES / "paper_rod.toml"
REFERENCE = ["simulation.event-driven.rtol=1e-9", "simulation.event-driven.atol=1e-9"]


def _bench():
    return load_script(ROOT / "benchmarks" / "bench_studies.py")


def test_the_rods_friction_is_recovered_at_the_rate_statistics_predicts():
    """20 seeded repeats: a key lies within 2σ with probability 0.954, so 5 or more misses out
    of 20 has probability < 0.3 %; within 1σ with 0.683, so 20 of 20 (σ grossly overstated)
    has probability 5e-4 and 8 or fewer (understated) about 1 %."""
    report = _bench().main(["--quick", "--skip-map", "--skip-posterior"])["fit"]
    for path in ("contacts.A.law.mu_s", "contacts.A.law.mu_d"):
        assert report[path]["within_2_sigma"] >= 16, report
        assert 9 <= report[path]["within_1_sigma"] <= 19, report


def test_noise_free_events_give_the_true_values_back():
    bench = _bench()
    exact = bench.rod_event_times(0.28, 0.20)
    measured = Measurements(events=[{"kind": "slip", "contact": "A", "t": exact["slip"], "sigma": 2e-3},
                                    {"kind": "impact", "contact": "B", "t": exact["impact"], "sigma": 1e-3}])
    r = fit(ROD, measured, ["contacts.A.law.mu_s=0:1", "contacts.A.law.mu_d"], method="event-driven",
            sets=REFERENCE + bench.START)
    assert r.estimate == pytest.approx([0.28, 0.20], abs=1e-5)
    assert all(v == "identifiable" for v in r.verdicts)
    assert np.all(np.abs(r.residuals) < 1e-3)
    assert abs(r.correlation[0, 1]) < 0.9 and r.correlation[0, 0] == pytest.approx(1.0)
    d = r.as_dict()
    assert [k["path"] for k in d["free"]] == r.paths and d["free"][0]["identifiable"]


def test_mu_d_is_not_identifiable_when_the_rod_never_slips():
    # μs = 2.5 > |min T/N| ≈ 1.97 at 60°: ball A rolls all the way to B's impact
    sets = REFERENCE + ["contacts.A.law.mu_s=2.5", "contacts.A.law.mu_d=0.2"]
    t_impact = load_and_run(ROD, sets).impacts[0].t
    measured = Measurements(events=[{"kind": "impact", "contact": "B", "t": t_impact + 4e-4, "sigma": 1e-3}])
    r = fit(ROD, measured, ["contacts.A.law.mu_d"], sets=sets, method="event-driven")
    assert not r.identifiable("contacts.A.law.mu_d")
    assert "not identifiable" in r.verdicts[0] and math.isnan(r.uncertainty[0])
    assert r.as_dict()["free"][0]["identifiable"] is False


def load_and_run(path, sets):
    data, source = scene_data(path, ["simulation.method=event-driven"] + list(sets))
    return simulate_scene(parse_scene(data, source))


def test_a_blocks_friction_from_a_noisy_trajectory():
    """The pushed block on its two corners (mass 1 kg, push 10 N/s): μs fixes when it starts to
    slide, μd how it accelerates after; x measured every 20 ms with σ = 1 mm."""
    sets = ["simulation.event-driven.output_dt=0.02", "contacts.*.law.mu_s=0.5", "contacts.*.law.mu_d=0.3"]
    truth = load_and_run(SCENES / "pushed_block.toml", sets)
    cols = trajectory_columns(truth)
    t = np.round(np.arange(0.02, 0.8 + 1e-9, 0.02), 12)
    x = np.interp(t, cols["t"], cols["block.x"]) + np.random.default_rng(7).normal(0, 1e-3, t.size)
    measured = Measurements(t=t, columns={"block.x": x}, sigma={"block.x": 1e-3})
    start = ["contacts.*.law.mu_s=0.45", "contacts.*.law.mu_d=0.25"]
    r = fit(SCENES / "pushed_block.toml", measured, ["contacts.*.law.mu_s", "contacts.*.law.mu_d"],
            sets=sets[:1] + start, method="event-driven")
    for k, true in enumerate((0.5, 0.3)):
        assert r.verdicts[k] == "identifiable"
        assert abs(r.estimate[k] - true) <= 3 * r.uncertainty[k], (r.estimate, r.uncertainty)
        assert r.uncertainty[k] < 0.02
    assert r.chi2 < t.size + 4 * math.sqrt(2 * t.size)  # χ² with ~40 degrees of freedom
