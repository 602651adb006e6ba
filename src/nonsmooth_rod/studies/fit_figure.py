"""The figure of a fit: measured against fitted (events, and each trajectory column), and the
confidence region of a contact's (μs, μd) when both were free."""
from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

# Δχ² of the 68 % and 95 % joint regions of two parameters
REGIONS = ((2.30, "68 %"), (6.18, "95 %"))


def _friction_pair(result) -> tuple[int, int] | None:
    for i, p in enumerate(result.paths):
        if p.endswith(".mu_s") and p[:-4] + "mu_d" in result.paths:
            j = result.paths.index(p[:-4] + "mu_d")
            if math.isfinite(result.uncertainty[i]) and math.isfinite(result.uncertainty[j]):
                return i, j
    return None


def _events_panel(ax, result) -> None:
    # Against the fitted time: the events lie far apart in t, their misfits within milliseconds.
    n = len(result.measurements.events)
    y = np.arange(n)
    ms = 1e3 * (result.measured[:n] - result.fitted[:n])
    ax.errorbar(ms, y, xerr=1e3 * result.sigma[:n], fmt="o", color="k", label="measured ± σ")
    ax.plot(np.zeros(n), y, "x", color="#d62728", ms=9, label="fitted")
    ax.set_yticks(y, [f"{lab}\n(fitted {t:.4f} s)" for lab, t in zip(result.labels[:n], result.fitted[:n])])
    ax.set_xlabel("measured − fitted time [ms]")
    ax.set_title("events")
    ax.legend(fontsize=8)


def _trajectory_panel(ax, result) -> None:
    m = result.measurements
    start = len(m.events)
    for k, name in enumerate(m.columns):
        sl = slice(start + k * m.t.size, start + (k + 1) * m.t.size)
        line = ax.errorbar(m.t, result.measured[sl], yerr=result.sigma[sl], fmt=".", label=f"{name} measured")
        ax.plot(m.t, result.fitted[sl], "-", color=line[0].get_color(), label=f"{name} fitted")
    ax.set_xlabel("t [s]")
    ax.set_title("trajectory")
    ax.legend(fontsize=8)


def _region_panel(ax, result, i: int, j: int) -> None:
    sd = result.uncertainty[[i, j]]
    rho = result.correlation[i, j]
    cov = np.array([[sd[0] ** 2, rho * sd[0] * sd[1]], [rho * sd[0] * sd[1], sd[1] ** 2]])
    vals, vecs = np.linalg.eigh(cov)
    angle = np.linspace(0, 2 * np.pi, 200)
    circle = np.stack([np.cos(angle), np.sin(angle)])
    centre = result.estimate[[i, j]]
    for dchi2, label in REGIONS:
        pts = centre[:, None] + vecs @ (np.sqrt(np.clip(vals, 0, None) * dchi2)[:, None] * circle)
        ax.plot(pts[0], pts[1], label=f"{label} region")
    ax.plot(*centre, "k+", ms=10, label="estimate")
    lo, hi = max(pts[0].min(), pts[1].min()), min(pts[0].max(), pts[1].max())
    if lo < hi:  # the physical limit, where it crosses the region
        ax.plot([lo, hi], [lo, hi], ":", color="grey", label="μd = μs")
    ax.set_xlabel(result.paths[i])
    ax.set_ylabel(result.paths[j])
    ax.set_title("confidence region (from the Jacobian)")
    ax.legend(fontsize=8)


def fit_figure(result) -> Figure:
    m = result.measurements
    panels = [p for p, on in (("events", bool(m.events)), ("trajectory", m.t is not None),
                              ("region", _friction_pair(result) is not None)) if on]
    fig = Figure(figsize=(5.5 * len(panels), 4.8), layout="constrained")
    for k, panel in enumerate(panels):
        ax = fig.add_subplot(1, len(panels), k + 1)
        if panel == "events":
            _events_panel(ax, result)
        elif panel == "trajectory":
            _trajectory_panel(ax, result)
        else:
            _region_panel(ax, result, *_friction_pair(result))
    return fig
