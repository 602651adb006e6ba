"""`nonsmooth-rod plot`: figures of a results folder written by `simulate`, and the paper's set."""
from __future__ import annotations

import argparse
from pathlib import Path

from .options import image_formats, integer as _int
from ..validation import InputError

DESCRIPTION = """\
Draw the paper's Fig. 14-16 panel (panel.png, panel.svg) of a results folder written by
`nonsmooth-rod simulate`: T/N under pure rolling with ±μs, t_r1, t_r2; the parameters and
characteristic times; θ, θ̇, θ̈, x_O, ẋ_O, ẍ_O, N and the actual T/N, rolling blue and sliding red.
--compare overlays a second run of the same problem (e.g. Moreau-Jean) as markers.
--frames/--gif draw the rod itself; --paper-figures writes the Figs. 18-25 set (three friction
cases, rolling vs sliding hypotheses, angular velocity near the impact) for the folder's body
(or, without a folder, for the paper's)."""


def register(subparsers) -> None:
    p = subparsers.add_parser("plot", help="figures of a results folder (the paper's Fig. 14-25)",
                              description=DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("folder", nargs="?", default=None,
                   help="results folder written by `simulate` (trajectory.csv + summary.json)")
    p.add_argument("--out", default=None, help="where to write the figures (default: the results folder)")
    p.add_argument("--compare", metavar="FOLDER", default=None,
                   help="a second results folder of the same problem, drawn as markers "
                        "(a Moreau-Jean run is always the markers, an event-driven one the lines)")
    p.add_argument("--paper-figures", action="store_true",
                   help="also write the Figs. 18-21 overlay, 22-24 hypotheses and 25 impact detail")
    p.add_argument("--frames", type=_int, default=None, metavar="N",
                   help="also write frames.png: a strip of N poses of the rod (2-48)")
    p.add_argument("--gif", action="store_true", help="also write rod.gif, an animation of the motion")
    p.add_argument("--no-panel", action="store_true", help="do not write the Fig. 14-16 panel")
    p.add_argument("--format", type=image_formats, default=("png", "svg"),
                   help="comma-separated image formats: png, svg (default png,svg)")
    p.add_argument("--dpi", type=_int, default=110, help="resolution of PNG files (default 110)")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    p.set_defaults(handler=cmd_plot)


def _same_problem(a, b) -> list[str]:
    fields = ("mu_s", "mu_d", "theta0", "restitution", "g", "mass", "xi", "inertia", "ball_radius", "length")
    return [f for f in fields if abs(getattr(a, f) - getattr(b, f)) > 1e-12 * max(1.0, abs(getattr(a, f)))]


def cmd_plot(args) -> int:
    from ..rod.plotting import frames_figure, lines_and_markers, load_run_dir, panel_figure, save_figure, write_gif

    if args.folder is None and not args.paper_figures:
        raise InputError("give a results folder (from `nonsmooth-rod simulate --out DIR`) or --paper-figures")
    if args.folder is None and (args.compare or args.frames or args.gif):
        raise InputError("--compare, --frames and --gif draw a run: give its results folder")
    if not 30 <= args.dpi <= 600:
        raise InputError(f"--dpi must lie in [30, 600], got {args.dpi}")
    if args.frames is not None and not 2 <= args.frames <= 48:
        raise InputError(f"--frames must lie in [2, 48], got {args.frames}")
    out_dir = Path(args.out if args.out is not None else args.folder or ".")
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError(f"--out '{out_dir}' exists and is not a folder")
    written = []
    data = load_run_dir(args.folder) if args.folder is not None else None
    if data is not None and not args.no_panel:
        compare = None
        if args.compare is not None:
            compare = load_run_dir(args.compare, rolling=False)
            differ = _same_problem(data.problem, compare.problem)
            if differ:
                raise InputError(f"--compare folder '{args.compare}' is a run of another problem "
                                 f"(differs in {', '.join(differ)})")
            data, compare = lines_and_markers(data, compare)
        written += save_figure(panel_figure(data, compare), out_dir / "panel", args.format, args.dpi)
    if data is not None and args.frames:
        written += save_figure(frames_figure(data, args.frames), out_dir / "frames", args.format, args.dpi)
    if data is not None and args.gif:
        written.append(write_gif(data, out_dir / "rod.gif"))
    if args.paper_figures:
        from ..rod.figures import write_paper_figures
        from ..rod.problem import RodProblem

        base = data.problem if data is not None else RodProblem.paper()
        written += write_paper_figures(out_dir, base, args.format, args.dpi)
    if not written:
        raise InputError("nothing to draw: --no-panel without --frames, --gif or --paper-figures")
    if not args.quiet:
        for path in written:
            print(path)
    return 0
