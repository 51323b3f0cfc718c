"""Atomic file writes: a reader sees the old file or the new one, never a half-written one.

The data go to an unnamed temporary file in the target's directory (Linux ``O_TMPFILE``: it
has no name until it is complete, so a process killed while writing, even by ``SIGKILL``,
leaves nothing behind), are flushed and ``fsync``-ed, get a name (``.<target>.wobjcal-<pid>-
<random>.tmp``) and replace the target with :func:`os.replace`, atomic on POSIX and Windows.
Where ``O_TMPFILE`` is not available the file is named from the start; a named temporary file
left by a killed process (its pid no longer running) is removed by the next write into that
directory. On any error the temporary file is removed and the target is left untouched.

The target is treated like ``cp`` treats it:

- a symbolic link is followed: the file it points to is replaced, the link stays; a dangling
  link is refused (``cp``: "not writing through dangling symlink");
- an existing file without any write permission bit is refused, even for root (who may
  write anything): a read-only program or plan stays as it is;
- a directory is refused.
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import secrets
import stat
from pathlib import Path

#: The temporary files this module names: ``.<target name>.wobjcal-<pid>-<hex>.tmp``.
_TMP_RE = re.compile(r"^\.(?P<name>.+)\.wobjcal-(?P<pid>\d+)-[0-9a-f]+\.tmp$")


def resolve_target(path: str | os.PathLike[str]) -> Path:
    """The file a write to ``path`` replaces, checked the way ``cp`` would.

    Raises:
        OSError: a dangling symbolic link, a directory, or a read-only file (``EACCES``),
            naming ``path``.
    """
    target = Path(path)
    if target.is_symlink():
        real = Path(os.path.realpath(target))
        if not real.exists():
            raise FileNotFoundError(
                errno.ENOENT, f"not writing through dangling symbolic link to {real}", str(path)
            )
        target = real
    if target.is_dir():
        raise IsADirectoryError(errno.EISDIR, "is a directory", str(path))
    if target.exists():
        mode = stat.S_IMODE(target.stat().st_mode)
        if not mode & (stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH):
            raise PermissionError(
                errno.EACCES, f"read-only file (mode {mode:o}), not overwritten", str(path)
            )
    return target


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically and return the path written (a symlink's target).

    Args:
        path: target file; its directory must exist.
        data: the bytes to write.

    Raises:
        OSError: the directory does not exist or is not writable, or the target is refused
            (see the module docstring); the target is unchanged.
    """
    target = resolve_target(path)
    directory = target.parent if str(target.parent) else Path()
    remove_stale_temporaries(directory)
    name = f".{target.name}.wobjcal-{os.getpid()}-{secrets.token_hex(4)}.tmp"
    tmp = directory / name
    fd, named = _open_temporary(directory, tmp, path)
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
            if not named:  # give the finished file its temporary name
                _link_unnamed(handle.fileno(), directory, tmp.name)
                named = True
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
        if named:
            with contextlib.suppress(OSError):
                tmp.unlink()
        raise
    _fsync_directory(directory)
    return target


def write_text_atomic(path: str | os.PathLike[str], text: str, encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` atomically (newlines written as given) and return the path."""
    return write_bytes_atomic(path, text.encode(encoding))


def remove_stale_temporaries(directory: Path) -> list[Path]:
    """Remove this module's temporary files in ``directory`` whose writing process is gone."""
    removed: list[Path] = []
    try:
        entries = list(directory.iterdir())
    except OSError:
        return removed
    for entry in entries:
        m = _TMP_RE.match(entry.name)
        if m is None or _running(int(m.group("pid"))):
            continue
        with contextlib.suppress(OSError):
            entry.unlink()
            removed.append(entry)
    return removed


def _running(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


def _open_temporary(directory: Path, tmp: Path, path: str | os.PathLike[str]) -> tuple[int, bool]:
    """A file descriptor to write to and whether it already has a name (``tmp``)."""
    flag = getattr(os, "O_TMPFILE", 0)
    try:
        if flag and Path("/proc/self/fd").is_dir():
            try:
                return os.open(directory, flag | os.O_WRONLY, 0o600), False
            except OSError as exc:
                if exc.errno not in (errno.EOPNOTSUPP, errno.EISDIR, errno.EINVAL):
                    raise
        return os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600), True
    except OSError as exc:  # name the directory the user gave, not the temporary file
        msg = f"cannot write into {directory}: {exc.strerror}"
        raise type(exc)(exc.errno, msg, str(path)) from None


def _link_unnamed(fd: int, directory: Path, name: str) -> None:
    """Give the ``O_TMPFILE`` file ``fd`` the name ``directory/name`` (``linkat`` with
    ``AT_SYMLINK_FOLLOW``, which :func:`os.link` uses only when given a directory fd)."""
    dfd = os.open(directory, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    try:
        os.link(f"/proc/self/fd/{fd}", name, dst_dir_fd=dfd, follow_symlinks=True)
    finally:
        os.close(dfd)


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
