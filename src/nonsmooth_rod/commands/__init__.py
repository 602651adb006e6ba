"""Subcommands of the nonsmooth-rod CLI besides simulate: each module has register(subparsers)."""
