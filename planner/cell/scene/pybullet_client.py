"""Importing and connecting PyBullet without its build-time banner in the output.

PyBullet's native code writes "pybullet build time: ..." when it is imported and when a client
connects; it lands in the middle of the command line's tables. Import PyBullet as
``from planner.cell.scene.pybullet_client import pb`` and connect with :func:`connect_direct`: both
run with file descriptors 1 and 2 pointed at ``/dev/null`` and flush the C library's buffers before
they are restored, so the banner never reaches the terminal or a ``--json`` document.

Loading a URDF, PyBullet also prints a ``b3Warning`` pair per link without ``<inertial>``
("No inertial data for link, using mass=1 ...", then the link's name): dozens of lines for a
vendor URDF, none of them news to wobjcal, which never simulates dynamics.
:func:`native_chatter_filtered` captures what native code prints meanwhile and sends it to the
log instead: those warnings at debug level (naming the links), anything else at warning level,
so nothing is lost.
"""

from __future__ import annotations

import contextlib
import ctypes
import logging
import os
import re
import sys
import tempfile
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

log = logging.getLogger(__name__)
_B3 = re.compile(r"b3(?:Warning|Error|Printf)\[[^\]]*\]:\s*")
_NO_INERTIA = "No inertial data for link"


@contextlib.contextmanager
def native_chatter_filtered() -> Iterator[None]:
    """Capture what native code prints on file descriptors 1 and 2 for the duration, and log
    it: PyBullet's missing-inertia warnings at debug level, anything else as a warning."""
    _flush_all()
    if sys.stderr is not None:
        with contextlib.suppress(OSError, ValueError):
            sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    with tempfile.TemporaryFile() as capture:
        try:
            os.dup2(capture.fileno(), 1)
            os.dup2(capture.fileno(), 2)
            yield
        finally:
            _flush_all()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
            capture.seek(0)
            _log_native(capture.read().decode("utf-8", errors="replace"))


def _log_native(text: str) -> None:
    """Log captured native output (see :func:`native_chatter_filtered`)."""
    if not text.strip():
        return
    chunks = [c.strip() for c in _B3.split(text) if c.strip()]
    no_inertia, i = [], 0
    while i < len(chunks):
        chunk = chunks[i]
        if chunk.startswith(_NO_INERTIA):
            name = chunks[i + 1] if i + 1 < len(chunks) and "\n" not in chunks[i + 1] else "?"
            no_inertia.append(name)
            i += 2
            continue
        log.warning("PyBullet: %s", chunk)
        i += 1
    if no_inertia:
        log.debug("PyBullet: no inertial data (mass 1 assumed) for links %s", no_inertia)


__all__ = ["connect_direct", "native_chatter_filtered", "pb"]


def connect_direct() -> int:
    """Open a PyBullet DIRECT client quietly and return its ``physicsClientId``."""
    with _native_output_silenced():
        return int(pb.connect(pb.DIRECT))
