"""Figures of a rod run (matplotlib, no screen needed)."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .io import atomic_path  # noqa: E402

MODE_COLOURS = {"stick": "tab:blue", "slip+": "tab:red", "slip-": "tab:red", "flight": "tab:gray"}


def _by_mode(ax, t, y, modes, **kw):
    """Plot y(t) in pieces coloured by regime: rolling blue, sliding red (as the paper)."""
    modes = np.asarray(modes)
    start = 0
    for k in range(1, len(t) + 1):
        if k == len(t) or modes[k] != modes[start]:
            sl = slice(start, min(k + 1, len(t)))
            ax.plot(t[sl], y[sl], color=MODE_COLOURS.get(modes[start], "k"), **kw)
            start = k


def plot_run(run, path) -> None:
    """The paper's Fig. 14-style overview of one run, written atomically to `path`."""
    tab = run.table
    t, modes = tab["t"], tab["mode"]
    p = run.problem
    fig, axes = plt.subplots(2, 4, figsize=(16, 7), constrained_layout=True)
    ax = axes[0, 0]
    ax.plot(run.rolling.t, run.rolling.T_over_N, color="tab:blue")
    for s in (p.mu_s, -p.mu_s):
        ax.axhline(s, color="k", ls="--", lw=0.8)
    for name in ("t_r1", "t_r2"):
        tv = getattr(run.rolling, name)
        if tv is not None:
            ax.axvline(tv, color="tab:green", lw=0.8)
            ax.annotate(name, (tv, p.mu_s), textcoords="offset points", xytext=(3, 3))
    ax.set(title="T/N under pure rolling", xlabel="t [s]", ylim=(-1.0, 1.0))
    panels = [("theta", "θ [rad]"), ("theta_dot", "θ̇ [rad/s]"), ("theta_ddot", "θ̈ [rad/s²]"),
              ("x_O", "x_O [m]"), ("x_O_dot", "ẋ_O [m/s]"), ("N", "N [N]")]
    for ax, (key, label) in zip(list(axes[0, 1:]) + list(axes[1, :3]), panels):
        _by_mode(ax, t, tab[key], modes)
        ax.set(ylabel=label, xlabel="t [s]")
    ax = axes[1, 3]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(tab["N"] > 0, tab["T"] / tab["N"], np.nan)
    _by_mode(ax, t, ratio, modes)
    for s in (p.mu_s, -p.mu_s, p.mu_d, -p.mu_d):
        ax.axhline(s, color="k", ls="--" if abs(s) == p.mu_s else ":", lw=0.8)
    ax.set(title="actual T/N (blue rolling, red sliding)", xlabel="t [s]", ylim=(-1.0, 1.0))
    impact = f", impact of B at t = {run.impact['t']:.6f} s" if run.impact else ""
    fig.suptitle(f"{run.method}: μs = {p.mu_s:g}, μd = {p.mu_d:g}, θ0 = {p.theta0_deg:g}°{impact}")
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
