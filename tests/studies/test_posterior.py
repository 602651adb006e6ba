"""The fit's optional posterior by MCMC (studies/posterior.py, emcee): for the bouncing ball's
restitution, whose second impact time t2 = t1 (1 + 2e) is linear in e, the posterior is the
closed-form Gaussian (mean (t2/t1 − 1)/2, sd σ/(2 t1)); bad chain settings are refused."""
from __future__ import annotations

from pathlib import Path

import pytest

from nonsmooth_rod.studies.fitting import fit
from nonsmooth_rod.studies.measurements import Measurements
from nonsmooth_rod.validation import InputError
from scripts import load_script

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

ROOT = Path(__file__).resolve().parents[2]


def _bench():
    return load_script(ROOT / "benchmarks" / "bench_studies.py")


def test_the_posterior_of_the_balls_restitution_is_the_closed_form_gaussian():
    """A short seeded chain (6 walkers × 40 steps, the benchmark's quick mode): its mean within
    half a posterior sd of the closed form's, its sd within 40 % (a chain of ~50 independent
    samples estimates an sd to ~10 %); the least squares' Jacobian sd is the closed form's."""
    pytest.importorskip("emcee")
    m = _bench().main(["--quick", "--skip-map", "--skip-fit"])["posterior"]
    sd = m["closed_form_sd"]
    assert m["estimate"] == pytest.approx(m["closed_form_mean"], abs=1e-3 * sd)
    assert m["jacobian_sd"] == pytest.approx(sd, rel=1e-2)
    assert abs(m["posterior_mean"] - m["closed_form_mean"]) < 0.5 * sd, m
    assert 0.6 < m["posterior_sd"] / sd < 1.4, m
    assert 0.2 < m["acceptance"] < 0.9 and m["samples"] == 6 * 30


@pytest.mark.parametrize("walkers, steps", [(3, 40), (5, 40), (8, 1)])
def test_a_chain_emcee_cannot_run_is_refused(walkers, steps):
    measured = Measurements(events=[{"kind": "impact", "contact": "floor", "t": 0.45, "sigma": 1e-3}])
    with pytest.raises(InputError, match="walkers|steps"):
        fit(ROOT / "examples" / "scenes" / "bouncing_ball.toml", measured, ["contacts.floor.law.restitution"],
            method="event-driven", posterior=True, walkers=walkers, posterior_steps=steps)
