"""`nonsmooth-rod simulate`: the paper's rod, any method; phase table, CSV, JSON and figure."""
from __future__ import annotations

import sys
from pathlib import Path

from ..solvers.registry import DEFAULT_SOLVER, SOLVER_HELP, require_solver
from ..validation import InputError
from .options import (
    EXIT_OK,
    EXIT_RUN_FAILED,
    add_output_options,
    add_physics_options,
    build_problem,
    escape,
    number,
    require_range,
)

ODE_METHODS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")


def register(subparsers) -> None:
    sim = subparsers.add_parser("simulate", help="simulate the rod (default: the paper's case 2)",
                                description="Simulate the tilted rod with two balls released on a plane "
                                            "with dry friction.")
    add_physics_options(sim)
    num = sim.add_argument_group("numerics")
    num.add_argument("--method", default="event-driven",
                     help="event-driven (default), moreau-jean, hybrid (Runge–Kutta steps of --h between "
                          "located events), or the baselines regularized and switched")
    num.add_argument("--h", type=number, default=None,
                     help="Moreau–Jean step size, s (default 1e-4); with --tol the first and largest step "
                          "(default 1e-2); hybrid: its step (default 1e-2)")
    num.add_argument("--tol", type=number, default=None,
                     help="Moreau–Jean error control: step sizes chosen for this tolerance on positions (m, rad) "
                          "and on located event times (s); docs/error_control.md")
    num.add_argument("--solver", default=DEFAULT_SOLVER, help=SOLVER_HELP)
    num.add_argument("--theta", type=number, default=0.5, help="Moreau–Jean θ in [0.5, 1] (default 0.5)")
    num.add_argument("--min-phase", type=number, default=None,
                     help="Moreau–Jean: merge phases shorter than this, s (default 2h)")
    num.add_argument("--rtol", type=number, default=None,
                     help="relative tolerance (default: event-driven 1e-12, regularized/switched 1e-6)")
    num.add_argument("--atol", type=number, default=None, help="regularized/switched: absolute tolerance (default rtol·1e-3)")
    num.add_argument("--max-step", type=number, default=None,
                     help="event-driven: largest ODE step, s (events are found at any step size)")
    num.add_argument("--epsilon", type=number, default=1e-4,
                     help="regularized: regularisation (stiction transition) velocity ε, m/s (default 1e-4)")
    num.add_argument("--friction-curve", default="stribeck", help="regularized: stribeck (default), tanh or linear")
    num.add_argument("--ode-method", default=None,
                     help="regularized: RK45 (default), DOP853, Radau, BDF, LSODA; switched: rk4 (default, step --h) "
                          "or one of those")
    num.add_argument("--stiffness", type=number, default=None,
                     help="regularized: penalty contact stiffness, N/m^1.5 (default 2e10, Hertz steel)")
    num.add_argument("--damping", type=number, default=None,
                     help="regularized: Hunt–Crossley damping α, s/m (default 500)")
    num.add_argument("--time-limit", type=number, default=None,
                     help="regularized/switched: stop after this many wall-clock seconds (status time-limit)")
    num.add_argument("--t-end", type=number, default=None,
                     help="end time, s (default: stop at ball B's impact; with it, continue after the impact)")
    add_output_options(sim)
    sim.set_defaults(handler=cmd_simulate)


def _check_numerics(args) -> None:
    for name in ("h", "tol", "rtol", "atol", "epsilon", "stiffness", "damping", "min_phase", "time_limit", "t_end",
                 "max_step"):
        require_range(name, getattr(args, name))
    if args.ode_method is not None and args.ode_method not in ODE_METHODS + ("rk4",):
        raise InputError(f"--ode-method must be one of {', '.join(ODE_METHODS + ('rk4',))}, got {args.ode_method!r}")
    require_solver("--solver", args.solver)  # for every method: a name outside the table is a typo


def _print_report(run, out_dir: Path, console) -> None:
    from rich.table import Table

    p = run.problem
    table = Table(title=escape(f"{run.method}: μs = {p.mu_s:g}, μd = {p.mu_d:g}, θ0 = {p.theta0_deg:g}°, "
                               f"e = {p.restitution:g}"))
    for col in ("mode", "start [s]", "end [s]", "duration [s]"):
        table.add_column(escape(col), justify="right" if col != "mode" else "left")
    for ph in run.phases:
        table.add_row(ph.mode, f"{ph.t_start:.6f}", f"{ph.t_end:.6f}", f"{ph.duration:.6f}")
    console.print(table)
    if run.impact:
        i = run.impact
        console.print(escape(f"impact of ball B: t = {i['t']:.6f} s, θ̇ = {i['theta_dot']:.5f} rad/s, "
                             f"x_O = {i['x_O']:.6f} m, ẋ_O = {i['x_O_dot']:.5f} m/s (before)"))
    else:
        console.print("no impact of ball B in the simulated interval")
    rh = run.rolling
    fmt = lambda x: "—" if x is None else f"{x:.6f} s"  # noqa: E731
    console.print(escape(f"rolling hypothesis: max T/N = {rh.T_over_N_max:.5f} at t = {rh.t_max:.6f} s, "
                         f"t_r1 = {fmt(rh.t_r1)}, t_r2 = {fmt(rh.t_r2)}"))
    console.print(escape(f"status: {run.status} ({run.result.message}); {run.result.steps} steps, "
                         f"{run.result.cpu_time_s:.3f} s CPU; files in {out_dir}/"))


def cmd_simulate(args) -> int:
    from ..io import dumps_json, provenance, remove_stale_temps, write_csv
    from ..result_files import claim_folder, write_summary
    from ..rod.simulation import TRAJECTORY_COLUMNS, simulate
    from .run import writable_folder

    problem = build_problem(args)
    _check_numerics(args)
    claim_folder(args.out, "simulate", args.force)
    out_dir = writable_folder(args.out)  # before the run: an unwritable --out is said at once
    extra = {} if args.max_step is None else {"max_step": args.max_step}
    run = simulate(problem, args.method, t_end=args.t_end, h=args.h, tol=args.tol, solver=args.solver,
                   theta=args.theta, min_phase=args.min_phase, rtol=args.rtol, atol=args.atol, epsilon=args.epsilon,
                   friction_curve=args.friction_curve, ode_method=args.ode_method, stiffness=args.stiffness,
                   damping=args.damping, time_limit=args.time_limit, **extra)
    remove_stale_temps(out_dir)
    summary = dict(run.summary(), provenance=provenance())
    write_csv(out_dir / "trajectory.csv", run.table, TRAJECTORY_COLUMNS)
    write_summary(out_dir, summary, [out_dir / "trajectory.csv"])
    if not args.no_plot:
        from ..rod.plotting import plot_run
        plot_run(run, out_dir / "figure.png")
    if args.json:
        sys.stdout.write(dumps_json(summary))
    elif not args.quiet:
        from rich.console import Console

        _print_report(run, out_dir, Console(soft_wrap=True))
    if run.status != "ok":
        print(f"nonsmooth-rod: run ended with status '{run.status}': {run.result.message}", file=sys.stderr)
        return EXIT_RUN_FAILED
    return EXIT_OK
