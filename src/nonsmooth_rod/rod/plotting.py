"""Figures of rod runs: the paper's Fig. 14–16 panel, a frame strip and a GIF of the motion.

Built on matplotlib's object API (`Figure` with the Agg canvas), never pyplot: no global figure
state, no window, safe in worker processes and in a notebook whatever its backend.

Every figure function returns the `Figure` it drew, with the data it plotted readable back:
axes carry labels (`axis(fig, "theta")`) and the curves of a run carry a gid (`DATA_GID` for
the lines, `MARKER_GID` for a compared run's markers); `drawn_series(ax, gid)` reassembles the
regime-coloured pieces into the plotted arrays, so tests can compare them with the run's own.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ..io import IMAGE_FORMATS, atomic_path, read_csv
from ..result_files import check_files, describe_folder, folder_kind
from ..plots.frames import frame_indices  # noqa: F401  (one frame picker for every animation)
from .problem import RodProblem
from ..results import Phase
from .hypotheses import RollingHypothesis, rolling_hypothesis
from ..validation import InputError

# The paper's colours: sliding red, rolling blue; flight (not in the paper) grey.
REGIME_COLOURS = {"stick": "tab:blue", "slip+": "tab:red", "slip-": "tab:red", "flight": "tab:gray"}
REGIME_WORDS = {"stick": "rolling", "slip+": "sliding (v_C > 0)", "slip-": "sliding (v_C < 0)",
                "flight": "flight"}
DATA_GID = "data"        # a run drawn as regime-coloured line pieces sharing the switch samples
MARKER_GID = "markers"   # a compared run drawn as regime-coloured markers, pieces not overlapping
ROLLING_GID = "rolling"  # T/N under the pure-rolling hypothesis
FORMATS = IMAGE_FORMATS

# Panels (c)–(j) of the paper's Fig. 14–16: table column (or derived series) and its axis label.
PANEL_SERIES = (
    ("theta", "(c) θ [rad]"),
    ("theta_dot", "(d) θ̇ [rad/s]"),
    ("theta_ddot", "(e) θ̈ [rad/s²]"),
    ("x_O", "(f) x_O [m]"),
    ("x_O_dot", "(g) ẋ_O [m/s]"),
    ("x_O_ddot", "(h) ẍ_O [m/s²]"),
    ("N", "(i) N [N]"),
    ("T_over_N", "(j) actual T/N"),
)


# --------------------------------------------------------------------------- run data
@dataclass
class RunData:
    """What the figures need of one run, from memory (`from_run`) or a results folder."""

    problem: RodProblem
    method: str
    table: dict
    phases: list
    impact: dict | None
    rolling: RollingHypothesis
    status: str = "ok"
    source: str = ""

    @classmethod
    def from_run(cls, run) -> "RunData":
        return cls(run.problem, run.method, run.table, list(run.phases), run.impact, run.rolling,
                   run.status, source="memory")

    def series(self, key: str) -> np.ndarray:
        """A table column, or T/N (NaN where N ≤ 0: no contact force to compare with)."""
        if key == "T_over_N":
            N, T = np.asarray(self.table["N"], float), np.asarray(self.table["T"], float)
            with np.errstate(divide="ignore", invalid="ignore"):
                return np.where(N > 0, T / N, np.nan)
        return np.asarray(self.table[key], dtype=float)

    @property
    def t_end(self) -> float:
        return float(self.table["t"][-1])


def problem_from_params(params: dict, where: str = "summary.json") -> RodProblem:
    """Rebuild the RodProblem from the "params" block of summary.json (every input in SI)."""
    keys = ("mass", "xi", "inertia", "ball_radius", "length", "mu_s", "mu_d", "theta0_rad",
            "restitution", "g")
    missing = [k for k in keys if k not in params]
    if missing:
        raise InputError(f"{where}: params lacks {', '.join(missing)}")
    try:
        values = {k: float(params[k]) for k in keys}
    except (TypeError, ValueError):
        raise InputError(f"{where}: params must be numbers") from None
    theta0 = values.pop("theta0_rad")
    return RodProblem(theta0=theta0, **values)


def _refuse_other_results(folder: Path) -> None:
    """A folder of `run` or `sweep` given to `plot`: say what it holds and what draws it."""
    kind = folder_kind(folder)
    hints = {"run": f"draw it with `nonsmooth-rod animate {folder}` (its figure is {folder / 'figure.png'})",
             "sweep": f"its map is {folder / 'regime_map.png'}"}
    if kind in hints:
        raise InputError(f"{folder} holds {describe_folder(folder)}; `plot` draws the results of "
                         f"`nonsmooth-rod simulate`: {hints[kind]}")


def load_run_dir(folder, *, rolling: bool = True) -> RunData:
    """Read `folder/trajectory.csv` and `folder/summary.json` as written by `simulate`."""
    folder = Path(folder)
    if not folder.exists():
        raise InputError(f"results folder '{folder}' does not exist")
    if not folder.is_dir():
        raise InputError(f"'{folder}' is not a folder (give the folder simulate wrote)")
    _refuse_other_results(folder)
    traj_path, summary_path = folder / "trajectory.csv", folder / "summary.json"
    for path in (traj_path, summary_path):
        if not path.is_file():
            raise InputError(f"{path} not found: make it with `nonsmooth-rod simulate --out {folder}`")
    try:
        summary = json.loads(summary_path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as err:
        raise InputError(f"{summary_path} is not valid JSON ({err.__class__.__name__}: {err})") from None
    if not isinstance(summary, dict) or not isinstance(summary.get("params"), dict):
        raise InputError(f"{summary_path} has no \"params\" object: not a summary written by simulate")
    check_files(folder, summary, "simulate")
    problem = problem_from_params(summary["params"], str(summary_path))
    try:
        table = read_csv(traj_path)
    except (IndexError, OSError, UnicodeDecodeError, ValueError) as err:
        raise InputError(f"{traj_path} could not be read ({err})") from None
    needed = ("t", "theta", "theta_dot", "theta_ddot", "x_O", "x_O_dot", "x_O_ddot", "N", "T", "mode")
    missing = [c for c in needed if c not in table]
    if missing:
        raise InputError(f"{traj_path} lacks the column(s) {', '.join(missing)}")
    if len(table["t"]) < 2:
        raise InputError(f"{traj_path} holds fewer than two samples: nothing to plot")
    for c in needed[:-1]:
        if table[c].dtype == object:  # a numeric column that did not parse: blank or text cells
            try:
                table[c] = np.array([float(x) if x != "" else np.nan for x in table[c]])
            except ValueError:
                raise InputError(f"{traj_path}: column {c} holds text where numbers belong") from None
    table["mode"] = np.asarray(table["mode"], dtype=object)
    bad = sorted(set(table["mode"]) - set(REGIME_COLOURS))
    if bad:
        raise InputError(f"{traj_path}: unknown mode(s) {', '.join(map(str, bad))}")
    phases = [Phase(p["mode"], float(p["t_start"]), float(p["t_end"])) for p in summary.get("phases") or []]
    rh = rolling_hypothesis(problem) if rolling else None
    return RunData(problem, str(summary.get("method", "?")), table, phases, summary.get("impact"), rh,
                   str(summary.get("status", "?")), source=str(folder))


# --------------------------------------------------------------------------- drawing helpers
def regime_pieces(modes) -> list[tuple[int, int, str]]:
    """Maximal runs of one mode as (start, stop, mode), stop exclusive."""
    modes = np.asarray(modes, dtype=object)
    pieces, start = [], 0
    for k in range(1, len(modes) + 1):
        if k == len(modes) or modes[k] != modes[start]:
            pieces.append((start, k, str(modes[start])))
            start = k
    return pieces


def plot_by_regime(ax, t, y, modes, *, markers: bool = False, gid: str | None = None,
                   n_markers: int = 45, **kw) -> None:
    """y(t) coloured by regime. Lines: each piece after the first also starts from the previous
    piece's last sample (the switch instant), so the curve stays connected and changes colour
    exactly at the switch. Markers: pieces do not overlap; every sample is drawn once (in the
    data; about `n_markers` are shown, so the lines beneath stay visible)."""
    t, y = np.asarray(t, float), np.asarray(y, float)
    gid = gid or (MARKER_GID if markers else DATA_GID)
    stride = max(1, len(t) // n_markers)
    for start, stop, mode in regime_pieces(modes):
        begin = start if markers else max(start - 1, 0)
        style = dict(color=REGIME_COLOURS.get(mode, "k"))
        if markers:
            style.update(ls="none", marker="o", ms=3.5, mfc="none", mew=0.8, markevery=stride)
        else:
            style.update(lw=1.4)
        style.update(kw)
        ax.plot(t[begin:stop], y[begin:stop], gid=gid, **style)


def drawn_series(ax, gid: str = DATA_GID) -> tuple[np.ndarray, np.ndarray]:
    """The (x, y) arrays drawn with `plot_by_regime(..., gid=gid)`, pieces reassembled."""
    lines = [ln for ln in ax.get_lines() if ln.get_gid() == gid]
    if not lines:
        return np.empty(0), np.empty(0)
    overlap = 0 if gid.startswith(MARKER_GID) else 1
    xs, ys = [], []
    for k, ln in enumerate(lines):
        x, y = (np.asarray(a, float) for a in ln.get_data())
        if k > 0 and overlap:
            x, y = x[overlap:], y[overlap:]
        xs.append(x)
        ys.append(y)
    return np.concatenate(xs), np.concatenate(ys)


def axis(fig: Figure, label: str):
    """The axes of `fig` labelled `label` (figure functions label their axes by content)."""
    for ax in fig.axes:
        if ax.get_label() == label:
            return ax
    raise KeyError(f"no axes labelled {label!r}; have {[a.get_label() for a in fig.axes]}")


def save_figure(fig: Figure, path, formats=("png",), dpi: int = 110) -> list[Path]:
    """Write `fig` as path.<fmt> for each format, atomically; returns the written paths."""
    path = Path(path)
    # Only a known image suffix is replaced: "fig22_mu0.1" keeps its ".1".
    stem = path.stem if path.suffix.lower().lstrip(".") in ("png", "svg", "pdf", "jpg") else path.name
    written = []
    for fmt in formats:
        target = path.with_name(f"{stem}.{fmt}")
        with atomic_path(target) as tmp:
            if fmt == "png":
                _save_png(fig, tmp, dpi)
            else:
                fig.savefig(tmp, dpi=dpi, format=fmt)
        written.append(target)
    return written


def _save_png(fig: Figure, path, dpi: int) -> None:
    """A lossless PNG (publication figures keep every colour matplotlib drew)."""
    fig.savefig(path, dpi=dpi, format="png")


def _fmt_time(t) -> str:
    return "—" if t is None else f"{t:.5f} s"


def _limits_of(ax, y) -> None:
    """y-limits from one series only: a compared Moreau–Jean run's impact step (impulse / h)
    would otherwise squash the whole panel."""
    y = np.asarray(y, float)
    y = y[np.isfinite(y)]
    if y.size:
        lo, hi = float(y.min()), float(y.max())
        pad = 0.06 * (hi - lo) if hi > lo else max(abs(hi) * 0.1, 1e-9)
        ax.set_ylim(lo - pad, hi + pad)


def _mark_impact(ax, data: RunData) -> None:
    if data.impact:
        ax.axvline(data.impact["t"], color="k", ls=":", lw=0.8)


# --------------------------------------------------------------------------- Fig. 14–16 panel
def _info_text(data: RunData, compare: RunData | None) -> str:
    p, rh = data.problem, data.rolling
    lines = [
        f"μs = {p.mu_s:g}    μd = {p.mu_d:g}",
        f"θ0 = {p.theta0_deg:g}°    e = {p.restitution:g}",
        "",
        "pure-rolling hypothesis:",
        f"  T/N(0) = {rh.T_over_N_initial:.4f}",
        f"  max T/N = {rh.T_over_N_max:.4f} at {_fmt_time(rh.t_max)}",
        f"  t_r1 (T/N = +μs) = {_fmt_time(rh.t_r1)}",
        f"  t_r2 (T/N = −μs) = {_fmt_time(rh.t_r2)}",
        f"  t_h (horizontal) = {_fmt_time(rh.t_horizontal)}",
        "",
        f"{data.method} (lines): {data.status}",
    ]
    for ph in data.phases[:6]:
        lines.append(f"  {ph.mode:<6} {ph.t_start:.5f} → {ph.t_end:.5f} s")
    if len(data.phases) > 6:
        lines.append(f"  … {len(data.phases) - 6} more phases")
    if data.impact:
        lines.append(f"  impact of B: t = {data.impact['t']:.5f} s")
    if compare is not None:
        lines.append(f"{compare.method} (markers): {compare.status}")
        if compare.impact:
            lines.append(f"  impact of B: t = {compare.impact['t']:.5f} s")
    return "\n".join(lines)


def panel_figure(data: RunData, compare: RunData | None = None) -> Figure:
    """The paper's Fig. 14–16 for one run: (a) T/N under pure rolling with ±μs, t_r1, t_r2;
    (b) parameters and characteristic times; (c)–(j) θ, θ̇, θ̈, x_O, ẋ_O, ẍ_O, N and the actual
    T/N, coloured by regime (rolling blue, sliding red). `compare` (e.g. a Moreau–Jean run of
    the same problem) is drawn as markers over `data`'s lines."""
    p, rh = data.problem, data.rolling
    fig = Figure(figsize=(20, 7.6), layout="constrained")
    axes = fig.subplots(2, 5)
    ax = axes[0, 0]
    ax.set_label("rolling_T_over_N")
    ax.plot(rh.t, rh.T_over_N, color="tab:blue", lw=1.4, gid=ROLLING_GID)
    for level in (p.mu_s, -p.mu_s):
        ax.axhline(level, color="k", ls="--", lw=0.8)
    for name in ("t_r1", "t_r2"):
        tv = getattr(rh, name)
        if tv is not None:
            ax.axvline(tv, color="tab:green", lw=0.9)
            ax.annotate(name, (tv, 0.04), xycoords=("data", "axes fraction"), xytext=(3, 0),
                        textcoords="offset points", color="tab:green")
    ax.set(title="(a) T/N under pure rolling", xlabel="t [s]")
    info = axes[0, 1]
    info.set_label("info")
    info.axis("off")
    info.set_title("(b) friction and characteristic times")
    info.text(0.0, 1.0, _info_text(data, compare), va="top", ha="left", family="monospace",
              fontsize=9, transform=info.transAxes)
    slots = list(axes[0, 2:]) + list(axes[1, :])
    for ax, (key, label) in zip(slots, PANEL_SERIES):
        ax.set_label(key)
        plot_by_regime(ax, data.table["t"], data.series(key), data.table["mode"])
        if compare is not None:
            plot_by_regime(ax, compare.table["t"], compare.series(key), compare.table["mode"], markers=True)
            _limits_of(ax, data.series(key))
        _mark_impact(ax, data)
        ax.set(title=label, xlabel="t [s]")
    ax = axis(fig, "T_over_N")
    for level, ls in ((p.mu_s, "--"), (-p.mu_s, "--"), (p.mu_d, ":"), (-p.mu_d, ":")):
        ax.axhline(level, color="k", ls=ls, lw=0.8)
    # Contact forces obey |T| ≤ μs N, so ±1.3 μs frames the data; a spike would hide the rest.
    ymax = max(1.3 * p.mu_s, 0.2)
    ax.set_ylim(-ymax, ymax)
    handles = [ax.plot([], [], color="tab:blue", lw=1.4, label="rolling")[0],
               ax.plot([], [], color="tab:red", lw=1.4, label="sliding")[0]]
    if compare is not None:
        handles.append(ax.plot([], [], ls="none", marker="o", mfc="none", color="k",
                               label=f"{compare.method} (markers)")[0])
    ax.legend(handles=handles, loc="lower left", fontsize=8)
    impact = f"; impact of B at t = {data.impact['t']:.5f} s" if data.impact else ""
    fig.suptitle(f"{data.method}: μs = {p.mu_s:g}, μd = {p.mu_d:g}, θ0 = {p.theta0_deg:g}°{impact}")
    return fig


def lines_and_markers(first: RunData, second: RunData) -> tuple[RunData, RunData]:
    """Which of two runs of one problem to draw as lines and which as markers: a time-stepping
    (Moreau–Jean) run is the markers whatever the order it was given in; otherwise the first
    is the lines. The lines' run keeps the rolling hypothesis for panel (a)."""
    if first.method == "moreau-jean" and second.method != "moreau-jean":
        if second.rolling is None:
            second.rolling = first.rolling
        return second, first
    return first, second


def plot_run(run, path, *, formats=("png",), dpi: int = 110, compare=None) -> list[Path]:
    """The Fig. 14-style panel of a RodRun (or RunData) written atomically to `path`
    (suffix replaced per format). Kept as `simulate`'s entry point for figure.png."""
    data = run if isinstance(run, RunData) else RunData.from_run(run)
    if compare is not None and not isinstance(compare, RunData):
        compare = RunData.from_run(compare)
    return save_figure(panel_figure(data, compare), path, formats, dpi)


# --------------------------------------------------------------------------- the body itself
def rod_outline(problem: RodProblem, x_O: float, theta: float, y_O: float | None = None) -> dict:
    """Centres of the balls and of mass for a pose (ball A on the plane unless y_O is given)."""
    y_O = problem.ball_radius if y_O is None else y_O
    c, s = math.cos(theta), math.sin(theta)
    return {"A": (x_O, y_O), "B": (x_O + problem.length * c, y_O + problem.length * s),
            "G": (x_O + problem.xi * c, y_O + problem.xi * s), "C": (x_O, y_O - problem.ball_radius)}


def _draw_pose(ax, problem: RodProblem, x_O, theta, mode, *, trail=None, rod_gid="rod") -> None:
    from matplotlib.patches import Circle

    pose = rod_outline(problem, x_O, theta)
    r = problem.ball_radius
    ax.axhline(0.0, color="0.3", lw=1.2)
    if trail is not None:
        ax.plot(*trail, color="0.75", lw=0.8)
    (xa, ya), (xb, yb), (xg, yg), (xc, yc) = pose["A"], pose["B"], pose["G"], pose["C"]
    ax.plot([xa, xb], [ya, yb], color="0.25", lw=2.5, solid_capstyle="round", gid=rod_gid)
    for (x, y) in (pose["A"], pose["B"]):
        ax.add_patch(Circle((x, y), r, fc="0.85", ec="0.25", lw=1.0))
    ax.plot([xg], [yg], "k+", ms=6)
    ax.plot([xc], [yc], "o", color=REGIME_COLOURS.get(mode, "k"), ms=7, gid="contact")


def _pose_limits(data: RunData) -> tuple[tuple[float, float], tuple[float, float]]:
    p, tab = data.problem, data.table
    xs = np.concatenate([tab["x_O"], tab["x_O"] + p.length * np.cos(tab["theta"])])
    ys = p.ball_radius + p.length * np.sin(tab["theta"])
    pad = 1.5 * p.ball_radius
    return (float(xs.min()) - pad, float(xs.max()) + pad), (-0.3 * pad, float(ys.max()) + pad)


def frames_figure(data: RunData, n_frames: int = 8, columns: int = 4) -> Figure:
    """A strip of poses at evenly spaced times; ball A's contact point coloured by regime and
    the path of ball B's centre traced so far."""
    if not 2 <= n_frames <= 48:
        raise InputError(f"frames must lie in [2, 48], got {n_frames}")
    p, tab = data.problem, data.table
    idx = frame_indices(tab["t"], n_frames)
    columns = min(columns, n_frames)
    rows = math.ceil(n_frames / columns)
    xlim, ylim = _pose_limits(data)
    width = 3.3
    height = width * (ylim[1] - ylim[0]) / (xlim[1] - xlim[0]) + 0.5
    fig = Figure(figsize=(width * columns, height * rows), layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, columns, squeeze=False)).ravel()
    xb = tab["x_O"] + p.length * np.cos(tab["theta"])
    yb = p.ball_radius + p.length * np.sin(tab["theta"])
    for k, ax in enumerate(axes):
        if k >= n_frames:
            ax.axis("off")
            continue
        i = idx[k]
        ax.set_label(f"frame{k}")
        mode = str(tab["mode"][i])
        _draw_pose(ax, p, float(tab["x_O"][i]), float(tab["theta"][i]), mode,
                   trail=(xb[: i + 1], yb[: i + 1]))
        ax.set(xlim=xlim, ylim=ylim, aspect="equal", xticks=[], yticks=[])
        ax.set_title(f"t = {tab['t'][i]:.3f} s, x_O = {1e3 * tab['x_O'][i]:+.1f} mm\n"
                     f"{REGIME_WORDS.get(mode, mode)}", fontsize=9,
                     color=REGIME_COLOURS.get(mode, "k"))
    fig.suptitle(f"{data.method}: μs = {p.mu_s:g}, μd = {p.mu_d:g}, θ0 = {p.theta0_deg:g}° — "
                 "contact point of ball A: blue rolling, red sliding")
    return fig


def write_gif(data: RunData, path, n_frames: int = 40, frame_ms: int = 80, dpi: int = 60) -> Path:
    """An animation of the motion as a GIF (Pillow, through matplotlib's Agg canvas)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image

    if not 2 <= n_frames <= 400:
        raise InputError(f"GIF frames must lie in [2, 400], got {n_frames}")
    p, tab = data.problem, data.table
    xlim, ylim = _pose_limits(data)
    xb = tab["x_O"] + p.length * np.cos(tab["theta"])
    yb = p.ball_radius + p.length * np.sin(tab["theta"])
    images = []
    for i in frame_indices(tab["t"], n_frames):
        fig = Figure(figsize=(6.0, 6.0 * (ylim[1] - ylim[0]) / (xlim[1] - xlim[0]) + 0.5))
        canvas = FigureCanvasAgg(fig)
        ax = fig.add_axes((0.02, 0.02, 0.96, 0.86))
        mode = str(tab["mode"][i])
        _draw_pose(ax, p, float(tab["x_O"][i]), float(tab["theta"][i]), mode, trail=(xb[: i + 1], yb[: i + 1]))
        ax.set(xlim=xlim, ylim=ylim, aspect="equal", xticks=[], yticks=[])
        ax.set_title(f"t = {tab['t'][i]:.3f} s  {REGIME_WORDS.get(mode, mode)}", fontsize=10,
                     color=REGIME_COLOURS.get(mode, "k"))
        fig.set_dpi(dpi)
        canvas.draw()
        images.append(Image.fromarray(np.asarray(canvas.buffer_rgba())).convert("P", palette=Image.ADAPTIVE))
    path = Path(path)
    with atomic_path(path) as tmp:
        images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:], duration=frame_ms,
                       loop=0, optimize=True)
    return path
