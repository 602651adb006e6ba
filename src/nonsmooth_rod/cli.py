"""Nonsmooth contact dynamics of the tilted two-ball rod: simulate, plot, sweep, benchmark.

Every mistake in the input ends with one line on stderr and exit status 2; a run that fails
(solver failure, Painlevé stop) still writes its files and exits with status 1.
"""
from __future__ import annotations

import argparse
import importlib
import math
import sys
from pathlib import Path

from . import __version__
from .validation import InputError

EXIT_OK, EXIT_RUN_FAILED, EXIT_BAD_INPUT = 0, 1, 2
STUDY_COMMANDS = ("plot", "sweep", "benchmark", "run", "animate")


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage mistake is one line, like every other input error."""

    def error(self, message):
        raise InputError(message)


def _float(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None


def _int(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None


def _add_physics(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("physics (defaults: the paper's case 2)")
    g.add_argument("--mu-s", type=_float, default=0.28, help="static friction coefficient μs (default 0.28)")
    g.add_argument("--mu-d", type=_float, default=0.20, help="dynamic friction coefficient μd ≤ μs (default 0.20)")
    g.add_argument("--theta0-deg", type=_float, default=60.0, help="initial tilt of the axis, degrees (default 60)")
    g.add_argument("--restitution", type=_float, default=0.0, help="Newton restitution e in [0, 1] (default 0)")
    g.add_argument("--g", type=_float, default=9.81, help="gravity, m/s² (default 9.81)")
    geo = p.add_argument_group("body: geometry and density, or mass properties given directly")
    geo.add_argument("--ball-radius", type=_float, default=None, help="ball radius r, m (default 0.020)")
    geo.add_argument("--rod-diameter", type=_float, default=None, help="rod diameter d, m (default 0.006)")
    geo.add_argument("--length", type=_float, default=None, help="distance between ball centres L, m (default 0.410)")
    geo.add_argument("--density", type=_float, default=None, help="density ρ, kg/m³ (default 7800)")
    geo.add_argument("--mass", type=_float, default=None, help="mass M, kg (with --xi and --inertia)")
    geo.add_argument("--xi", type=_float, default=None, help="distance from ball A's centre to the centre of mass, m")
    geo.add_argument("--inertia", type=_float, default=None, help="central moment of inertia J_Γ, kg·m²")


def build_problem(args):
    """RodProblem from parsed options (raises InputError on any inconsistency)."""
    from .rod.problem import RodGeometry, RodProblem

    common = dict(mu_s=args.mu_s, mu_d=args.mu_d, restitution=args.restitution, g=args.g)
    if not math.isfinite(args.theta0_deg):
        raise InputError(f"theta0-deg must be finite, got {args.theta0_deg!r}")
    if not 0.0 < args.theta0_deg < 90.0:
        raise InputError(f"theta0-deg must lie in (0, 90), got {args.theta0_deg:g}")
    common["theta0"] = math.radians(args.theta0_deg)
    direct = [args.mass, args.xi, args.inertia]
    if any(x is not None for x in direct):
        if any(x is None for x in direct):
            raise InputError("--mass, --xi and --inertia go together: give all three")
        if args.rod_diameter is not None or args.density is not None:
            raise InputError("give either --rod-diameter/--density or --mass/--xi/--inertia, not both")
        r = 0.020 if args.ball_radius is None else args.ball_radius
        length = 2 * args.xi if args.length is None else args.length
        return RodProblem(mass=args.mass, xi=args.xi, inertia=args.inertia, ball_radius=r, length=length, **common)
    geo = RodGeometry(
        ball_radius=0.020 if args.ball_radius is None else args.ball_radius,
        rod_diameter=0.006 if args.rod_diameter is None else args.rod_diameter,
        length=0.410 if args.length is None else args.length,
        density=7800.0 if args.density is None else args.density,
    )
    return RodProblem.from_geometry(geo, **common)


def add_physics_options(parser: argparse.ArgumentParser) -> None:
    """The rod's physical options, shared by every command that builds a RodProblem."""
    _add_physics(parser)


def make_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="nonsmooth-rod", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"nonsmooth-rod {__version__}")
    sub = parser.add_subparsers(dest="command", parser_class=_Parser)
    sim = sub.add_parser("simulate", help="simulate the rod (default: the paper's case 2)",
                         description="Simulate the tilted rod with two balls released on a plane with dry friction.")
    _add_physics(sim)
    num = sim.add_argument_group("numerics")
    num.add_argument("--method", default="event-driven",
                     help="event-driven (default), moreau-jean, or the baselines regularized and switched")
    num.add_argument("--h", type=_float, default=1e-4, help="Moreau–Jean step size, s (default 1e-4)")
    num.add_argument("--solver", default="lemke", help="Moreau–Jean one-step solver (default lemke)")
    num.add_argument("--theta", type=_float, default=0.5, help="Moreau–Jean θ in [0.5, 1] (default 0.5)")
    num.add_argument("--min-phase", type=_float, default=None,
                     help="Moreau–Jean: merge phases shorter than this, s (default 2h)")
    num.add_argument("--rtol", type=_float, default=None,
                     help="relative tolerance (default: event-driven 1e-12, regularized/switched 1e-6)")
    num.add_argument("--atol", type=_float, default=None, help="regularized/switched: absolute tolerance (default rtol·1e-3)")
    num.add_argument("--epsilon", type=_float, default=1e-4,
                     help="regularized: regularisation (stiction transition) velocity ε, m/s (default 1e-4)")
    num.add_argument("--friction-curve", default="stribeck", help="regularized: stribeck (default), tanh or linear")
    num.add_argument("--ode-method", default=None,
                     help="regularized: RK45 (default), DOP853, Radau, BDF, LSODA; switched: rk4 (default, step --h) "
                          "or one of those")
    num.add_argument("--stiffness", type=_float, default=None,
                     help="regularized: penalty contact stiffness, N/m^1.5 (default 2e10, Hertz steel)")
    num.add_argument("--damping", type=_float, default=None,
                     help="regularized: Hunt–Crossley damping α, s/m (default 500)")
    num.add_argument("--time-limit", type=_float, default=None,
                     help="regularized/switched: stop after this many wall-clock seconds (status time-limit)")
    num.add_argument("--t-end", type=_float, default=None,
                     help="end time, s (default: stop at ball B's impact; with it, continue after the impact)")
    out = sim.add_argument_group("output")
    out.add_argument("--out", default="results", help="output folder (default ./results)")
    out.add_argument("--json", action="store_true", help="print the summary JSON on stdout and nothing else there")
    out.add_argument("--no-plot", action="store_true", help="do not write figure.png")
    out.add_argument("--quiet", action="store_true", help="print nothing but errors")
    sim.set_defaults(handler=cmd_simulate)
    # The other studies live in nonsmooth_rod.commands.<name>: each module offers
    # register(subparsers) and sets its own handler.
    for name in STUDY_COMMANDS:
        try:
            module = importlib.import_module(f"nonsmooth_rod.commands.{name}")
        except ModuleNotFoundError as err:
            if err.name != f"nonsmooth_rod.commands.{name}":
                raise
            continue
        module.register(sub)
    return parser


def _print_report(run, out_dir: Path, console) -> None:
    from rich.table import Table

    p = run.problem
    table = Table(title=f"{run.method}: μs = {p.mu_s:g}, μd = {p.mu_d:g}, θ0 = {p.theta0_deg:g}°, e = {p.restitution:g}")
    for col in ("mode", "start [s]", "end [s]", "duration [s]"):
        table.add_column(col, justify="right" if col != "mode" else "left")
    for ph in run.phases:
        table.add_row(ph.mode, f"{ph.t_start:.6f}", f"{ph.t_end:.6f}", f"{ph.duration:.6f}")
    console.print(table)
    if run.impact:
        i = run.impact
        console.print(f"impact of ball B: t = {i['t']:.6f} s, θ̇ = {i['theta_dot']:.5f} rad/s, "
                      f"x_O = {i['x_O']:.6f} m, ẋ_O = {i['x_O_dot']:.5f} m/s (before)")
    else:
        console.print("no impact of ball B in the simulated interval")
    rh = run.rolling
    fmt = lambda x: "—" if x is None else f"{x:.6f} s"  # noqa: E731
    console.print(f"rolling hypothesis: max T/N = {rh.T_over_N_max:.5f} at t = {rh.t_max:.6f} s, "
                  f"t_r1 = {fmt(rh.t_r1)}, t_r2 = {fmt(rh.t_r2)}")
    console.print(f"status: {run.status} ({run.result.message}); {run.result.steps} steps, "
                  f"{run.result.cpu_time_s:.3f} s CPU; files in {out_dir}/")


def cmd_simulate(args) -> int:
    from rich.console import Console

    from .io import dumps_json, write_csv, write_json
    from .rod.simulation import TRAJECTORY_COLUMNS, simulate

    problem = build_problem(args)
    if args.method == "moreau-jean":
        from .solvers import available_solvers
        if args.solver not in available_solvers():
            raise InputError(f"unknown solver '{args.solver}'; choose from: {', '.join(available_solvers())}")
    run = simulate(problem, args.method, t_end=args.t_end, h=args.h, solver=args.solver, theta=args.theta,
                   min_phase=args.min_phase, rtol=args.rtol, atol=args.atol, epsilon=args.epsilon,
                   friction_curve=args.friction_curve, ode_method=args.ode_method, stiffness=args.stiffness,
                   damping=args.damping, time_limit=args.time_limit)
    out_dir = Path(args.out)
    summary = run.summary()
    write_csv(out_dir / "trajectory.csv", run.table, TRAJECTORY_COLUMNS)
    write_json(out_dir / "summary.json", summary)
    if not args.no_plot:
        from .rod.plotting import plot_run
        plot_run(run, out_dir / "figure.png")
    if args.json:
        sys.stdout.write(dumps_json(summary))
    elif not args.quiet:
        _print_report(run, out_dir, Console(soft_wrap=True))
    if run.status != "ok":
        print(f"nonsmooth-rod: run ended with status '{run.status}': {run.result.message}", file=sys.stderr)
        return EXIT_RUN_FAILED
    return EXIT_OK


def main(argv=None) -> int:
    parser = make_parser()
    try:
        args = parser.parse_args(argv)
        if args.command is None:
            parser.print_help()
            return EXIT_BAD_INPUT
        return args.handler(args)
    except InputError as err:
        print(f"nonsmooth-rod: error: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("nonsmooth-rod: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
