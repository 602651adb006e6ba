"""The regime map drawn: scenario colours over any two axes of a sweep, the analytic thresholds
of the rolling hypothesis over them, and the transition times (the sweep itself is regime.py)."""
from __future__ import annotations

import math

import numpy as np

from .regime_grid import GEOMETRY_AXES, KEY_DIGITS, OTHER_COLOUR, SCENARIO_COLOURS, row_key, Grid, InputError, RodProblem, SCENARIOS, SweepSettings, Thresholds, point_key, predicted_scenario, thresholds


def _edges(values: np.ndarray) -> np.ndarray:
    """Cell edges around sorted grid values (half a step beyond the ends)."""
    v = np.asarray(sorted(set(np.round(values, KEY_DIGITS))), float)
    if v.size == 1:
        half = max(abs(v[0]) * 0.05, 0.01)
        return np.array([v[0] - half, v[0] + half])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]])


def _scenario_codes(rows) -> tuple[list[str], dict]:
    names = list(SCENARIOS) + sorted({r["scenario"] for r in rows} - set(SCENARIOS))
    return names, {n: i for i, n in enumerate(names)}


def regime_map_figure(rows, grid: Grid, base: RodProblem, ths: list[Thresholds],
                      settings: SweepSettings = SweepSettings(), x: str | None = None, y: str | None = None):
    """The map: for a μs × θ0 (one μd ratio) or μs × μd × θ0 grid, the figure below; for any
    other grid or any two axes `x`, `y` asked for, `axes_map_figure`."""
    if x is not None or y is not None or grid.extra or grid.varies_ratio:
        return axes_map_figure(rows, grid, base, settings, x, y)
    return _friction_map_figure(rows, grid, base, ths, settings)


BOUNDARY_STYLES = (("T_over_N_initial", "|T/N(0)|", "k", "-"), ("T_over_N_max", "max T/N", "k", "--"),
                   ("T_over_N_min", "|min T/N|", "k", ":"))


class _MapStyle:
    """What the panels of one map share: the scenario colours and the μs cells."""

    def __init__(self, rows, grid: Grid):
        from matplotlib.colors import BoundaryNorm, ListedColormap

        self.names, self.code = _scenario_codes(rows)
        colours = [SCENARIO_COLOURS.get(n, OTHER_COLOUR) for n in self.names]
        self.cmap = ListedColormap(colours).with_extremes(bad="white")
        self.norm = BoundaryNorm(np.arange(len(self.names) + 1) - 0.5, len(self.names))
        self.mu_s_edges = _edges(grid.mu_s)
        self.mu_s_vals = np.asarray(sorted(set(np.round(grid.mu_s, KEY_DIGITS))), float)
        self.x_lo, self.x_hi = self.mu_s_edges[0], self.mu_s_edges[-1]
        self.by_key = {row_key(r, ("mu_s", "mu_d", "theta0_deg")): r for r in rows}

    def cells(self, ys, mu_d_of) -> np.ndarray:
        """Scenario codes on (ys × μs); `mu_d_of(y, μs)` → (μd, θ0) of the cell."""
        Z = np.full((len(ys), self.mu_s_vals.size), np.nan)
        for i, y in enumerate(ys):
            for j, ms in enumerate(self.mu_s_vals):
                r = self.by_key.get(point_key((ms, *mu_d_of(y, ms))))
                if r is not None:
                    Z[i, j] = self.code[r["scenario"]]
        return np.ma.masked_invalid(Z)

    def patches(self):
        from matplotlib.patches import Patch

        return [Patch(color=SCENARIO_COLOURS.get(n, OTHER_COLOUR), label=n) for n in self.names]


def _friction_map_figure(rows, grid: Grid, base: RodProblem, ths: list[Thresholds],
                         settings: SweepSettings = SweepSettings()):
    """Scenario of each grid cell with the analytic boundaries. With μd = R·μs (or one μd) the
    map is μs × θ0 with the boundaries as curves of θ0, and a second panel shows the transition
    and impact times against μs beside the rolling hypothesis' prediction; with a μd grid it is
    μs × μd, one panel per θ0, and the boundaries are vertical lines (they do not depend on μd)."""
    from matplotlib.figure import Figure

    style = _MapStyle(rows, grid)
    if not grid.varies_mu_d:
        fig = Figure(figsize=(13, 5.2), layout="constrained")
        ax, ax_t = fig.subplots(1, 2, width_ratios=(1.25, 1))
        th_vals = _theta_map_panel(ax, style, grid, base, ths, settings)
        _times_panel(ax_t, rows, base, ths, th_vals, style.x_lo, style.x_hi)
    else:
        fig = _mu_d_panels(style, grid, ths, settings)
    fig.suptitle("Regime map: the paper's scenarios, with the boundaries of the pure-rolling hypothesis")
    return fig


def _theta_map_panel(ax, style: _MapStyle, grid: Grid, base, ths, settings) -> np.ndarray:
    ax.set_label("map")
    ratio = None if grid.ratios is None else float(grid.ratios[0])
    th_vals = np.asarray(sorted(set(np.round(grid.theta0_deg, KEY_DIGITS))), float)

    def mu_d_of(th, ms):
        return (min(ms, ratio * ms) if ratio is not None else float(grid.mu_d[0])), th

    ax.pcolormesh(style.mu_s_edges, _edges(th_vals), style.cells(th_vals, mu_d_of), cmap=style.cmap,
                  norm=style.norm)
    # Boundaries as curves of θ0 (a fine θ0 grid when the map has several rows).
    ys = np.linspace(th_vals[0], th_vals[-1], 40) if th_vals.size > 1 else None
    fine_th = [thresholds(base, th) for th in ys] if ys is not None else ths[:1]
    off = []
    for key, label, colour, ls in BOUNDARY_STYLES:
        vals = np.array([abs(getattr(t, key)) for t in fine_th])
        if ys is None:
            ax.axvline(vals[0], color=colour, ls=ls, lw=1.4, label=f"{label} = {vals[0]:.4f}", gid=key)
        else:
            ax.plot(vals, ys, color=colour, ls=ls, lw=1.4, label=label, gid=key)
        off += [f"{label} ≥ {vals.min():.3g}"] if vals.min() > style.x_hi else []
    ax.set_xlim(style.x_lo, style.x_hi)
    ax.set(xlabel="μs", ylabel="θ0 [°]")
    if th_vals.size == 1:
        ax.set_yticks(th_vals)
    mu_d_text = f"μd = {ratio:g}·μs" if ratio is not None else f"μd = {float(grid.mu_d[0]):g}"
    ax.set_title(f"scenario ({mu_d_text}, {settings.method})")
    handles = style.patches() + ax.get_legend_handles_labels()[0]
    ax.legend(handles=handles, fontsize=8, loc="upper left", bbox_to_anchor=(0, -0.13), ncol=3)
    if off:
        ax.text(0.99, 0.02, "off the map: " + "; ".join(off) + "\n(roll-to-impact lies beyond)",
                transform=ax.transAxes, ha="right", va="bottom", fontsize=8,
                bbox=dict(fc="white", ec="0.7", alpha=0.9))
    return th_vals


def _times_panel(ax_t, rows, base, ths, th_vals, x_lo, x_hi) -> None:
    """Times against μs for a few θ0 rows, beside the rolling hypothesis' transition time."""
    ax_t.set_label("times")
    picks = th_vals if th_vals.size <= 4 else th_vals[np.linspace(0, th_vals.size - 1, 4).round().astype(int)]
    fine_mu = np.linspace(x_lo, x_hi, 300)
    for k, th in enumerate(picks):
        colour = f"C{k}"
        th_obj = next((t for t in ths if abs(t.theta0_deg - th) < 1e-9), None) or thresholds(base, th)
        pred = np.array([predicted_scenario(th_obj.rolling, m)[1] for m in fine_mu])
        ax_t.plot(fine_mu, pred, color=colour, lw=1.0, ls="--", gid=f"predicted:{th:g}")
        sel = sorted((r for r in rows if abs(r["theta0_deg"] - th) < 1e-9), key=lambda r: r["mu_s"])
        ms = [r["mu_s"] for r in sel]
        ax_t.plot(ms, [r["t_transition"] for r in sel], "o", color=colour, ms=4,
                  gid=f"t_transition:{th:g}", label=f"θ0 = {th:g}°: end of rolling")
        ax_t.plot(ms, [r["t_impact"] for r in sel], "s", color=colour, ms=4, mfc="none",
                  gid=f"t_impact:{th:g}", label=f"θ0 = {th:g}°: impact of B")
    ax_t.plot([], [], "k--", lw=1.0, label="rolling hypothesis: |T/N| reaches μs")
    ax_t.set(xlabel="μs", ylabel="t [s]", title="end of rolling and impact time", xlim=(x_lo, x_hi))
    ax_t.grid(alpha=0.3)
    ax_t.legend(fontsize=7, loc="upper left", bbox_to_anchor=(0, -0.13), ncol=2)


def _mu_d_panels(style: _MapStyle, grid: Grid, ths, settings):
    """μs × μd, one panel per θ0, the boundaries as vertical lines."""
    from matplotlib.figure import Figure

    n = len(grid.theta0_deg)
    cols = min(n, 3)
    fig = Figure(figsize=(5.2 * cols, 4.6 * math.ceil(n / cols) + 0.6), layout="constrained")
    axes = np.atleast_1d(fig.subplots(math.ceil(n / cols), cols, squeeze=False)).ravel()
    md_vals = np.asarray(sorted(set(np.round(grid.mu_d, KEY_DIGITS))), float)
    x_lo, x_hi = style.x_lo, style.x_hi
    for ax, th, th_obj in zip(axes, grid.theta0_deg, ths):
        ax.set_label(f"map:{th:g}")
        cells = style.cells(md_vals, lambda md, ms, th=th: (md, th))
        ax.pcolormesh(style.mu_s_edges, _edges(md_vals), cells, cmap=style.cmap, norm=style.norm)
        lim = (min(x_lo, md_vals[0]), max(x_hi, md_vals[-1]))
        ax.plot(lim, lim, color="0.5", lw=0.8, label="μd = μs (white above: μd > μs)")
        off = []
        for key, label, colour, ls in BOUNDARY_STYLES:
            v = abs(getattr(th_obj, key))
            if x_lo <= v <= x_hi:
                ax.axvline(v, color=colour, ls=ls, lw=1.4, label=f"{label} = {v:.4f}", gid=key)
            else:
                off.append(f"{label} = {v:.3g}")
        if off:
            ax.text(0.99, 0.02, "off the map: " + "; ".join(off), transform=ax.transAxes, ha="right",
                    va="bottom", fontsize=8, bbox=dict(fc="white", ec="0.7", alpha=0.9))
        ax.set(xlim=(x_lo, x_hi), ylim=(_edges(md_vals)[0], _edges(md_vals)[-1]), xlabel="μs", ylabel="μd",
               title=f"θ0 = {th:g}° ({settings.method})")
        ax.legend(fontsize=7, loc="upper left")
    for ax in axes[n:]:
        ax.axis("off")
    fig.legend(handles=style.patches(), loc="outside lower center", ncol=len(style.names), fontsize=8)
    return fig


def grid_step(values) -> float:
    v = np.unique(np.round(np.asarray(values, float), KEY_DIGITS))
    return float(np.max(np.diff(v))) if v.size > 1 else 0.0


AXIS_LABELS = {"mu_s": "μs", "mu_d": "μd", "mu_d_ratio": "μd/μs", "theta0_deg": "θ0 [°]", "ball_radius": "r [m]",
               "rod_diameter": "d [m]", "length": "L [m]", "density": "ρ [kg/m³]", "restitution": "e"}
FRICTION_ONLY_AXES = ("mu_d", "mu_d_ratio", "restitution")  # the rolling thresholds do not depend on them


def _independent_axes(grid: Grid) -> list[str]:
    """The axes a map can use: given ones that are table columns (μd is derived when the
    ratio is the axis; a single ratio is no column)."""
    return [c for c in grid.axes if c in grid.columns]


def map_axes_of(grid: Grid, x, y) -> tuple[str, str]:
    cols = _independent_axes(grid)
    for name in (x, y):
        if name is not None and name not in cols:
            raise InputError(f"cannot map axis {name!r}: this sweep's axes are {', '.join(cols)}")
    x = x or "mu_s"
    varying = [c for c in cols if c != x and np.unique(np.round(grid.axes.get(c, [0.0]), KEY_DIGITS)).size > 1]
    y = y or (varying[0] if varying else "theta0_deg" if x != "theta0_deg" else "mu_s")
    if x == y:
        raise InputError(f"map axes must differ, got {x!r} twice")
    return x, y


def axes_map_figure(rows, grid: Grid, base: RodProblem, settings: SweepSettings = SweepSettings(),
                    x: str | None = None, y: str | None = None):
    """Scenario over any two axes (default μs and the first other axis that varies); the other
    axes are held at their first value. With μs along x the rolling hypothesis' boundaries are
    drawn for each y (vertical lines when y does not change them: μd, μd/μs, e)."""
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    x, y = map_axes_of(grid, x, y)
    others = [c for c in _independent_axes(grid) if c not in (x, y)]
    held = {c: min(r[c] for r in rows) for c in others if rows}
    sel = [r for r in rows if all(round(r[c] - held[c], KEY_DIGITS) == 0 for c in others)]
    xs = np.unique(np.round([r[x] for r in sel], KEY_DIGITS))
    ys = np.unique(np.round([r[y] for r in sel], KEY_DIGITS))
    names, code = _scenario_codes(rows)
    Z = np.full((ys.size, xs.size), np.nan)
    for r in sel:
        i, j = np.searchsorted(ys, round(r[y], KEY_DIGITS)), np.searchsorted(xs, round(r[x], KEY_DIGITS))
        Z[i, j] = code[r["scenario"]]
    fig = Figure(figsize=(7.5, 5.6), layout="constrained")
    ax = fig.subplots()
    ax.set_label("map")
    cmap = ListedColormap([SCENARIO_COLOURS.get(n, OTHER_COLOUR) for n in names]).with_extremes(bad="white")
    ax.pcolormesh(_edges(xs), _edges(ys), np.ma.masked_invalid(Z), cmap=cmap,
                  norm=BoundaryNorm(np.arange(len(names) + 1) - 0.5, len(names)))
    if x == "mu_s" and sel:
        _draw_boundaries(ax, base, held | {"mu_s": base.mu_s}, y, ys)
    ax.set(xlabel=AXIS_LABELS[x], ylabel=AXIS_LABELS[y], xlim=(_edges(xs)[0], _edges(xs)[-1]))
    held_text = ", ".join(f"{AXIS_LABELS[c].split(' ')[0]} = {v:g}" for c, v in held.items() if c != "mu_d")
    ax.set_title(f"scenario ({settings.method}; {held_text})", fontsize=9)
    handles = [Patch(color=SCENARIO_COLOURS.get(n, OTHER_COLOUR), label=n) for n in names]
    ax.legend(handles=handles + ax.get_legend_handles_labels()[0], fontsize=7, loc="upper left",
              bbox_to_anchor=(0, -0.12), ncol=3)
    fig.suptitle("Regime map with the boundaries of the pure-rolling hypothesis")
    return fig


def _draw_boundaries(ax, base, held: dict, y: str, ys) -> None:
    """|T/N(0)| and max T/N at each y value (one vertical line if y does not change them)."""
    def group_at(value):
        point = {k: v for k, v in held.items() if k in ("theta0_deg",) + GEOMETRY_AXES}
        if y in ("theta0_deg",) + GEOMETRY_AXES:
            point[y] = value
        return thresholds(base, point.pop("theta0_deg", base.theta0_deg), point)

    at = [group_at(v) for v in (ys[:1] if y in FRICTION_ONLY_AXES else ys)]
    for key, label, ls in (("T_over_N_initial", "|T/N(0)|", "-"), ("T_over_N_max", "max T/N", "--")):
        vals = np.array([abs(getattr(t, key)) for t in at])
        if y in FRICTION_ONLY_AXES or ys.size == 1:
            ax.axvline(vals[0], color="k", ls=ls, lw=1.4, label=f"{label} = {vals[0]:.4f}", gid=key)
        else:
            ax.plot(vals, ys, "k", ls=ls, lw=1.4, marker=".", ms=3, label=label, gid=key)
