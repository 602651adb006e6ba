"""figure.png of any scene: the bodies' paths and coordinates, contact forces, friction ratios
T/N with their ±μs bands, and each contact's phases as coloured bands (impacts marked)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..io import atomic_path
from .animation import shown_contacts

# The line plots colour bodies and contacts C0, C1, ... (blue, orange, green, red, ...): the phase
# bar must not reuse a hue, or "stick" reads as "the first body". Its states are greys and
# hatches instead — dark for stick, mirrored hatching for the two slip directions, pale for open.
MODE_STYLES = {"open": {"facecolor": "#f2f2f2", "edgecolor": "#bdbdbd", "hatch": ""},
               "stick": {"facecolor": "#404040", "edgecolor": "#404040", "hatch": ""},
               "slip+": {"facecolor": "#ffffff", "edgecolor": "#404040", "hatch": "////"},
               "slip-": {"facecolor": "#ffffff", "edgecolor": "#404040", "hatch": "\\\\"}}
MODE_LABELS = {"open": "open", "stick": "stick", "slip+": "slip+", "slip-": "slip−"}
OTHER_MODE = {"facecolor": "#969696", "edgecolor": "#969696", "hatch": "xx"}  # a word no law gives


def body_names(result) -> list[str]:
    from ..result_files import body_names_of

    return body_names_of(result)


def contact_mu_s(result) -> dict:
    sf = getattr(result, "scene_file", None)
    if sf is None:
        return {}
    return {c.name: c.law.friction.mu_s for c in sf.scene.contacts}


def _robust_ylim(ax, y) -> None:
    """Limits that keep an impact step (impulse / h) from squashing the resting forces."""
    y = np.asarray(y, float)
    y = y[np.isfinite(y)]
    if y.size:
        lo, hi = np.percentile(y, [1, 99])
        if hi - lo <= 1e-9 * (np.max(y) - np.min(y)):  # nothing but the spikes: show them whole
            lo, hi = np.min(y), np.max(y)
        pad = 0.1 * max(hi - lo, abs(hi), 1e-12)
        ax.set_ylim(lo - pad, hi + pad)


def _paths(ax, result, names) -> None:
    q = result.trajectory.q
    for i, name in enumerate(names):
        ax.plot(q[:, 3 * i], q[:, 3 * i + 1], label=name)
        ax.plot(q[0, 3 * i], q[0, 3 * i + 1], "o", color=ax.lines[-1].get_color(), ms=4)
    sf = getattr(result, "scene_file", None)
    if sf is not None:
        from .animation import draw_lines, move_driven, scene_extent

        extent = scene_extent(result, sf)
        move_driven(ax, draw_lines(ax, sf, extent), float(result.trajectory.t[0]))  # driven: at the start
        ax.set(xlim=extent[:2], ylim=extent[2:])
    ax.set(xlabel="x [m]", ylabel="y [m]", title="paths of the centres of mass (o: start)")
    ax.set_aspect("equal", adjustable="box")
    ax.legend(fontsize="small")


def _coordinates(ax, result, names) -> None:
    t, q = result.trajectory.t, result.trajectory.q
    right = ax.twinx()
    for i, name in enumerate(names):
        colour = f"C{i % 10}"
        ax.plot(t, q[:, 3 * i], color=colour, label=f"{name} x")
        ax.plot(t, q[:, 3 * i + 1], "--", color=colour, label=f"{name} y")
        right.plot(t, q[:, 3 * i + 2], ":", color=colour, label=f"{name} θ")
    ax.set(xlabel="t [s]", ylabel="x (solid), y (dashed) [m]", title="centre-of-mass coordinates")
    right.set_ylabel("θ [rad] (dotted)")
    ax.legend(fontsize="x-small", loc="best")


def _forces(ax, result) -> None:
    tr = result.trajectory
    for k, name in shown_contacts(result):
        ax.plot(tr.t, tr.normal_force[:, k], label=f"{name} N")
        ax.plot(tr.t, tr.tangential_force[:, k], "--", color=ax.lines[-1].get_color(), label=f"{name} T")
    _robust_ylim(ax, np.concatenate([tr.normal_force.ravel(), tr.tangential_force.ravel()]))
    ax.set(xlabel="t [s]", ylabel="force [N]", title="contact forces (impacts clipped: impulse / h)")
    if result.contact_names:
        ax.legend(fontsize="x-small")


def _ratios(ax, result) -> None:
    tr, mu = result.trajectory, contact_mu_s(result)
    scale = np.max(np.abs(tr.normal_force)) if tr.normal_force.size else 0.0
    for k, name in shown_contacts(result):
        n = tr.normal_force[:, k]
        ratio = np.where(n > 1e-9 * scale, tr.tangential_force[:, k] / np.where(n > 0, n, 1.0), np.nan)
        line, = ax.plot(tr.t, ratio, label=f"{name} T/N")
        if name in mu:
            ax.axhspan(-mu[name], mu[name], color=line.get_color(), alpha=0.08)
            ax.axhline(mu[name], color=line.get_color(), lw=0.8, ls=":")
            ax.axhline(-mu[name], color=line.get_color(), lw=0.8, ls=":")
    ax.set(xlabel="t [s]", ylabel="T/N", title="friction ratio with ±μs (shaded; where N > 0)")
    ax.set_xlim(tr.t[0], tr.t[-1] if tr.t[-1] > tr.t[0] else tr.t[0] + 1)
    if result.contact_names:
        ax.legend(fontsize="x-small")


def mode_style(mode) -> dict:
    mode = str(mode)
    return MODE_STYLES.get("open" if mode == "flight" else mode, OTHER_MODE)


def _phases(ax, result) -> None:
    from matplotlib.patches import Patch

    names = [name for _, name in shown_contacts(result)]
    for k, name in enumerate(names):
        for ph in result.phases.get(name, []):
            ax.broken_barh([(ph.t_start, ph.t_end - ph.t_start)], (k - 0.4, 0.8), linewidth=0.5,
                           **mode_style(ph.mode), gid=f"phase:{name}:{ph.mode}")
    for imp in result.impacts:
        if imp.contact in names:
            ax.plot(imp.t, names.index(imp.contact), "v", color="white", mec="black", ms=7)
    handles = [Patch(**style, linewidth=0.5, label=MODE_LABELS[m]) for m, style in MODE_STYLES.items()]
    handles.append(ax.plot([], [], "v", color="white", mec="black", label="impact")[0])
    ax.legend(handles=handles, fontsize="small", ncol=5, loc="lower left", bbox_to_anchor=(0.0, 1.0),
              frameon=False, borderaxespad=0.2, handlelength=2.6, handleheight=1.3)
    ax.set_yticks(range(len(names)), names)
    ax.set(xlabel="t [s]", ylim=(-0.6, max(len(names), 1) - 0.4))
    ax.set_title("phases per contact", loc="right")
    t = result.trajectory.t
    ax.set_xlim(t[0], t[-1] if t[-1] > t[0] else t[0] + 1)


def result_figure(result):
    """The matplotlib Figure of a run of any scene."""
    from matplotlib.figure import Figure

    names = body_names(result)
    fig = Figure(figsize=(12, 10), layout="constrained")
    grid = fig.add_gridspec(3, 2, height_ratios=(1.2, 1, 0.5 + 0.15 * len(shown_contacts(result))))
    panels = {"paths": grid[0, 0], "coordinates": grid[0, 1], "forces": grid[1, 0], "ratios": grid[1, 1],
              "phases": grid[2, :]}
    axes = {key: fig.add_subplot(spec, label=key) for key, spec in panels.items()}
    _paths(axes["paths"], result, names)
    _coordinates(axes["coordinates"], result, names)
    _forces(axes["forces"], result)
    _ratios(axes["ratios"], result)
    _phases(axes["phases"], result)
    sf = getattr(result, "scene_file", None)
    title = (sf.title if sf is not None and sf.title else "run")
    fig.suptitle(f"{title}: {result.method}, status {getattr(result.status, 'value', result.status)}")
    return fig


def plot_result(result, path) -> Path:
    """Write the run's figure as a lossless PNG, atomically."""
    path = Path(path)
    fig = result_figure(result)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=90, format="png")
    return path
