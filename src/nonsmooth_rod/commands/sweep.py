"""`nonsmooth-rod sweep`: the regime map over a grid of friction coefficients and tilts."""
from __future__ import annotations

import argparse
import copy
import sys

from ..validation import InputError

DESCRIPTION = """\
Classify each (μs, μd, θ0) of a grid into the paper's scenarios — slide-at-start,
roll-until-r1 (rolling, then sliding when T/N reaches +μs), roll-until-r2 (rolling until T/N
reaches −μs), roll-to-impact — and write DIR/regime_map.csv (mu_s,mu_d,theta0_deg,scenario,
t_transition,t_impact,phases), DIR/thresholds.csv (the rolling hypothesis' boundaries per θ0) and
the map DIR/regime_map.png with those boundaries. Ranges are START:STOP:N (N values, ends
included), a,b,c or one number. Rows are appended as they finish: rerunning an interrupted
sweep with the same --out computes only the missing points."""


def register(subparsers) -> None:
    from .options import add_physics_options, integer as _int, number as _float

    # The shared physics options define --mu-s/--mu-d/--theta0-deg as single numbers; here they
    # are ranges, so this parser resolves the clash in favour of the definitions below.
    p = subparsers.add_parser("sweep", help="regime map over a grid of μs, μd, θ0",
                              description=DESCRIPTION, conflict_handler="resolve",
                              formatter_class=argparse.RawDescriptionHelpFormatter)
    add_physics_options(p)
    g = p.add_argument_group("grid")
    g.add_argument("--mu-s", default="0.05:0.5:46", help="static friction μs: START:STOP:N (default 0.05:0.5:46)")
    mu_d = g.add_mutually_exclusive_group()
    mu_d.add_argument("--mu-d-ratio", type=_float, default=None, help="μd = R·μs, R in [0, 1] (default 0.75)")
    mu_d.add_argument("--mu-d", default=None, help="dynamic friction μd: START:STOP:N (points with μd > μs are skipped)")
    g.add_argument("--theta0-deg", default="60", help="initial tilt θ0 in degrees: START:STOP:N or a number (default 60)")
    num = p.add_argument_group("numerics and output")
    num.add_argument("--method", default="event-driven", help="event-driven (default) or moreau-jean")
    num.add_argument("--h", type=_float, default=1e-4, help="Moreau-Jean step size, s (default 1e-4)")
    num.add_argument("--solver", default="lemke", help="Moreau-Jean one-step solver (default lemke)")
    num.add_argument("--jobs", type=_int, default=None, help="worker processes (default: 2, or 1 on one core)")
    num.add_argument("--out", default="sweep", help="output folder (default ./sweep); an existing sweep there is resumed")
    num.add_argument("--no-plot", action="store_true", help="do not draw regime_map.png")
    num.add_argument("--format", default="png", help="comma-separated image formats: png, svg (default png)")
    num.add_argument("--dpi", type=_int, default=110, help="resolution of regime_map.png (default 110)")
    num.add_argument("--quiet", action="store_true", help="no progress bar and no summary")
    p.set_defaults(handler=cmd_sweep)


def cmd_sweep(args) -> int:
    from .options import build_problem
    from ..rod.plotting import FORMATS
    from ..rod.regime import Grid, SweepSettings, default_jobs, parse_range, sweep
    from ..rod.simulation import METHODS

    mu_s = parse_range(args.mu_s, "--mu-s")
    theta0 = parse_range(args.theta0_deg, "--theta0-deg", max_count=200)
    if args.mu_d is not None:
        grid = Grid(mu_s, theta0, mu_d=parse_range(args.mu_d, "--mu-d"))
    else:
        grid = Grid(mu_s, theta0, mu_d_ratio=0.75 if args.mu_d_ratio is None else args.mu_d_ratio)
    n_points = len(grid.points())
    if n_points > 200_000:
        raise InputError(f"{n_points} grid points is too many (at most 200000)")
    if args.method not in METHODS:
        raise InputError(f"unknown method '{args.method}'; choose from: {', '.join(METHODS)}")
    if args.method == "moreau-jean":
        from ..solvers import available_solvers
        if args.solver not in available_solvers():
            raise InputError(f"unknown solver '{args.solver}'; choose from: {', '.join(available_solvers())}")
        if not 0 < args.h <= 1e-2:
            raise InputError(f"--h must lie in (0, 0.01] s, got {args.h:g}")
    jobs = default_jobs() if args.jobs is None else args.jobs
    if not 1 <= jobs <= 64:
        raise InputError(f"--jobs must lie in [1, 64], got {jobs}")
    formats = tuple(dict.fromkeys(f.strip().lower() for f in args.format.split(",") if f.strip()))
    if not formats or any(f not in FORMATS for f in formats):
        raise InputError(f"--format must be among {', '.join(FORMATS)}, got {args.format!r}")
    if not 30 <= args.dpi <= 600:
        raise InputError(f"--dpi must lie in [30, 600], got {args.dpi}")
    # The body (and e, g) from the shared options; friction and tilt are set per grid point.
    body_args = copy.copy(args)
    body_args.mu_s, body_args.mu_d, body_args.theta0_deg = 0.28, 0.20, float(grid.theta0_deg[0])
    base = build_problem(body_args)
    settings = SweepSettings(method=args.method, h=args.h, solver=args.solver)
    result = sweep(base, grid, args.out, settings, jobs=jobs, plot=not args.no_plot, formats=formats,
                   dpi=args.dpi, progress=not args.quiet and sys.stderr.isatty())
    if not args.quiet:
        _report(result)
    failed = [r for r in result.grid_rows if r["scenario"] in ("failed",)]
    return 1 if failed else 0


def _report(result) -> None:
    from collections import Counter

    from rich.console import Console
    from rich.table import Table

    console = Console()
    counts = Counter(r["scenario"] for r in result.grid_rows)
    table = Table(title=f"regime map, {len(result.grid_rows)} points")
    table.add_column("scenario")
    table.add_column("points", justify="right")
    for name, n in sorted(counts.items()):
        table.add_row(name, str(n))
    console.print(table)
    console.print(f"{result.computed} computed, {result.reused} from an earlier run")
    for th in result.thresholds:
        console.print(f"θ0 = {th.theta0_deg:g}°: T/N(0) = {th.T_over_N_initial:.4f}, "
                      f"max T/N = {th.T_over_N_max:.4f} (t = {th.t_max:.4f} s), min T/N = {th.T_over_N_min:.4f}")
    console.print("files: " + ", ".join(str(f) for f in result.files))
