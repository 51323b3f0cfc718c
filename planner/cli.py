"""The ``wobjcal`` command line: ``main(argv) -> int``."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from calib._version import __version__


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``wobjcal`` command."""
    parser = argparse.ArgumentParser(
        prog="wobjcal",
        description="Plan, check and validate work-object calibration with a robot-held "
        "proximity sensor (Hultman & Leijon 2013).",
    )
    parser.add_argument("--version", action="version", version=f"wobjcal {__version__}")
    parser.add_subparsers(dest="command", metavar="COMMAND")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line with ``argv`` (default ``sys.argv[1:]``); return the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help(sys.stdout)
        return 0
    return 0
