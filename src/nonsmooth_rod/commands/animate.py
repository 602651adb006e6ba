"""`nonsmooth-rod animate RESULT_DIR`: draw a run of any scene frame by frame (GIF, and MP4 with ffmpeg)."""
from __future__ import annotations

from pathlib import Path

from ..validation import InputError
from .options import integer


def register(subparsers) -> None:
    p = subparsers.add_parser("animate", help="animate a results folder written by `run` (GIF; MP4 with ffmpeg)",
                              description="Draw the bodies, lines and contact forces of a results folder "
                                          "written by `nonsmooth-rod run`, frame by frame, to animation.gif "
                                          "(and animation.mp4 where ffmpeg is installed).")
    p.add_argument("folder", help="results folder (summary.json, trajectory.csv and the scene copy)")
    p.add_argument("--out", default=None, help="where to write the animation (default: the results folder)")
    p.add_argument("--frames", type=integer, default=120, help="number of frames (2-2000, default 120)")
    p.add_argument("--fps", type=integer, default=25, help="frames per second (1-120, default 25)")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    p.set_defaults(handler=cmd_animate)


def cmd_animate(args) -> int:
    from ..plots.animation import write_animation
    from ..result_files import describe_folder, folder_kind, load

    if not 2 <= args.frames <= 2000:
        raise InputError(f"--frames must lie in [2, 2000], got {args.frames}")
    if not 1 <= args.fps <= 120:
        raise InputError(f"--fps must lie in [1, 120], got {args.fps}")
    if folder_kind(args.folder) == "simulate":
        raise InputError(f"{args.folder} holds {describe_folder(args.folder)}; `animate` draws the results of "
                         f"`nonsmooth-rod run`: draw the rod with `nonsmooth-rod plot {args.folder} --gif`")
    result = load(args.folder)
    if result.scene_file is None:
        raise InputError(f"{args.folder}: no scene copy (scene.toml/scene.json) to draw the bodies from")
    from .run import writable_folder

    out = writable_folder(args.out) if args.out else Path(args.folder)
    for note in write_animation(result, out, frames=args.frames, fps=args.fps):
        if not args.quiet:
            print(note)
    return 0
