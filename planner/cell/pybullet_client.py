"""Importing and connecting PyBullet without its build-time banner in the output.

PyBullet's native code writes "pybullet build time: ..." when it is imported and when a client
connects; it lands in the middle of the command line's tables. Import PyBullet as
``from planner.cell.pybullet_client import pb`` and connect with :func:`connect_direct`: both run
with file descriptors 1 and 2 pointed at ``/dev/null`` and flush the C library's buffers before
they are restored, so the banner never reaches the terminal or a ``--json`` document.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
from collections.abc import Iterator


def _flush_all() -> None:
    if sys.stdout is not None:
        with contextlib.suppress(OSError, ValueError):
            sys.stdout.flush()
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None).fflush(None)


@contextlib.contextmanager
def _native_output_silenced() -> Iterator[None]:
    """Point file descriptors 1 and 2 at /dev/null, flushing C stdio before restoring them."""
    _flush_all()
    if sys.stderr is not None:
        with contextlib.suppress(OSError, ValueError):
            sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        os.dup2(devnull, 2)
        yield
        _flush_all()
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in (*saved, devnull):
            os.close(fd)


with _native_output_silenced():
    import pybullet as pb


__all__ = ["connect_direct", "pb"]


def connect_direct() -> int:
    """Open a PyBullet DIRECT client quietly and return its ``physicsClientId``."""
    with _native_output_silenced():
        return int(pb.connect(pb.DIRECT))
