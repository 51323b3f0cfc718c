"""The ``wobjcal`` command line: ``main(argv) -> int``.

Exit codes: 0 success; 1 the plan was checked and something is not feasible (``check``) or a
validation failed its targets; 2 bad input (file, plan, measurement, argument) or an output
that could not be written (a file, a device, standard output: a full disk is never reported
as done). Errors print one line on stderr, never a traceback (``--debug`` shows it). Each
command lives in ``planner/cli/<command>.py``.
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
from planner.cli.common import (
    StdoutError,
    checked_stdout,
    flush_stdout,
    native_output_to_stderr,
)

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
    import planner.cli.sweep as sweep
    import planner.cli.validate as validate

    parser = argparse.ArgumentParser(
        prog="wobjcal",
        description="Plan, check and validate work-object calibration with a robot-held "
        "proximity sensor (Hultman & Leijon 2013).",
        epilog="exit codes: 0 ok, 1 check/validation found a problem, 2 bad input or output\n"
        "run 'wobjcal COMMAND --help' for each command; docs/cli.md has more",
        formatter_class=_FORMATTER,
    )
    parser.add_argument("--version", action="version", version=f"wobjcal {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks and debug logs")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for module in (check, validate, calibrate, export, suggest, sweep, misc):
        module.register(sub, _add)
    return parser


def _drop_stdout() -> None:
    """Point file descriptor 1 at ``/dev/null``: what is left in ``sys.stdout``'s buffer (a
    reader that left, a full device) must not turn the exit code into 120 at shutdown."""
    with contextlib.suppress(OSError, ValueError, AttributeError):
        target = sys.stdout.fileno()
        null = os.open(os.devnull, os.O_WRONLY)
        try:
            os.dup2(null, target)
        finally:
            os.close(null)


def _parse(parser: argparse.ArgumentParser, argv: Sequence[str] | None) -> argparse.Namespace | int:
    """The parsed arguments, or the exit code when there is no command to run (``--help``,
    ``--version``, an argument error, no command: their output on stdout checked too)."""
    try:
        with checked_stdout():  # argparse ignores a failed write; a StdoutError passes it
            try:
                args = parser.parse_args(argv)
            except SystemExit as exc:  # --help, --version, or an argument error (printed)
                flush_stdout()
                return int(exc.code or 0)
            if args.command is None:
                parser.print_help(sys.stdout)
                flush_stdout()
                return EXIT_OK
            return args
    except BrokenPipeError:
        _drop_stdout()
        return EXIT_OK
    except StdoutError as exc:
        print(f"wobjcal: error: {exc}", file=sys.stderr)
        _drop_stdout()
        return EXIT_INPUT


def _unnamed(exc: BaseException) -> str:
    """Words for an error that carries no message (``wobjcal ui`` once printed only
    ``error: ``): its type, and what it means when that is known."""
    if isinstance(exc, TimeoutError):
        return "TimeoutError: a step did not finish within its time limit"
    if isinstance(exc, MemoryError):
        return "MemoryError: the machine ran out of memory"
    return f"{type(exc).__name__} (no message; run again with --debug for the traceback)"


def _run(args: argparse.Namespace) -> int:
    handler: Callable[[argparse.Namespace], int] = args.handler
    return handler(args)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line with ``argv`` (default ``sys.argv[1:]``); return the exit code."""
    args = _parse(build_parser(), argv)
    if isinstance(args, int):
        return args
    debug = bool(getattr(args, "debug", False))
    logging.basicConfig(level=logging.DEBUG if debug else logging.WARNING, format="%(message)s")
    previous = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        with native_output_to_stderr(), checked_stdout():
            code = _run(args)
            flush_stdout()  # output lost at the last flush is a failure, not a success
            return code
    except Terminated:
        print(f"wobjcal {args.command}: terminated", file=sys.stderr)
        _exit_now(EXIT_TERMINATED)
    except BrokenPipeError:  # e.g. `wobjcal check --json plan.json | head`: the reader left
        _drop_stdout()
        return EXIT_OK
    except (WobjcalError, OSError) as exc:
        if isinstance(exc, StdoutError):
            _drop_stdout()
        if debug:
            raise
        what = (
            f"{exc.filename}: {exc.strerror}" if isinstance(exc, OSError) and exc.filename else exc
        )
        print(f"wobjcal {args.command}: error: {str(what) or _unnamed(exc)}", file=sys.stderr)
        return EXIT_INPUT
    except KeyboardInterrupt:
        print(f"wobjcal {args.command}: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # a bug: say so briefly, the traceback is one flag away
        if debug:
            raise
        what = f"{type(exc).__name__}: {exc}" if str(exc) else _unnamed(exc)
        if isinstance(exc, MemoryError):
            what = f"out of memory ({what})"
        print(
            f"wobjcal {args.command}: internal error: {what} "
            "(run again with --debug for the traceback)",
            file=sys.stderr,
        )
        return EXIT_INPUT
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
