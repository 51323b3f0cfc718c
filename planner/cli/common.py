"""Helpers shared by the ``wobjcal`` commands: consoles, plan loading, JSON output."""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import sys
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import Any, TextIO, cast

from rich.console import Console

from calib.errors import WobjcalError
from calib.plan.file import Plan, load_plan


def count_arg(minimum: int, maximum: int | None = None) -> Callable[[str], int]:
    """An argparse ``type`` for whole numbers ``>= minimum`` (and ``<= maximum``)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be >= {minimum}, got {value}")
        if maximum is not None and value > maximum:
            shown = f"{value:,}" if value < 10**15 else f"{value:.3g}"
            raise argparse.ArgumentTypeError(f"must be at most {maximum:,}, got {shown}")
        return value

    return parse


@contextlib.contextmanager
def native_output_to_stderr() -> Iterator[None]:
    """Send what native code prints on file descriptor 1 to stderr for the duration.

    PyBullet's URDF loader prints warnings (``b3Warning ... No inertial data``) with C
    ``printf``; in ``--json`` output they would corrupt the document. Python's ``sys.stdout``
    keeps writing to the real standard output through a private duplicate. Does nothing when
    ``sys.stdout`` is not the process's file descriptor 1 (e.g. captured by a test).
    """
    try:
        real = sys.stdout is not None and sys.stdout.fileno() == 1
    except (AttributeError, OSError, ValueError):
        real = False
    if not real:
        yield
        return
    sys.stdout.flush()
    saved_fd = os.dup(1)
    private = os.fdopen(os.dup(saved_fd), "w", encoding=sys.stdout.encoding, errors="replace")
    old_stdout = sys.stdout
    os.dup2(2, 1)
    sys.stdout = private
    try:
        yield
    finally:
        with contextlib.suppress(BrokenPipeError, OSError, ValueError):
            private.flush()
        sys.stdout = old_stdout
        os.dup2(saved_fd, 1)
        os.close(saved_fd)
        with contextlib.suppress(BrokenPipeError, OSError):
            private.close()


class StdoutError(WobjcalError):
    """Standard output could not be written (a full disk or device, an I/O error): the
    command's output is lost, so it fails (exit 2) instead of reporting success."""


class _CheckedStdout:
    """``sys.stdout`` for a command: a write or flush that fails raises :class:`StdoutError`
    naming standard output (a reader that left, :class:`BrokenPipeError`, passes unchanged);
    everything else is the wrapped stream's."""

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream

    def _checked(self, action: Callable[[], int | None]) -> int | None:
        try:
            return action()
        except BrokenPipeError:
            raise
        except OSError as exc:
            raise StdoutError(f"cannot write to standard output: {exc}") from exc

    def write(self, text: str) -> int | None:
        return self._checked(lambda: self._stream.write(text))

    def writelines(self, lines: Iterable[str]) -> None:
        for line in lines:
            self.write(line)

    def flush(self) -> None:
        self._checked(self._stream.flush)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


@contextlib.contextmanager
def checked_stdout() -> Iterator[None]:
    """Make ``sys.stdout`` a :class:`_CheckedStdout` for the duration; the caller flushes it
    before leaving, so that an output lost at the last flush is an error too."""
    if sys.stdout is None or isinstance(sys.stdout, _CheckedStdout):
        yield
        return
    old = sys.stdout
    sys.stdout = cast(TextIO, _CheckedStdout(old))
    try:
        yield
    finally:
        sys.stdout = old


def flush_stdout() -> None:
    """Flush ``sys.stdout``; a failure (not a reader that left) raises :class:`StdoutError`."""
    if sys.stdout is None:
        return
    try:
        sys.stdout.flush()
    except (BrokenPipeError, StdoutError):
        raise
    except OSError as exc:
        raise StdoutError(f"cannot write to standard output: {exc}") from exc


def stdout() -> Console:
    """A console on the current ``sys.stdout`` (tests capture it); no colour when piped."""
    return Console(file=sys.stdout, highlight=False, soft_wrap=True)


def stderr() -> Console:
    """A console on the current ``sys.stderr`` for progress and notes."""
    return Console(file=sys.stderr, highlight=False, soft_wrap=True)


def read_plan(path: str, command: str | None = None) -> tuple[Plan, Path]:
    """Load the plan at ``path`` strictly; return it and its directory (for relative paths).

    With ``command`` (a job that builds the plan's cell: ``"check"``, ...), a plan without a
    ``cell`` section is said on stderr (:func:`planner.plan_cell.default_cell_note`)."""
    from planner.plan_cell import default_cell_note

    p = Path(path)
    plan = load_plan(p)
    if command is not None and (note := default_cell_note(plan)):
        print(f"wobjcal {command}: note: {note}", file=sys.stderr)
    return plan, p.resolve().parent


def print_json(obj: Any) -> None:
    """Print ``obj`` as indented JSON on stdout (keys sorted, finite numbers only)."""
    sys.stdout.write(json.dumps(obj, indent=2, sort_keys=True, allow_nan=False) + "\n")
