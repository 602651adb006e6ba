"""`nonsmooth-rod run SCENE.toml`: simulate any scene described in a scene file.

Writes trajectory.csv, summary.json (schema nonsmooth-rod/summary/2), a copy of the scene file
and figure.png into --out; prints a phase table per contact and the impacts. Exit status 0 ok,
1 the run ended badly (files still written), 2 bad input (one line on stderr).
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from .options import EXIT_OK, EXIT_RUN_FAILED, add_output_options, escape

DESCRIPTION = """\
Simulate the scene described in a scene file (TOML or JSON, schema nonsmooth-rod/scene/1,
see docs/scene-format.md). Writes trajectory.csv, summary.json, a copy of the scene file and
figure.png into --out (docs/output-format.md); --animate adds animation.gif (and .mp4 where
ffmpeg is installed). --set changes any value of the file by its dotted path, entries by name:
  --set contacts.floor.law.mu_s=0.3 --set simulation.method=event-driven
  --set simulation.moreau-jean.h=1e-4 --set initial.ball.v=[1,0,0]"""


def register(subparsers) -> None:
    p = subparsers.add_parser("run", help="simulate any scene described in a scene file (TOML/JSON)",
                              description=DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene", help="scene file (.toml, or .json)")
    p.add_argument("--set", action="append", default=[], metavar="PATH=VALUE",
                   help="override a value of the scene file (repeatable), e.g. contacts.floor.law.mu_s=0.3")
    add_output_options(p)
    p.add_argument("--animate", action="store_true", help="also write animation.gif (and animation.mp4 with ffmpeg)")
    p.set_defaults(handler=cmd_run)


def writable_folder(text: str) -> Path:
    """--out as a folder that exists (made if needed) and takes files, else a one-line InputError."""
    from ..validation import InputError

    out_dir = Path(text)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise InputError(f"--out {text}: cannot make the folder ({err.strerror or err})") from None
    if not os.access(out_dir, os.W_OK | os.X_OK):
        raise InputError(f"--out {text}: the folder is not writable")
    return out_dir


def _fmt(x: float) -> str:
    return f"{x:.6f}"


def print_report(result, out_dir, console) -> None:
    """Phase table per contact, the impacts, the status line (rich; '[s]' escaped from markup)."""
    from rich.table import Table

    table = Table(title=f"{result.method}: phases per contact")
    for col in ("contact", "mode", escape("start [s]"), escape("end [s]"), escape("duration [s]")):
        table.add_column(col, justify="left" if col in ("contact", "mode") else "right")
    for name in result.contact_names:
        for ph in result.phases.get(name, []):
            table.add_row(name, str(ph.mode), _fmt(ph.t_start), _fmt(ph.t_end), _fmt(ph.t_end - ph.t_start))
    console.print(table)
    if result.impacts:
        imp = Table(title="impacts")
        for col in ("contact", escape("t [s]"), escape("normal impulse [N·s]"), escape("tangential impulse [N·s]")):
            imp.add_column(col, justify="left" if col == "contact" else "right")
        for i in result.impacts:
            k = result.contact_names.index(i.contact) if i.contact in result.contact_names else None
            pn = "—" if k is None else f"{float(i.normal_impulse[k]):.6g}"
            pt = "—" if k is None else f"{float(i.tangential_impulse[k]):.6g}"
            imp.add_row(i.contact, _fmt(i.t), pn, pt)
        console.print(imp)
    else:
        console.print("no impacts")
    console.print(escape(f"status: {_status(result)} ({result.message}); files in {out_dir}/"))


def _status(result) -> str:
    return str(getattr(result.status, "value", result.status))


def cmd_run(args) -> int:
    from rich.console import Console

    from ..io import dumps_json
    from ..result_files import claim_folder, save
    from ..scenefile import load_scene, simulate_scene

    scene_file = load_scene(args.scene, args.set)
    claim_folder(args.out, "run", args.force)
    out_dir = writable_folder(args.out)
    result = simulate_scene(scene_file)
    summary = save(result, out_dir)
    console = Console(soft_wrap=True, stderr=False)
    if not args.no_plot:
        from ..plots.scene_figure import plot_result

        plot_result(result, out_dir / "figure.png")
    if args.animate:
        from ..plots.animation import write_animation

        notes = write_animation(result, out_dir)
        if not (args.quiet or args.json):
            for note in notes:
                console.print(escape(note))
    if args.json:
        sys.stdout.write(dumps_json(summary))
    elif not args.quiet:
        print_report(result, out_dir, console)
    if not result.success:
        print(f"nonsmooth-rod: run ended with status '{_status(result)}': {result.message}", file=sys.stderr)
        return EXIT_RUN_FAILED
    return EXIT_OK
