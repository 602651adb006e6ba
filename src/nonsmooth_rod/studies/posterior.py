"""The posterior of a fit's keys by Markov chain Monte Carlo (emcee's affine-invariant ensemble).

Where the linearised uncertainties of fitting.py can mislead — a key near a bound, a strongly
curved model, a μd the data barely see — the posterior says what the data allow: the
likelihood exp(−χ²/2) of the same residuals (in sigmas), a flat prior inside the keys' bounds
with μd ≤ μs (a point the scene refuses has probability 0). The walkers start in a small ball
around the least-squares estimate (its standard uncertainties where known, else a thousandth of
the bounds), so the chain's burn-in is short. emcee is the optional `mcmc` extra.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..validation import InputError

QUANTILES = (0.16, 0.5, 0.84)  # the median and the central 68 % interval


@dataclass
class Posterior:
    paths: list
    samples: np.ndarray        # (n, keys) after burn-in, every walker
    walkers: int
    steps: int
    burn: int
    acceptance: float          # the walkers' mean acceptance fraction
    autocorrelation: np.ndarray  # integrated autocorrelation time per key, in steps (NaN: chain too short to tell)
    evaluations: int

    @property
    def mean(self) -> np.ndarray:
        return self.samples.mean(axis=0)

    @property
    def sd(self) -> np.ndarray:
        return self.samples.std(axis=0, ddof=1)

    @property
    def quantiles(self) -> np.ndarray:
        """(3, keys): the 16 %, 50 % and 84 % points."""
        return np.quantile(self.samples, QUANTILES, axis=0)

    def as_dict(self) -> dict:
        q = self.quantiles
        keys = [{"path": p, "mean": float(m), "sd": float(s), "q16": float(a), "median": float(b), "q84": float(c),
                 "autocorrelation_steps": float(t)}
                for p, m, s, a, b, c, t in zip(self.paths, self.mean, self.sd, q[0], q[1], q[2], self.autocorrelation)]
        return {"walkers": self.walkers, "steps": self.steps, "burn": self.burn, "samples": int(self.samples.shape[0]),
                "acceptance": self.acceptance, "evaluations": self.evaluations, "free": keys}


def _emcee():
    try:
        import emcee
    except ImportError:
        raise InputError("--posterior needs emcee: pip install 'nonsmooth-rod[mcmc]'") from None
    return emcee


def check_chain(walkers: int, steps: int, n_keys: int) -> None:
    """Refuse a chain emcee cannot run (it needs at least two walkers per key)."""
    if int(walkers) < max(2 * n_keys, 4) or int(walkers) % 2:
        raise InputError(f"walkers must be an even number ≥ {max(2 * n_keys, 4)} (two per free key), got {walkers}")
    if int(steps) < 2:
        raise InputError(f"posterior steps must be at least 2, got {steps}")


def _starts(estimate, sd, lo, hi, walkers, rng, allowed, tries: int = 100) -> np.ndarray:
    """Walkers' starts: a small Gaussian ball around the estimate (a tenth of its standard
    uncertainties; a thousandth of the bounds where unknown), inside the bounds and allowed."""
    span = np.where(np.isfinite(hi - lo), hi - lo, 1.0)
    width = np.where(np.isfinite(sd) & (sd > 0), 0.1 * np.nan_to_num(sd), 1e-3 * span)
    starts = []
    for _ in range(tries * walkers):
        p = np.clip(estimate + width * rng.standard_normal(estimate.size), lo, hi)
        if allowed(p):
            starts.append(p)
            if len(starts) == walkers:
                return np.array(starts)
    raise InputError("posterior: no room around the estimate to start the walkers (bounds or mu_d <= mu_s)")


def sample_posterior(model, coords, estimate, sd, lo, hi, *, walkers: int = 16, steps: int = 400,
                     burn: int | None = None, seed: int = 0) -> Posterior:
    """Run the chain over the physical keys (fitting.Model `model`, bounds lo, hi per key); see
    the module doc. `burn`: steps dropped at the start (default a quarter)."""
    emcee = _emcee()
    n = len(model.free)
    check_chain(walkers, steps, n)
    burn = steps // 4 if burn is None else int(burn)
    obs, sig = model.observed, model.sigma
    pairs = list(coords.ratio_of.items())  # (μd index, μs index): μd ≤ μs

    def allowed(p) -> bool:
        return bool(np.all(p >= lo) and np.all(p <= hi) and all(p[i] <= p[j] for i, j in pairs))

    def log_probability(p) -> float:
        if not allowed(p):
            return -np.inf
        try:
            r = (model.predict(p) - obs) / sig
        except InputError:  # a point the scene refuses
            return -np.inf
        return -0.5 * float(r @ r)

    rng = np.random.default_rng(seed)
    calls_before = model.calls
    sampler = emcee.EnsembleSampler(int(walkers), n, log_probability)
    starts = _starts(np.asarray(estimate, float), np.asarray(sd, float), lo, hi, int(walkers), rng, allowed)
    state = emcee.State(starts, random_state=np.random.RandomState(seed).get_state())  # seeded: a repeatable chain
    sampler.run_mcmc(state, int(steps), progress=False)
    tau = sampler.get_autocorr_time(discard=burn, quiet=True) if steps - burn >= 50 else np.full(n, np.nan)
    return Posterior([f.path for f in model.free], sampler.get_chain(discard=burn, flat=True), int(walkers),
                     int(steps), burn, float(np.mean(sampler.acceptance_fraction)), np.asarray(tau, dtype=float),
                     model.calls - calls_before)
