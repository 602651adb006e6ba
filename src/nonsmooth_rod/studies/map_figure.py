"""The figure of a map of any scene: the regime at every grid point over two axes (the other
axes at their first value), with the refined boundaries as black marks."""
from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from ..io import atomic_path

PALETTE = ("#1f5fa8", "#d62728", "#ff9f4a", "#2ca02c", "#8fbbe0", "#9467bd", "#8c564b", "#e377c2",
           "#bcbd22", "#17becf", "#7f7f7f", "#aec7e8")
SPECIAL = {"refused": "#dddddd", "failed": "#444444"}


def _slice(result, x, y) -> list[dict]:
    """The rows with every axis other than x and y at its first value."""
    fixed = {a.path: float(a.values[0]) for a in result.axes if a.path not in (x, y)}
    return [r for r in result.rows if all(abs(r[p] - v) <= 1e-12 * max(1.0, abs(v)) for p, v in fixed.items())]


def _colours(regimes) -> dict:
    normal = [g for g in regimes if g not in SPECIAL]
    return {g: PALETTE[i % len(PALETTE)] for i, g in enumerate(normal)} | {
        g: SPECIAL[g] for g in regimes if g in SPECIAL}


def _edges(values: np.ndarray) -> np.ndarray:
    if values.size == 1:
        return np.array([values[0] - 0.5, values[0] + 0.5])
    mid = 0.5 * (values[1:] + values[:-1])
    return np.concatenate([[2 * values[0] - mid[0]], mid, [2 * values[-1] - mid[-1]]])


def map_figure(result, x: str, y: str | None = None) -> Figure:
    """Cells coloured by regime over (x, y) (one row of cells without y); a legend per regime."""
    rows = _slice(result, x, y)
    regimes = sorted({r["regime"] for r in rows})
    colour = _colours(regimes)
    index = {g: i for i, g in enumerate(regimes)}
    xs = next(a.values for a in result.axes if a.path == x)
    ys = next(a.values for a in result.axes if a.path == y) if y else np.array([0.0])
    grid = np.full((ys.size, xs.size), np.nan)
    for r in rows:
        grid[int(np.searchsorted(ys, r[y])) if y else 0, int(np.searchsorted(xs, r[x]))] = index[r["regime"]]
    from matplotlib.colors import ListedColormap

    fig = Figure(figsize=(8.5, 5.5 + 0.25 * len(regimes)), layout="constrained")
    ax = fig.add_subplot()
    cmap = ListedColormap([colour[g] for g in regimes] or ["#ffffff"])
    ax.pcolormesh(_edges(xs), _edges(ys), grid, cmap=cmap, vmin=-0.5, vmax=max(len(regimes), 1) - 0.5)
    for b in result.boundaries:
        if (y is None or b["axis"] in (x, y)) and b in _slice_boundaries(result, x, y):
            ax.plot(b[x], b[y] if y else 0.0, "k.", ms=4)
    ax.set_xlabel(x)
    ax.set_ylabel(y or "")
    ax.set_title(f"regimes: {len(regimes)} (each contact's phase sequence)")
    handles = [Patch(color=colour[g], label=_short(g)) for g in regimes]
    fig.legend(handles=handles, loc="outside lower center", fontsize=7, ncols=1 if len(regimes) > 4 else 2)
    return fig


def _slice_boundaries(result, x, y) -> list[dict]:
    fixed = {a.path: float(a.values[0]) for a in result.axes if a.path not in (x, y)}
    return [b for b in result.boundaries if all(abs(b[p] - v) <= 1e-12 * max(1.0, abs(v)) for p, v in fixed.items())]


def _short(regime: str, width: int = 110) -> str:
    return regime if len(regime) <= width else regime[: width - 1] + "…"


def save(fig: Figure, path, formats=("png",), dpi: int = 110) -> list[Path]:
    """Write `fig` as path.<fmt> for each format, atomically."""
    written = []
    for fmt in formats:
        target = Path(path).with_name(f"{Path(path).name}.{fmt}")
        with atomic_path(target) as tmp:
            fig.savefig(tmp, dpi=dpi, format=fmt)
        written.append(target)
    return written
