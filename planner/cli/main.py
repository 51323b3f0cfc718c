"""The ``wobjcal`` command line: ``main(argv) -> int``.

Exit codes: 0 success; 1 the plan was checked and something is not feasible (``check``) or a
validation failed its targets; 2 bad input (file, plan, measurement, argument). Errors print
one line on stderr, never a traceback (``--debug`` shows it). Each command lives in
``planner/cli/<command>.py``.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import signal
import sys
import threading
from collections.abc import Callable, Sequence
from typing import NoReturn

from calib._version import __version__
from calib.errors import WobjcalError
from planner.cli.common import native_output_to_stderr

EXIT_OK, EXIT_FAIL, EXIT_INPUT = 0, 1, 2
#: Exit code after SIGTERM (128 + 15, as a shell reports it).
EXIT_TERMINATED = 143


class Terminated(BaseException):
    """Raised in the main thread when the process gets SIGTERM: ``finally`` blocks run (worker
    processes stopped, temporary files removed) before the command exits 143."""


def _raise_terminated(signum: int, frame: object) -> None:
    raise Terminated()


def _exit_now(code: int) -> NoReturn:
    """Leave at once after SIGTERM, once the main thread has cleaned up (``finally`` blocks ran
    while :class:`Terminated` propagated): the interpreter's normal exit would wait for helper
    threads (a process pool's manager, a progress bar) that a terminated command must not."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    os._exit(code)


_FORMATTER = argparse.RawDescriptionHelpFormatter


def _add(
    sub: argparse._SubParsersAction,
    name: str,
    help_: str,
    description: str,
    example: str,
) -> argparse.ArgumentParser:
    parser: argparse.ArgumentParser = sub.add_parser(
        name,
        help=help_,
        description=description,
        epilog="example:\n  " + example.replace("\n", "\n  "),
        formatter_class=_FORMATTER,
    )
    parser.add_argument(
        "--debug",
        action="store_true",
        default=argparse.SUPPRESS,
        help="show tracebacks and debug logs",
    )
    return parser


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``wobjcal`` command."""
    # each command group by its own module (not through the package, which imports this one)
    import planner.cli.calibrate as calibrate
    import planner.cli.check as check
    import planner.cli.export as export
    import planner.cli.misc as misc
    import planner.cli.suggest as suggest
    import planner.cli.validate as validate

    parser = argparse.ArgumentParser(
        prog="wobjcal",
        description="Plan, check and validate work-object calibration with a robot-held "
        "proximity sensor (Hultman & Leijon 2013).",
        epilog="exit codes: 0 ok, 1 check/validation found a problem, 2 bad input\n"
        "run 'wobjcal COMMAND --help' for each command; docs/cli.md has more",
        formatter_class=_FORMATTER,
    )
    parser.add_argument("--version", action="version", version=f"wobjcal {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks and debug logs")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for module in (check, validate, calibrate, export, suggest, misc):
        module.register(sub, _add)
    return parser


def _run(args: argparse.Namespace) -> int:
    handler: Callable[[argparse.Namespace], int] = args.handler
    return handler(args)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line with ``argv`` (default ``sys.argv[1:]``); return the exit code."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or an argument error (argparse printed it)
        return int(exc.code or 0)
    debug = bool(getattr(args, "debug", False))
    logging.basicConfig(level=logging.DEBUG if debug else logging.WARNING, format="%(message)s")
    if args.command is None:
        parser.print_help(sys.stdout)
        return EXIT_OK
    previous = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        with native_output_to_stderr():
            return _run(args)
    except Terminated:
        print(f"wobjcal {args.command}: terminated", file=sys.stderr)
        _exit_now(EXIT_TERMINATED)
    except BrokenPipeError:  # e.g. `wobjcal check --json plan.json | head`: the reader left
        with contextlib.suppress(OSError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    except (WobjcalError, OSError) as exc:
        if debug:
            raise
        what = (
            f"{exc.filename}: {exc.strerror}" if isinstance(exc, OSError) and exc.filename else exc
        )
        print(f"wobjcal {args.command}: error: {what}", file=sys.stderr)
        return EXIT_INPUT
    except KeyboardInterrupt:
        print(f"wobjcal {args.command}: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # a bug: say so briefly, the traceback is one flag away
        if debug:
            raise
        print(
            f"wobjcal {args.command}: internal error: {type(exc).__name__}: {exc} "
            "(run again with --debug for the traceback)",
            file=sys.stderr,
        )
        return EXIT_INPUT
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
