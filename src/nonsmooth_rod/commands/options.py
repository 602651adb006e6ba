"""Option parsing every subcommand shares: numbers with the ranges that work, the rod's physics,
the output options, and the exit codes. Subcommands import from here, never from `cli`."""
from __future__ import annotations

import argparse
import math

from ..validation import InputError

EXIT_OK, EXIT_RUN_FAILED, EXIT_BAD_INPUT = 0, 1, 2

# Ranges in which the rod's physics is computed without overflow (SI units). Outside them the
# squares and products of the model overflow float64 or the ODE solvers stall; each option
# names its range in the error.
RANGES = {
    "ball_radius": (1e-6, 10.0), "rod_diameter": (1e-6, 10.0), "length": (1e-5, 100.0),
    "density": (1e-3, 1e6), "mass": (1e-9, 1e9), "xi": (1e-6, 100.0), "inertia": (1e-15, 1e12),
    "g": (0.0, 1e4), "t_end": (1e-9, 1e4), "h": (1e-9, 1.0), "tol": (1e-12, 0.1), "rtol": (2.3e-14, 0.1), "atol": (1e-300, 1e-2),
    "epsilon": (1e-12, 10.0), "stiffness": (1.0, 1e15), "damping": (0.0, 1e9), "min_phase": (0.0, 1e4),
    "time_limit": (1e-3, 1e6), "theta": (0.5, 1.0), "restitution": (0.0, 1.0), "max_step": (1e-9, 1e4),
}


class Parser(argparse.ArgumentParser):
    """argparse, but a usage mistake is one line, like every other input error."""

    def error(self, message):
        raise InputError(message)


def number(text: str) -> float:
    """A finite float (argparse type): nan, inf and 1e999 are refused here, by name."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
    return value


def integer(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None


def require_range(option: str, value: float | None) -> float | None:
    """Refuse a value outside the range `RANGES` gives for `option` (None passes through)."""
    if value is None:
        return None
    lo, hi = RANGES[option.lstrip("-").replace("-", "_")]
    flag = "--" + option.lstrip("-").replace("_", "-")
    if lo > 0 and value <= 0:
        raise InputError(f"{flag} must be positive, got {value:g}")
    if value < 0 <= lo:
        raise InputError(f"{flag} must be non-negative, got {value:g}")
    if not lo <= value <= hi:
        raise InputError(f"{flag} = {value:g} is outside the range that works, [{lo:g}, {hi:g}]")
    return value


def add_physics_options(p: argparse.ArgumentParser) -> None:
    """The rod's physical options, shared by every command that builds a RodProblem."""
    g = p.add_argument_group("physics (defaults: the paper's case 2)")
    g.add_argument("--mu-s", type=number, default=0.28, help="static friction coefficient μs (default 0.28)")
    g.add_argument("--mu-d", type=number, default=0.20, help="dynamic friction coefficient μd ≤ μs (default 0.20)")
    g.add_argument("--theta0-deg", type=number, default=60.0, help="initial tilt of the axis, degrees (default 60)")
    g.add_argument("--restitution", type=number, default=0.0, help="Newton restitution e in [0, 1] (default 0)")
    g.add_argument("--g", type=number, default=9.81, help="gravity, m/s² (default 9.81)")
    geo = p.add_argument_group("body: geometry and density, or mass properties given directly")
    geo.add_argument("--ball-radius", type=number, default=None, help="ball radius r, m (default 0.020)")
    geo.add_argument("--rod-diameter", type=number, default=None, help="rod diameter d, m (default 0.006)")
    geo.add_argument("--length", type=number, default=None, help="distance between ball centres L, m (default 0.410)")
    geo.add_argument("--density", type=number, default=None, help="density ρ, kg/m³ (default 7800)")
    geo.add_argument("--mass", type=number, default=None, help="mass M, kg (with --xi and --inertia)")
    geo.add_argument("--xi", type=number, default=None, help="distance from ball A's centre to the centre of mass, m")
    geo.add_argument("--inertia", type=number, default=None, help="central moment of inertia J_Γ, kg·m²")


def build_problem(args):
    """RodProblem from parsed options (raises InputError on any inconsistency)."""
    from ..rod.problem import RodGeometry, RodProblem

    for name in ("ball_radius", "rod_diameter", "length", "density", "mass", "xi", "inertia", "g", "restitution"):
        require_range(name, getattr(args, name))
    common = dict(mu_s=args.mu_s, mu_d=args.mu_d, restitution=args.restitution, g=args.g)
    if not 0.0 < args.theta0_deg < 90.0:
        raise InputError(f"--theta0-deg must lie in (0, 90), got {args.theta0_deg:g}")
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


def add_output_options(p: argparse.ArgumentParser, default_out: str = "results", figure: str = "figure.png",
                       force: bool = True) -> None:
    """--out, --json, --no-plot, --quiet (and --force, for the commands that guard their folders):
    what every simulating command writes and prints."""
    out = p.add_argument_group("output")
    out.add_argument("--out", default=default_out, help=f"output folder (default ./{default_out})")
    out.add_argument("--json", action="store_true", help="print the summary JSON on stdout and nothing else there")
    out.add_argument("--no-plot", action="store_true", help=f"do not write {figure}")
    out.add_argument("--quiet", action="store_true", help="print nothing but errors")
    if not force:
        return
    out.add_argument("--force", action="store_true",
                     help="replace the results of another command in --out (`simulate` and `run` refuse to "
                          "overwrite each other's folders without it)")


def escape(text: str) -> str:
    """Text for rich: square brackets (units such as [s]) are not markup."""
    from rich.markup import escape as rich_escape

    return rich_escape(text)


def parse_image_formats(text: str, option: str = "--format") -> tuple[str, ...]:
    """Comma-separated image formats: known ones, each once (InputError naming the option)."""
    from ..io import IMAGE_FORMATS

    fmts = [f.strip().lower() for f in text.split(",")]
    if not all(fmts) or any(f not in IMAGE_FORMATS for f in fmts):
        raise InputError(f"{option} must be among {', '.join(IMAGE_FORMATS)}, got {text!r}")
    if len(set(fmts)) != len(fmts):
        raise InputError(f"{option} names a format twice: {text!r}")
    return tuple(fmts)


def image_formats(text: str) -> tuple[str, ...]:
    """`parse_image_formats` as an argparse type."""
    try:
        return parse_image_formats(text)
    except InputError as err:
        raise argparse.ArgumentTypeError(str(err).replace("--format ", "", 1)) from None
