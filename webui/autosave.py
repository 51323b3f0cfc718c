"""Autosave files: one per plan and bound port, held by a lock, found again after a crash.

A UI server autosaves its session plan (:class:`webui.state.SessionState`) to
``~/.cache/wobjcal/autosave/<plan stem>-<8 hex of its absolute path>-<port>.json`` (or
``demo-<port>.json``), named for the port the server actually bound (viser moves on to the next
port when the requested one is busy), and holds an exclusive lock on ``<file>.lock`` while it
runs (:class:`AutosaveLock`; the operating system drops it when the process dies, even by
``kill -9``). So two servers never write one file.

On start, :func:`find_newer_autosave` looks for this plan's autosaves from earlier runs (any
port) that no running server holds, whose content differs from the plan file and that are
newer than it: the newest is what the last session left. The app restores it and says so, or
with ``fresh`` keeps it aside as ``<file>.<time>.bak`` (:func:`set_aside`) so no edit is lost.

A restore is marked (``<file>.restoring``, :func:`mark_restoring`) until the restored session
has loaded its cell and checked its points (:func:`clear_restoring`). A mark left behind means
that restore never finished: the server ran out of memory, was killed or failed while loading
that autosave. The next start does not restore it again (it would crash again, at every start
until ``--fresh``): it sets it aside and says so, with the path (issue 27).
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import time
from dataclasses import dataclass
from pathlib import Path

#: Folder of the default autosave files (see :func:`default_autosave_path`).
AUTOSAVE_DIR = Path.home() / ".cache" / "wobjcal" / "autosave"

try:  # POSIX advisory locks; elsewhere the lock only records the pid
    import fcntl
except ImportError:  # pragma: no cover (Windows)
    fcntl = None  # type: ignore[assignment]


def _prefix(plan_path: str | Path | None) -> str:
    if plan_path is None:
        return "demo"
    resolved = Path(plan_path).resolve()
    digest = hashlib.sha256(str(resolved).encode()).hexdigest()[:8]
    return f"{resolved.stem}-{digest}"


def default_autosave_path(plan_path: str | Path | None, port: int) -> Path:
    """Where a session autosaves by default: one file per plan and bound port.

    ``~/.cache/wobjcal/autosave/<plan stem>-<8 hex of its absolute path>-<port>.json``, or
    ``demo-<port>.json`` for the built-in demo.
    """
    return AUTOSAVE_DIR / f"{_prefix(plan_path)}-{int(port)}.json"


class AutosaveLockedError(OSError):
    """Another running server holds the autosave file's lock."""


class AutosaveLock:
    """An exclusive lock on ``<autosave>.lock``, held until :meth:`release` or process exit.

    Raises:
        AutosaveLockedError: another process holds it (the message names the file).
    """

    def __init__(self, autosave: Path) -> None:
        self.path = Path(str(autosave) + ".lock")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._fd: int | None = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        if fcntl is not None:
            try:
                fcntl.flock(self._fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                os.close(self._fd)
                self._fd = None
                raise AutosaveLockedError(
                    f"{autosave} is in use by another wobjcal UI server (lock {self.path})"
                ) from None
        os.ftruncate(self._fd, 0)
        os.write(self._fd, f"{os.getpid()}\n".encode())

    def release(self) -> None:
        """Drop the lock (idempotent); the lock file is removed."""
        if self._fd is None:
            return
        with contextlib.suppress(OSError):
            self.path.unlink()
        os.close(self._fd)
        self._fd = None


def in_use(autosave: Path) -> bool:
    """True when a running server holds the lock of ``autosave``."""
    try:
        AutosaveLock(autosave).release()
    except AutosaveLockedError:
        return True
    return False


@dataclass(frozen=True)
class FoundAutosave:
    """An autosave of an earlier session of the plan.

    Attributes:
        path: the file.
        saved: its modification time (seconds since the epoch).
    """

    path: Path
    saved: float

    def describe(self) -> str:
        """E.g. ``"~/.cache/wobjcal/autosave/plan-1a2b3c4d-8080.json, saved 14:02:11"``."""
        when = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(self.saved))
        return f"{self.path}, saved {when}"


def find_newer_autosave(
    plan_path: str | Path | None,
    plan_bytes: bytes,
    folder: Path | None = None,
    also: Path | None = None,
) -> FoundAutosave | None:
    """The newest autosave of the plan at ``plan_path`` worth restoring, or ``None``.

    Args:
        plan_path: the plan file (``None``: the built-in demo).
        plan_bytes: the plan as the session would autosave it unchanged: an autosave with the
            same bytes holds no edit.
        folder: where to look (default :data:`AUTOSAVE_DIR`).
        also: one more file to consider (an explicit autosave path).

    An autosave counts when no running server holds it, it differs from ``plan_bytes`` and it
    is newer than the plan file.
    """
    where = AUTOSAVE_DIR if folder is None else folder
    candidates = set(where.glob(f"{_prefix(plan_path)}-*.json")) if where.is_dir() else set()
    if also is not None and also.is_file():
        candidates.add(also)
    plan_time = Path(plan_path).stat().st_mtime if plan_path is not None else 0.0
    best: FoundAutosave | None = None
    for path in candidates:
        try:
            saved = path.stat().st_mtime
            if saved <= plan_time or in_use(path) or path.read_bytes() == plan_bytes:
                continue
        except OSError:
            continue
        if best is None or saved > best.saved:
            best = FoundAutosave(path, saved)
    return best


def restoring_mark(path: Path) -> Path:
    """The mark of a restore of the autosave ``path`` under way: ``<path>.restoring``."""
    return Path(str(path) + ".restoring")


def mark_restoring(path: Path) -> None:
    """Mark that the autosave ``path`` is being restored (the pid and time in the mark)."""
    mark = restoring_mark(path)
    mark.write_text(f"{os.getpid()} {time.strftime('%Y-%m-%d %H:%M:%S')}\n", encoding="utf-8")


def clear_restoring(path: Path) -> None:
    """The restore of the autosave ``path`` finished: drop its mark."""
    with contextlib.suppress(OSError):
        restoring_mark(path).unlink()


def restore_unfinished(path: Path) -> bool:
    """True when an earlier restore of the autosave ``path`` left its mark: it never finished."""
    return restoring_mark(path).exists()


def set_aside(path: Path) -> Path | None:
    """Rename ``path`` to ``<path>.<time>.bak`` so a fresh session does not overwrite it."""
    if not path.is_file():
        return None
    target = path.with_name(f"{path.name}.{time.strftime('%Y%m%d-%H%M%S')}.bak")
    path.replace(target)
    return target


__all__ = [
    "AUTOSAVE_DIR",
    "AutosaveLock",
    "AutosaveLockedError",
    "FoundAutosave",
    "clear_restoring",
    "default_autosave_path",
    "find_newer_autosave",
    "in_use",
    "mark_restoring",
    "restore_unfinished",
    "restoring_mark",
    "set_aside",
]
