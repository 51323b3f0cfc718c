"""Atomic file writes: a reader sees the old file or the new one, never a half-written one.

The text goes to a temporary file in the same directory (same file system), is flushed and
``fsync``-ed, then replaces the target with ``Path.replace`` (:func:`os.replace`), which is
atomic on POSIX and Windows. On any error the temporary file is removed and the target is
left untouched.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically and return the path.

    Args:
        path: target file; its directory must exist.
        data: the bytes to write.

    Raises:
        OSError: the directory does not exist or is not writable (the target is unchanged).
    """
    target = Path(path)
    directory = target.parent if str(target.parent) else Path()
    try:
        fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=directory)
    except OSError as exc:  # name the directory the user gave, not the temporary file
        msg = f"cannot write into {directory}: {exc.strerror}"
        raise type(exc)(exc.errno, msg, str(target)) from None

    tmp = Path(tmp_name)
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        if target.exists():
            # keep the permissions of the file being replaced
            with contextlib.suppress(OSError):
                tmp.chmod(target.stat().st_mode & 0o7777)
        else:
            umask = os.umask(0)
            os.umask(umask)
            tmp.chmod(0o666 & ~umask)
        tmp.replace(target)  # os.replace: atomic
    except BaseException:
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise
    _fsync_directory(directory)
    return target


def write_text_atomic(path: str | os.PathLike[str], text: str, encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` atomically (newlines written as given) and return the path."""
    return write_bytes_atomic(path, text.encode(encoding))


def _fsync_directory(directory: Path) -> None:
    """Make the rename durable where the platform allows opening a directory."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)
