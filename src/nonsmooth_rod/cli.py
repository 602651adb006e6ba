"""Nonsmooth contact dynamics of planar rigid bodies: simulate the paper's rod, run any scene, plot, sweep, fit, benchmark.

The entry point only: each subcommand lives in `nonsmooth_rod.commands.<name>` with a
`register(subparsers)` that sets its handler; shared option parsing is `commands.options`.
Every mistake in the input ends with one line on stderr and exit status 2; a run that fails
(solver failure, Painlevé stop) still writes its files and exits with status 1, and so does one
that cannot write them (a full disk) or loses a worker, with one line naming the cause.
"""
from __future__ import annotations

import importlib
import sys

from . import __version__
from .commands.options import EXIT_BAD_INPUT, EXIT_RUN_FAILED, Parser
from .io import RunAborted
from .validation import InputError

# In the order `--help` lists them. A module that is missing (an optional part) is skipped.
COMMANDS = ("simulate", "run", "animate", "plot", "sweep", "fit", "benchmark", "compile")


def make_parser() -> Parser:
    parser = Parser(prog="nonsmooth-rod", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"nonsmooth-rod {__version__}")
    sub = parser.add_subparsers(dest="command", parser_class=Parser)
    for name in COMMANDS:
        try:
            module = importlib.import_module(f"nonsmooth_rod.commands.{name}")
        except ModuleNotFoundError as err:
            if err.name != f"nonsmooth_rod.commands.{name}":
                raise
            continue
        module.register(sub)
    return parser


def _say_when_compiling(quiet: bool = False) -> None:
    """A first compiled run takes seconds, and one without numba is slow: say so in one line on
    stderr (stdout may carry JSON), or nothing with --quiet."""
    from . import _jit

    _jit.set_compile_notifier((lambda message: None) if quiet else
                              (lambda message: print(f"nonsmooth-rod: {message}", file=sys.stderr, flush=True)))


def main(argv=None) -> int:
    parser = make_parser()
    try:
        args = parser.parse_args(argv)
        if args.command is None:
            parser.print_help()
            return EXIT_BAD_INPUT
        _say_when_compiling(quiet=getattr(args, "quiet", False))
        return args.handler(args)
    except InputError as err:
        print(f"nonsmooth-rod: error: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except RunAborted as err:  # a full disk, a lost worker: not the input's fault
        print(f"nonsmooth-rod: {err}", file=sys.stderr)
        return EXIT_RUN_FAILED
    except KeyboardInterrupt:
        print("nonsmooth-rod: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
