"""Scene keys identified from measurements: weighted least squares through the simulation.

`fit(scene, measured, free)` adjusts the free keys (dotted paths, as `run --set`) so the
simulated events and trajectory match the measured ones (measurements.py), each residual in
units of its sigma. The scene runs with the event-driven reference where it supports the
scene's contacts: its event times are located inside the step, so they move continuously with
the parameters (a time-stepper's are quantised to its step and give zero gradients); otherwise
with the file's method, and the report says so.

Bounds are respected (scipy.optimize.least_squares, 'trf'); where a contact's μs and μd are
both free, the fit moves (μs, r = μd/μs) with r in [0, 1], so μd ≤ μs holds at every step; a
lone free μd stays below the file's μs. At the estimate the Jacobian (central differences in
the physical keys) gives standard uncertainties and correlations, cov = (JᵀJ)⁻¹ with residuals
already divided by their sigma; a key the residuals do not move (zero sensitivity: μd when the
motion never slips) is reported as not identifiable and left out of the covariance."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..scenefile import parse_scene, simulate_scene
from ..validation import InputError
from .maps import scene_data
from .measurements import Measurements, read_measurements
from .outcome import contact_events
from .patching import PointScenes
from .paths import check_path, current_value

DEFAULT_BOUNDS = {"mu_s": (0.0, 2.0), "mu_d": (0.0, 2.0), "restitution": (0.0, 1.0)}
SENSITIVITY_FLOOR = 1e-6  # residual change (in sigmas) per unit of a key's scale below which it is unseen
REL_STEP = 1e-4           # finite-difference step, relative to the key's scale


@dataclass
class Free:
    path: str
    lo: float
    hi: float
    start: float

    @property
    def key(self) -> str:
        return self.path.rsplit(".", 1)[-1]

    @property
    def scale(self) -> float:
        return max(abs(self.start), 1e-3 * (self.hi - self.lo) if math.isfinite(self.hi - self.lo) else 0.0, 1e-6)


def parse_free(text: str, data: dict) -> Free:
    """'PATH' or 'PATH=LO:HI' → a free key starting at the file's value."""
    path, sep, spec = str(text).partition("=")
    path = path.strip()
    now = check_path(data, path, 0.5, "--free")
    if now is None:
        raise InputError(f"--free {path}: the scene file gives it no value to start from: --set it")
    lo, hi = DEFAULT_BOUNDS.get(path.rsplit(".", 1)[-1], (-math.inf, math.inf))
    if sep:
        parts = spec.split(":")
        try:
            lo, hi = float(parts[0]), float(parts[1])
        except (ValueError, IndexError):
            raise InputError(f"--free {text!r}: expected PATH=LO:HI") from None
        if len(parts) != 2 or not lo < hi:
            raise InputError(f"--free {text!r}: expected PATH=LO:HI with LO < HI")
    return Free(path, lo, hi, min(max(now, lo), hi))


# --------------------------------------------------------------------------- the model
@dataclass
class Model:
    """The scene as a function of the free keys: simulated events and samples."""

    data: dict
    source: str
    free: list
    measured: Measurements
    calls: int = 0
    scenes: PointScenes | None = None  # the scene parsed once, the free keys patched in (patching.py)

    def run(self, values):
        self.calls += 1
        paths = [f.path for f in self.free]
        if self.scenes is None:
            self.scenes = PointScenes(self.data, self.source, paths)
        return simulate_scene(self.scenes.scene_file(dict(zip(paths, map(float, values)))))

    def predict(self, values) -> np.ndarray:
        """The model's value of every measured quantity, in the order of `labels`."""
        result = self.run(values)
        return np.concatenate([_event_times(result, self.measured.events), _samples(result, self.measured)])

    @property
    def observed(self) -> np.ndarray:
        m = self.measured
        traj = [m.columns[c] for c in m.columns] if m.t is not None else []
        return np.concatenate([[e["t"] for e in m.events]] + traj) if (m.events or traj) else np.zeros(0)

    @property
    def sigma(self) -> np.ndarray:
        m = self.measured
        traj = [np.full(m.t.size, m.sigma[c]) for c in m.columns] if m.t is not None else []
        return np.concatenate([[e["sigma"] for e in m.events]] + traj)

    @property
    def labels(self) -> list[str]:
        m = self.measured
        out = [f"{e['kind']} at {e['contact']}" for e in m.events]
        return out + ([f"{c} at t = {t:.6g}" for c in m.columns for t in m.t] if m.t is not None else [])


def _event_times(result, measured_events) -> np.ndarray:
    """The n-th simulated event of each measured (kind, contact); the run's end where the
    simulation shows no such event (it had not happened by then)."""
    simulated: dict = {}
    for kind, contact, t in contact_events(result):
        simulated.setdefault((kind, contact), []).append(t)
    seen: dict = {}
    out = []
    for e in measured_events:
        key = (e["kind"], e["contact"])
        n = seen.get(key, 0)
        seen[key] = n + 1
        times = simulated.get(key, [])
        out.append(times[n] if n < len(times) else float(result.t[-1]))
    return np.array(out, dtype=float)


def _samples(result, m: Measurements) -> np.ndarray:
    if m.t is None:
        return np.zeros(0)
    from ..result_files import trajectory_columns

    cols = trajectory_columns(result)
    return np.concatenate([np.interp(m.t, cols["t"], np.asarray(cols[c], dtype=float)) for c in m.columns])


# --------------------------------------------------------------------------- μd ≤ μs
@dataclass
class Coordinates:
    """The optimiser's coordinates z: the free keys, except that a μd whose μs is free too is
    moved as r = μd/μs in [0, 1] (so μd ≤ μs at every step)."""

    free: list
    ratio_of: dict = field(default_factory=dict)  # index of μd -> index of its μs

    @classmethod
    def of(cls, free: list, data: dict) -> "Coordinates":
        paths = {f.path: i for i, f in enumerate(free)}
        pairs = {}
        for i, f in enumerate(free):
            if f.key != "mu_d":
                continue
            partner = f.path[: -len("mu_d")] + "mu_s"
            if partner in paths:
                pairs[i] = paths[partner]
            else:  # a lone μd stays below the file's μs
                mu_s = current_value(data, partner)
                if mu_s is not None:
                    f.hi = min(f.hi, mu_s)
                    f.start = min(f.start, mu_s)
        for i, f in enumerate(free):
            if f.key == "mu_s" and f.path[: -len("mu_s")] + "mu_d" not in paths:
                mu_d = current_value(data, f.path[: -len("mu_s")] + "mu_d")
                if mu_d is not None:
                    f.lo, f.start = max(f.lo, mu_d), max(f.start, mu_d)
        return cls(free, pairs)

    def physical(self, z) -> np.ndarray:
        p = np.array(z, dtype=float)
        for i, j in self.ratio_of.items():
            p[i] = z[i] * p[j]
        return p

    def start(self) -> np.ndarray:
        z = np.array([f.start for f in self.free])
        for i, j in self.ratio_of.items():
            z[i] = min(1.0, z[i] / z[j]) if z[j] > 0 else 1.0
        return z

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        lo = np.array([f.lo for f in self.free])
        hi = np.array([f.hi for f in self.free])
        for i, j in self.ratio_of.items():
            # r's range: μd's own bounds mapped through μs's, and never above 1
            lo[i] = max(0.0, self.free[i].lo / self.free[j].hi) if self.free[j].hi > 0 else 0.0
            hi[i] = min(1.0, self.free[i].hi / self.free[j].lo) if self.free[j].lo > 0 else 1.0
        return lo, hi


# --------------------------------------------------------------------------- the estimate's quality
def jacobian(model: Model, p: np.ndarray, sigma: np.ndarray, base: np.ndarray | None = None) -> np.ndarray:
    """d(residual)/d(key) at p, residuals in sigmas: central differences, one-sided at a bound
    or where the scene refuses a side (μd above μs). `base`: the prediction at p, if known."""
    base = model.predict(p) if base is None else base
    J = np.zeros((base.size, p.size))
    for i, f in enumerate(model.free):
        h = REL_STEP * f.scale
        sides = []
        for sign in (1.0, -1.0):
            q = p.copy()
            q[i] += sign * h
            if not f.lo <= q[i] <= f.hi:
                continue
            try:
                sides.append((sign, model.predict(q)))
            except InputError:
                continue
        if len(sides) == 2:
            J[:, i] = (sides[0][1] - sides[1][1]) / (2 * h)
        elif sides:
            J[:, i] = sides[0][0] * (sides[0][1] - base) / h
    return J / sigma[:, None]


def identifiability(J: np.ndarray, free: list) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """(standard uncertainties, correlations, a verdict per key): a key whose column is ~zero
    is not identifiable (NaN uncertainty, left out of the covariance); the others' covariance
    is (JᵀJ)⁻¹ on that subset."""
    n = len(free)
    scale = np.array([f.scale for f in free])
    sens = np.linalg.norm(J, axis=0) * scale
    seen = sens > SENSITIVITY_FLOOR
    sd, corr = np.full(n, np.nan), np.full((n, n), np.nan)
    verdicts = ["not identifiable: the measurements do not depend on it (zero sensitivity)"] * n
    if seen.any():
        Js = J[:, seen] * scale[seen]
        cov_s = np.linalg.pinv(Js.T @ Js, rcond=1e-12, hermitian=True)
        cov = cov_s * np.outer(scale[seen], scale[seen])
        idx = np.flatnonzero(seen)
        sd[idx] = np.sqrt(np.clip(np.diag(cov), 0, None))
        with np.errstate(invalid="ignore", divide="ignore"):
            corr[np.ix_(idx, idx)] = cov / np.outer(sd[idx], sd[idx])
        for k in idx:
            verdicts[k] = _verdict(k, free, sd, corr)
    return sd, corr, verdicts


def _verdict(k: int, free: list, sd, corr) -> str:
    f = free[k]
    if math.isfinite(f.hi - f.lo) and sd[k] >= 0.5 * (f.hi - f.lo):
        return "not identifiable: its uncertainty spans its bounds"
    twins = [free[j].path for j in range(len(free)) if j != k and abs(corr[k, j]) > 0.999]
    if twins:
        return f"only in combination with {', '.join(twins)} (correlation > 0.999)"
    return "identifiable"


# --------------------------------------------------------------------------- the fit
@dataclass
class FitResult:
    paths: list
    estimate: np.ndarray
    uncertainty: np.ndarray        # standard uncertainties (NaN: not identifiable)
    correlation: np.ndarray
    verdicts: list
    bounds: list                   # (lo, hi) per key
    labels: list                   # one per measured quantity
    measured: np.ndarray
    sigma: np.ndarray
    fitted: np.ndarray             # the model at the estimate
    method: str                    # the simulation method the fit ran
    chi2: float
    success: bool
    message: str
    evaluations: int
    measurements: Measurements = field(repr=False, default=None)
    start: np.ndarray = field(default=None)
    posterior: object = field(repr=False, default=None)  # posterior.Posterior when asked for

    @property
    def residuals(self) -> np.ndarray:
        """(fitted − measured)/sigma per measured quantity."""
        return (self.fitted - self.measured) / self.sigma

    @property
    def dof(self) -> int:
        return int(self.measured.size - np.count_nonzero(np.isfinite(self.uncertainty)))

    def identifiable(self, path: str) -> bool:
        return self.verdicts[self.paths.index(path)] == "identifiable"

    def as_dict(self) -> dict:
        keys = [{"path": p, "estimate": float(x), "uncertainty": float(u), "lo": lo, "hi": hi, "start": float(s),
                 "identifiable": v == "identifiable", "identifiability": v}
                for p, x, u, (lo, hi), s, v in zip(self.paths, self.estimate, self.uncertainty, self.bounds,
                                                   self.start, self.verdicts)]
        res = [{"quantity": q, "measured": float(m), "fitted": float(f), "sigma": float(s), "residual": float(r)}
               for q, m, f, s, r in zip(self.labels, self.measured, self.fitted, self.sigma, self.residuals)]
        return {"schema": "nonsmooth-rod/fit/1", "method": self.method, "success": self.success,
                "message": self.message, "chi2": self.chi2, "dof": self.dof, "evaluations": self.evaluations,
                "free": keys, "correlation": self.correlation.tolist(), "residuals": res,
                "measured_files": self.measurements.files if self.measurements else [],
                **({"posterior": self.posterior.as_dict()} if self.posterior is not None else {})}


def _reference_data(data: dict, source: str) -> tuple[dict, str]:
    """The scene run by the event-driven reference when it handles the scene, else as filed."""
    ref = {**data, "simulation": {**data.get("simulation", {}), "method": "event-driven"}}
    try:
        simulate_scene(parse_scene(ref, source))
        return ref, "event-driven"
    except InputError:
        parse_scene(data, source)
        return data, str(data.get("simulation", {}).get("method", "moreau-jean"))


def _coarse_samples(data: dict, t_end: float) -> dict:
    """Events alone are located whatever the sampling: save a few samples only (a third less work)."""
    sim = data.get("simulation", {})
    ed = {**sim.get("event-driven", {})}
    ed["output_dt"] = max(float(ed.get("output_dt", 1e-3)), t_end / 10)
    return {**data, "simulation": {**sim, "event-driven": ed}}


def _check_count(model: Model) -> None:
    if model.observed.size == 0:
        raise InputError("--measured: no measured quantity to fit")
    if len({f.path for f in model.free}) != len(model.free):
        raise InputError("--free: a path is given twice")


def fit(scene, measured, free, *, sets=(), method: str | None = None, max_evaluations: int = 200,
        posterior: bool = False, walkers: int = 16, posterior_steps: int = 400, seed: int = 0) -> FitResult:
    """Estimate the `free` keys of the scene file `scene` (a path or its content as a dict;
    `sets`: --set overrides) from `measured` (file paths, or a Measurements). `free`: texts
    'PATH' or 'PATH=LO:HI'. `method`: force the simulation method (default: the event-driven
    reference where it handles the scene, else the file's). `posterior`: also sample the keys'
    posterior by MCMC (posterior.py: `walkers` × `posterior_steps` runs, seeded). See the module doc."""
    from scipy.optimize import least_squares

    data, source = scene_data(scene, sets)
    if not free:
        raise InputError("--free: name at least one scene key to estimate")
    if posterior:
        from .posterior import check_chain

        check_chain(walkers, posterior_steps, len(free))
    if method is None:
        data, method = _reference_data(data, source)
    else:
        data = {**data, "simulation": {**data.get("simulation", {}), "method": method}}
    sf = parse_scene(data, source)
    frees = [parse_free(f, data) for f in free]
    m = measured if isinstance(measured, Measurements) else read_measurements(
        [measured] if isinstance(measured, (str, bytes)) or hasattr(measured, "__fspath__") else list(measured),
        sf.body_names, sf.contact_names)
    if m.t is None and method == "event-driven":
        data = _coarse_samples(data, sf.t_end)
    model = Model(data, source, frees, m)
    _check_count(model)
    coords = Coordinates.of(frees, data)
    lo, hi = coords.bounds()
    if np.any(lo >= hi):
        raise InputError(f"--free {frees[int(np.argmax(lo >= hi))].path}: its bounds leave no room (μd ≤ μs)")
    obs, sig = model.observed, model.sigma
    z0 = np.clip(coords.start(), lo, hi)

    def residuals(z):
        return (model.predict(coords.physical(z)) - obs) / sig

    # xtol: the keys to 1e-7 of their size, far inside any uncertainty the data allow
    sol = least_squares(residuals, z0, bounds=(lo, hi), method="trf", diff_step=REL_STEP, x_scale="jac",
                        xtol=1e-7, max_nfev=max_evaluations)
    p = coords.physical(sol.x)
    fitted = obs + sig * sol.fun  # the residuals at the solution: no second run of the same point
    J = jacobian(model, p, sig, fitted)
    sd, corr, verdicts = identifiability(J, frees)
    chi2 = float(np.sum(((fitted - obs) / sig) ** 2))
    evaluations = model.calls
    chain = None
    if posterior:
        from .posterior import sample_posterior

        chain = sample_posterior(model, coords, p, sd, np.array([f.lo for f in frees]), np.array([f.hi for f in frees]),
                                 walkers=walkers, steps=posterior_steps, seed=seed)
    return FitResult([f.path for f in frees], p, sd, corr, verdicts, [(f.lo, f.hi) for f in frees], model.labels,
                     obs, sig, fitted, method, chi2, bool(sol.success), str(sol.message), evaluations, m,
                     coords.physical(z0), chain)
