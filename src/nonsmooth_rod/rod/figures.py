"""The paper's comparison figures (Alaci et al. 2024, Figs. 18–25) for any body of the family.

* `cases_figure`      Figs. 18–21: θ, θ̇, x_O, ẋ_O of several friction cases overlaid.
* `hypotheses_figure` Figs. 22–24: pure rolling (blue) against pure sliding with μd (red).
* `impact_detail_figure` Fig. 25: θ̇ of both hypotheses up to the impact for several μ, with a
  detail around the last switch of the sliding solution (reversal or end of a v_C = 0 interval).
* `write_paper_figures` makes the whole set, simulating the cases with the event-driven method.

As in plotting.py, every function returns its Figure; curves carry gids naming what they are
("case0", "rolling", "sliding", ...) and axes are labelled by the quantity they show.
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from . import closed_form as cf
from .problem import PAPER_CASES, RodProblem
from .plotting import FORMATS, RunData, save_figure
from .hypotheses import RollingHypothesis, SlidingHypothesis, rolling_hypothesis, sliding_hypothesis

CASE_COLOURS = ("tab:red", "tab:green", "tab:blue", "tab:purple", "tab:orange", "tab:brown")
HYPOTHESIS_MU = (0.10, 0.257, 0.30)      # the paper's Figs. 22, 23, 24
IMPACT_DETAIL_MU = (0.25, 0.26, 0.30)    # the paper's Fig. 25
OVERLAY_SERIES = (("theta", "θ [rad]", "Fig. 18"), ("theta_dot", "θ̇ [rad/s]", "Fig. 19"),
                  ("x_O", "x_O [m]", "Fig. 20"), ("x_O_dot", "ẋ_O [m/s]", "Fig. 21"))
HYPOTHESIS_SERIES = (("theta", "(a) θ [rad]"), ("x_O", "(b) x_O [m]"), ("theta_dot", "(c) θ̇ [rad/s]"),
                     ("x_O_dot", "(d) ẋ_O [m/s]"), ("theta_ddot", "(e) θ̈ [rad/s²]"),
                     ("x_O_ddot", "(f) ẍ_O [m/s²]"))


# --------------------------------------------------------------------------- Figs. 18–21
def cases_figure(runs: list[RunData]) -> Figure:
    """θ, θ̇, x_O, ẋ_O of each run on shared axes, one colour per friction case; a dot marks
    every phase change and a cross the impact of ball B."""
    fig = Figure(figsize=(13, 8.5), layout="constrained")
    axes = fig.subplots(2, 2).ravel()
    for ax, (key, label, paper) in zip(axes, OVERLAY_SERIES):
        ax.set_label(key)
        for k, data in enumerate(runs):
            colour = CASE_COLOURS[k % len(CASE_COLOURS)]
            t, y = data.table["t"], data.series(key)
            p = data.problem
            ax.plot(t, y, color=colour, lw=1.5, gid=f"case{k}",
                    label=f"μs = {p.mu_s:g}, μd = {p.mu_d:g} ({'; '.join(_phase_words(data))})")
            switch_times = [ph.t_start for ph in data.phases[1:]]
            if switch_times:
                ax.plot(switch_times, np.interp(switch_times, t, y), "o", color=colour, ms=5,
                        gid=f"case{k}:switch")
            if data.impact:
                ax.plot([data.impact["t"]], [data.impact[key] if key in data.impact else np.interp(
                    data.impact["t"], t, y)], "x", color=colour, ms=8, mew=2, gid=f"case{k}:impact")
        ax.set(title=f"{paper}-style: {label}", xlabel="t [s]", ylabel=label)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, loc="lower left")
    p0 = runs[0].problem
    fig.suptitle(f"{runs[0].method}, θ0 = {p0.theta0_deg:g}°: the friction cases overlaid "
                 "(• phase change, × impact of ball B)")
    return fig


def _phase_words(data: RunData) -> list[str]:
    words = {"stick": "roll", "slip+": "slide+", "slip-": "slide−", "flight": "fly"}
    return [words.get(ph.mode, ph.mode) for ph in data.phases]


# --------------------------------------------------------------------------- Figs. 22–24
def rolling_series(p: RodProblem, rh: RollingHypothesis) -> dict:
    """The pure-rolling hypothesis in the paper's columns (x_O = −r(θ − θ0), ẋ_O = −r θ̇)."""
    th_dd = np.array([cf.rolling(p, a, b)[0] for a, b in zip(rh.theta, rh.theta_dot)])
    r = p.ball_radius
    return {"t": rh.t, "theta": rh.theta, "theta_dot": rh.theta_dot, "theta_ddot": th_dd,
            "x_O": -r * (rh.theta - p.theta0), "x_O_dot": -r * rh.theta_dot, "x_O_ddot": -r * th_dd}


def sliding_series(sh: SlidingHypothesis) -> dict:
    return {"t": sh.t, "theta": sh.theta, "theta_dot": sh.theta_dot, "theta_ddot": sh.theta_ddot,
            "x_O": sh.x_O, "x_O_dot": sh.x_O_dot, "x_O_ddot": sh.x_O_ddot}


def _hypothesis_problem(base: RodProblem, mu: float) -> RodProblem:
    """The body of `base` with μs = μd = μ: the hypotheses use one coefficient, as the paper."""
    return replace(base, mu_s=mu, mu_d=mu)


def _shade_filippov(ax, sh: SlidingHypothesis) -> None:
    for a, b in sh.filippov:
        ax.axvspan(a, b, color="tab:orange", alpha=0.15, lw=0)


def hypotheses_figure(mu: float, base: RodProblem | None = None) -> Figure:
    """Figs. 22–24: θ, x_O, θ̇, ẋ_O, θ̈, ẍ_O under pure rolling (blue) and pure sliding with μd = μ
    (red). Shaded: intervals where μ exceeds what rolling needs, so the sliding solution keeps
    v_C = 0 (Filippov) — the paper's curves do not show these."""
    base = base or RodProblem.paper()
    p = _hypothesis_problem(base, mu)
    roll = rolling_series(p, rolling_hypothesis(p))
    sh = sliding_hypothesis(p)
    slide = sliding_series(sh)
    fig = Figure(figsize=(12, 10), layout="constrained")
    axes = fig.subplots(3, 2).ravel()
    for ax, (key, label) in zip(axes, HYPOTHESIS_SERIES):
        ax.set_label(key)
        ax.plot(roll["t"], roll[key], color="tab:blue", lw=1.5, gid="rolling", label="pure rolling")
        ax.plot(slide["t"], slide[key], color="tab:red", lw=1.5, gid="sliding", label=f"pure sliding, μd = {mu:g}")
        _shade_filippov(ax, sh)
        for t_rev in sh.reversals:
            ax.axvline(t_rev, color="tab:red", ls=":", lw=0.8)
        ax.set(title=label, xlabel="t [s]")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=9)
    notes = []
    if sh.reversals:
        notes.append("slip reverses at t = " + ", ".join(f"{t:.4f}" for t in sh.reversals) + " s")
    if sh.filippov:
        notes.append("v_C = 0 (shaded) on " + ", ".join(f"[{a:.4f}, {b:.4f}]" for a, b in sh.filippov) + " s")
    if sh.status != "ok":
        notes.append(f"sliding solution ended: {sh.status}")
    fig.suptitle(f"Pure rolling (blue) vs pure sliding (red), μd = {mu:g}, θ0 = {p.theta0_deg:g}°"
                 + ("\n" + "; ".join(notes) if notes else ""))
    return fig


# --------------------------------------------------------------------------- Fig. 25
def _detail_window(sh: SlidingHypothesis, t_end: float, half_width: float = 0.02) -> tuple[float, float]:
    """Around the last switch of the sliding solution; the last 2·half_width s if none."""
    switches = list(sh.reversals) + [b for _, b in sh.filippov]
    centre = max(switches) if switches else t_end - half_width
    return max(0.0, centre - half_width), min(t_end, centre + half_width)


def impact_detail_figure(mus=IMPACT_DETAIL_MU, base: RodProblem | None = None) -> Figure:
    """Fig. 25: θ̇ up to the horizontal for each μ (rolling blue, sliding red), and beside it a
    detail around the sliding solution's last switch with θ̈ (dashed, right axis) showing the
    jump of the acceleration the paper calls a discontinuity."""
    base = base or RodProblem.paper()
    fig = Figure(figsize=(12, 3.4 * len(mus)), layout="constrained")
    axes = fig.subplots(len(mus), 2, squeeze=False)
    letters = "abcdefghijklmnop"
    for row, mu in enumerate(mus):
        p = _hypothesis_problem(base, mu)
        roll = rolling_series(p, rolling_hypothesis(p))
        sh = sliding_hypothesis(p)
        slide = sliding_series(sh)
        full, detail = axes[row]
        for ax, kind in ((full, "full"), (detail, "detail")):
            ax.set_label(f"mu{mu:g}:{kind}")
            ax.plot(roll["t"], roll["theta_dot"], color="tab:blue", lw=1.5, gid="rolling")
            ax.plot(slide["t"], slide["theta_dot"], color="tab:red", lw=1.5, gid="sliding")
            _shade_filippov(ax, sh)
            ax.grid(alpha=0.3)
            ax.set(xlabel="t [s]", ylabel="θ̇ [rad/s]")
        t_end = float(max(roll["t"][-1], slide["t"][-1]))
        lo, hi = _detail_window(sh, t_end)
        in_window = [(s["t"] >= lo) & (s["t"] <= hi) for s in (roll, slide)]
        ys = np.concatenate([s["theta_dot"][m] for s, m in zip((roll, slide), in_window)])
        pad = 0.05 * max(float(np.ptp(ys)), 1e-3)
        detail.set(xlim=(lo, hi), ylim=(ys.min() - pad, ys.max() + pad))
        acc = detail.twinx()
        acc.set_label(f"mu{mu:g}:acceleration")
        acc.plot(slide["t"], slide["theta_ddot"], color="tab:red", ls="--", lw=0.9, gid="sliding_theta_ddot")
        acc.plot(roll["t"], roll["theta_ddot"], color="tab:blue", ls="--", lw=0.9, gid="rolling_theta_ddot")
        acc.set_xlim(lo, hi)
        acc.set_ylabel("θ̈ [rad/s²] (dashed)")
        full.axvspan(lo, hi, color="0.5", alpha=0.12, lw=0)
        full.set_title(f"({letters[2 * row]}) μ = {mu:g}")
        detail.set_title(f"({letters[2 * row + 1]}) detail μ = {mu:g}: t ∈ [{lo:.3f}, {hi:.3f}] s")
    fig.suptitle("Angular velocity up to the impact: pure rolling (blue), pure sliding (red); "
                 "shaded orange: sliding solution held at v_C = 0")
    return fig


# --------------------------------------------------------------------------- the set
def simulate_cases(base: RodProblem | None = None, cases=None) -> list[RunData]:
    """Event-driven runs of the friction cases (default: the paper's three) on base's body."""
    from .simulation import simulate

    base = base or RodProblem.paper()
    cases = cases or [PAPER_CASES[k] for k in sorted(PAPER_CASES)]
    return [RunData.from_run(simulate(replace(base, mu_s=ms, mu_d=md))) for ms, md in cases]


def write_paper_figures(out_dir, base: RodProblem | None = None, formats=FORMATS[:1], dpi: int = 100) -> list[Path]:
    """Figs. 18–21 (one overlay figure), 22–24 and 25 for base's body and θ0 into out_dir."""
    out_dir = Path(out_dir)
    base = base or RodProblem.paper()
    written = save_figure(cases_figure(simulate_cases(base)), out_dir / "fig18-21_cases", formats, dpi)
    for number, mu in zip((22, 23, 24), HYPOTHESIS_MU):
        written += save_figure(hypotheses_figure(mu, base), out_dir / f"fig{number}_hypotheses_mu{mu:g}",
                               formats, dpi)
    written += save_figure(impact_detail_figure(IMPACT_DETAIL_MU, base), out_dir / "fig25_impact_detail",
                           formats, dpi)
    return written
