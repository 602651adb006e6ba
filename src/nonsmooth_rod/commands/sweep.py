"""`nonsmooth-rod sweep`: the rod's regime map over a grid of friction coefficients and tilts,
or, given a scene file, a map of that scene's outcomes over any of its keys (studies/maps.py)."""
from __future__ import annotations

import argparse
import copy
import sys

import numpy as np

from ..solvers.registry import DEFAULT_SOLVER, SOLVER_HELP, require_solver
from ..validation import InputError

DESCRIPTION = """\
Classify each point of a grid of the rod's parameters into the paper's scenarios —
slide-at-start, roll-until-r1 (rolling, then sliding when T/N reaches +μs), roll-until-r2
(rolling until T/N reaches −μs), roll-to-impact — and write DIR/regime_map.csv (one column per
axis, then scenario, status, t_transition, t_impact, the state at the impact, phases; also
regime_map.parquet when pyarrow is installed), DIR/thresholds.csv (the rolling hypothesis'
boundaries per θ0 and body), DIR/sweep.json (settings, grid, provenance, accuracy) and the map
DIR/regime_map.png. Every axis takes START:STOP:N (N values, ends included), a,b,c or one
number (then it is a fixed value, not an axis). Points run with Moreau–Jean (h = 2e-3, lemke)
by default; a random sample is re-run with the event-driven reference and the agreement is
reported. Rows are appended as they finish: rerunning an interrupted sweep with the same --out
computes only the missing points.

Any scene: `sweep SCENE.toml --axis PATH=START:STOP:N --axis PATH=a,b,c [--set PATH=VALUE]`
maps the outcome of the scene file over its keys (PATH as for `run --set`; `*` selects every
entry: contacts.*.law.mu_s). Writes DIR/map.csv (the axes, then regime = every contact's phase
sequence, status, held, each contact's first slip/stick/lift-off/impact time, the final state),
map.parquet, sweep.json, map.png (regimes over --map-axes) and, with --refine K, boundaries.csv
(each regime boundary bisected K times between neighbouring grid points). See docs/sweeps.md."""

ROD_DEFAULTS = {"mu_s": "0.05:0.5:46", "theta0_deg": "60", "method": "moreau-jean", "h": 2e-3,
                "solver": DEFAULT_SOLVER,
                "check": 8, "g": 9.81}

RANGE_AXES = (("ball-radius", "ball radius r, m (default 0.020)"),
              ("rod-diameter", "rod diameter d, m (default 0.006)"),
              ("length", "distance between the ball centres L, m (default 0.410)"),
              ("density", "density ρ, kg/m³ (default 7800)"),
              ("restitution", "Newton restitution e in [0, 1] (default 0)"))


def register(subparsers) -> None:
    from .options import add_physics_options, integer as _int, number as _float

    # The shared physics options define the body's values as single numbers; here they are
    # ranges, so this parser resolves the clash in favour of the definitions below.
    p = subparsers.add_parser("sweep", help="regime map over a grid of the rod's parameters",
                              description=DESCRIPTION, conflict_handler="resolve",
                              formatter_class=argparse.RawDescriptionHelpFormatter)
    add_physics_options(p)
    p.set_defaults(g=None)  # None: not given (a scene map refuses it); the rod's sweep fills 9.81
    scene = p.add_argument_group("a map of any scene")
    scene.add_argument("scene", nargs="?", default=None, help="scene file (.toml/.json): map it over --axis keys")
    scene.add_argument("--axis", action="append", default=[], metavar="PATH=START:STOP:N",
                       help="an axis of the map: a scene key and its values (START:STOP:N or a,b,c); repeatable")
    scene.add_argument("--set", action="append", default=[], metavar="PATH=VALUE",
                       help="override a value of the scene file for every point (repeatable)")
    scene.add_argument("--outcome", default=None,
                       help="comma-separated outcome columns to keep (default all; regime and status always)")
    scene.add_argument("--refine", type=_int, default=0, help="bisection steps per regime boundary (default 0)")
    g = p.add_argument_group("grid (each START:STOP:N, a,b,c or a number)")
    g.add_argument("--mu-s", default=None, help="static friction μs (default 0.05:0.5:46)")
    mu_d = g.add_mutually_exclusive_group()
    mu_d.add_argument("--mu-d-ratio", default=None, help="μd = R·μs, R in [0, 1] (default 0.75)")
    mu_d.add_argument("--mu-d", default=None, help="dynamic friction μd (points with μd > μs are skipped)")
    g.add_argument("--theta0-deg", default=None, help="initial tilt θ0 in degrees (default 60)")
    for name, text in RANGE_AXES:
        g.add_argument(f"--{name}", default=None, help=text)
    num = p.add_argument_group("numerics, execution and output")
    num.add_argument("--method", default=None, help="moreau-jean (default) or event-driven")
    num.add_argument("--h", type=_float, default=None,
                     help="Moreau-Jean step size, s (default 2e-3: times within 3h = 6 ms of the reference)")
    num.add_argument("--solver", default=None, help=SOLVER_HELP)
    num.add_argument("--check", type=_int, default=None,
                     help="points re-run with the event-driven reference to report the accuracy (default 8)")
    num.add_argument("--executor", default="local", help="local (a process pool, default) or dask")
    num.add_argument("--scheduler", default=None,
                     help="dask.distributed scheduler address (default: a LocalCluster on this machine)")
    num.add_argument("--jobs", type=_int, default=None, help="workers (default: 2, or 1 on one core)")
    num.add_argument("--out", default="sweep",
                     help="output folder (default ./sweep); an existing sweep there is resumed")
    num.add_argument("--map-axes", default=None, help="the map's two axes X,Y (default: μs and the first other axis)")
    num.add_argument("--no-plot", action="store_true", help="do not draw regime_map.png")
    num.add_argument("--format", default="png", help="comma-separated image formats: png, svg (default png)")
    num.add_argument("--dpi", type=_int, default=110, help="resolution of regime_map.png (default 110)")
    num.add_argument("--quiet", action="store_true", help="no progress bar and no summary")
    p.set_defaults(handler=cmd_sweep)


def _grid_and_body(args):
    """The grid from the range options, and the options for the base body: an option with one
    value is a fixed value of the body, not an axis."""
    from ..rod.regime import Grid, check_axis_values, parse_range

    body_args = copy.copy(args)
    extra = {}
    for name, _ in RANGE_AXES:
        attr = name.replace("-", "_")
        text = getattr(args, attr)
        if text is None:
            setattr(body_args, attr, 0.0 if attr == "restitution" else None)
            continue
        values = parse_range(text, f"--{name}", max_count=200)
        check_axis_values(attr, values)
        if values.size == 1:
            setattr(body_args, attr, float(values[0]))
        else:
            extra[attr] = values
            setattr(body_args, attr, float(values[0]))
    mu_s = parse_range(args.mu_s, "--mu-s")
    theta0 = parse_range(args.theta0_deg, "--theta0-deg", max_count=200)
    if args.mu_d is not None:
        grid = Grid(mu_s, theta0, mu_d=parse_range(args.mu_d, "--mu-d"), extra=extra)
    else:
        ratio = np.array([0.75]) if args.mu_d_ratio is None else parse_range(args.mu_d_ratio, "--mu-d-ratio")
        grid = Grid(mu_s, theta0, mu_d_ratio=ratio, extra=extra)
    body_args.mu_s, body_args.mu_d, body_args.theta0_deg = 0.28, 0.20, float(grid.theta0_deg[0])
    return grid, body_args


def _check_numerics(args) -> int:
    from ..rod.simulation import METHODS

    if args.method not in ("moreau-jean", "event-driven"):
        known = METHODS if args.method not in METHODS else ("moreau-jean", "event-driven")
        raise InputError(f"unknown method '{args.method}' for a sweep; choose from: {', '.join(known)}")
    if args.method == "moreau-jean":
        require_solver("--solver", args.solver)
        if not 0 < args.h <= 1e-2:
            raise InputError(f"--h must lie in (0, 0.01] s, got {args.h:g}")
    if not 0 <= args.check <= 1000:
        raise InputError(f"--check must lie in [0, 1000], got {args.check}")
    from ..rod.regime import default_jobs
    jobs = default_jobs() if args.jobs is None else args.jobs
    if not 1 <= jobs <= 64:
        raise InputError(f"--jobs must lie in [1, 64], got {jobs}")
    return jobs


def cmd_sweep(args) -> int:
    if args.scene is not None:
        return cmd_scene_map(args)
    if args.axis or args.set or args.outcome or args.refine:
        raise InputError("--axis, --set, --outcome and --refine map a scene file: give SCENE.toml first")
    for name, value in ROD_DEFAULTS.items():
        if getattr(args, name) is None:
            setattr(args, name, value)
    return _rod_sweep(args)


def _rod_sweep(args) -> int:
    from .options import build_problem, parse_image_formats
    from ..rod.regime import SweepSettings, sweep

    grid, body_args = _grid_and_body(args)
    n_points = len(grid.points())
    if n_points > 1_000_000:  # the rows are held in memory (about 1.5 kB each) for the final sort
        raise InputError(f"{n_points} grid points is too many (at most 1000000)")
    jobs = _check_numerics(args)
    formats = () if args.no_plot else parse_image_formats(args.format)  # (checking them imports matplotlib)
    if not 30 <= args.dpi <= 600:
        raise InputError(f"--dpi must lie in [30, 600], got {args.dpi}")
    map_axes = _map_axes_option(args.map_axes, grid)
    base = build_problem(body_args)
    settings = SweepSettings(method=args.method, h=args.h, solver=args.solver)
    result = sweep(base, grid, args.out, settings, jobs=jobs, executor=args.executor, scheduler=args.scheduler,
                   plot=not args.no_plot, formats=formats, dpi=args.dpi, map_axes=map_axes,
                   progress=not args.quiet and sys.stderr.isatty(), check_points=args.check)
    if not args.quiet:
        _report(result)
    failed = [r for r in result.grid_rows if r["scenario"] in ("failed",)]
    return 1 if failed else 0


def _map_axes_option(text, grid) -> tuple:
    if text is None:
        return (None, None)
    from ..rod.regime_figure import map_axes_of

    parts = [t.strip().replace("-", "_") for t in text.split(",")]
    if len(parts) != 2:
        raise InputError(f"--map-axes: expected X,Y, got {text!r}")
    return map_axes_of(grid, *parts)


def _counts_and_rate(title: str, column: str, labels) -> object:
    """Print a table of how many points each label has, and the computing rate; returns the console."""
    from collections import Counter

    from rich.console import Console
    from rich.table import Table

    from .options import escape

    console = Console()
    table = Table(title=title)
    table.add_column(column)
    table.add_column("points", justify="right")
    for name, n in sorted(Counter(labels).items()):
        table.add_row(escape(name), str(n))
    console.print(table)
    return console


def _rate_line(result) -> str:
    rate = result.computed / max(result.compute_s, 1e-9)
    return (f"{result.computed} computed, {result.reused} from an earlier run; {rate:,.0f} points/s "
            f"({result.compute_s:.2f} s computing, {result.wall_s:.2f} s in all)")


def _report(result) -> None:
    console = _counts_and_rate(f"regime map, {len(result.grid_rows)} points", "scenario",
                               (r["scenario"] for r in result.grid_rows))
    console.print(_rate_line(result))
    from ..rod.regime import accuracy_text

    console.print(accuracy_text(result.accuracy))
    for th in result.thresholds[:12]:
        extra = "".join(f", {k} = {v:g}" for k, v in th.params.items())
        console.print(f"θ0 = {th.theta0_deg:g}°{extra}: T/N(0) = {th.T_over_N_initial:.4f}, "
                      f"max T/N = {th.T_over_N_max:.4f} (t = {th.t_max:.4f} s), min T/N = {th.T_over_N_min:.4f}")
    console.print("files: " + ", ".join(str(f) for f in result.files))


def _refuse_rod_options(args) -> None:
    rod = [n for n in ROD_DEFAULTS if getattr(args, n) is not None]
    rod += [n for n in ("mu_d", "mu_d_ratio", "mass", "xi", "inertia") if getattr(args, n) is not None]
    rod += [n.replace("-", "_") for n, _ in RANGE_AXES if getattr(args, n.replace("-", "_")) is not None]
    if rod:
        raise InputError(f"--{rod[0].replace('_', '-')} is an option of the rod's sweep; a scene file is "
                         "mapped over --axis PATH=... and run with its own simulation table (use --set)")


def cmd_scene_map(args) -> int:
    """`sweep SCENE.toml --axis ...`: the map of any scene (studies/maps.py)."""
    from ..studies.maps import sweep as scene_sweep
    from .options import parse_image_formats

    _refuse_rod_options(args)
    from ..rod.regime import default_jobs

    jobs = default_jobs() if args.jobs is None else args.jobs
    if not 1 <= jobs <= 64:
        raise InputError(f"--jobs must lie in [1, 64], got {jobs}")
    formats = () if args.no_plot else parse_image_formats(args.format)
    if not 30 <= args.dpi <= 600:
        raise InputError(f"--dpi must lie in [30, 600], got {args.dpi}")
    outcomes = None if args.outcome is None else [o.strip() for o in args.outcome.split(",") if o.strip()]
    map_axes = None if args.map_axes is None else [t.strip() for t in args.map_axes.split(",")]
    result = scene_sweep(args.scene, args.axis, args.out, sets=args.set, outcomes=outcomes, refine=args.refine,
                         jobs=jobs, executor=args.executor, scheduler=args.scheduler, plot=not args.no_plot,
                         map_axes=map_axes, formats=formats, dpi=args.dpi,
                         progress=not args.quiet and sys.stderr.isatty(), command=" ".join(sys.argv))
    if not args.quiet:
        _report_map(result)
    return 1 if any(r["status"] == "failed" for r in result.rows) else 0


def _report_map(result) -> None:
    from .options import escape

    console = _counts_and_rate(f"map of {len(result.rows)} points: regimes (each contact's phase sequence)",
                               "regime", (r["regime"] for r in result.rows))
    console.print(_rate_line(result))
    for b in result.boundaries[:20]:
        console.print(escape(f"boundary along {b['axis']} in [{b['lo']:.6g}, {b['hi']:.6g}]: "
                             f"{b['regime_lo']} | {b['regime_hi']}"))
    console.print("files: " + ", ".join(str(f) for f in result.files))
