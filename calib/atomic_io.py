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
- a directory is refused;
- a target that exists and is not a regular file (a character or block device such as
  ``/dev/null``, a FIFO) is written in place, like ``cp`` writes it: opened, written, closed,
  never replaced by a regular file;
- ``/dev/stdout``, ``/dev/stderr``, ``/dev/fd/N`` and ``/proc/self/fd/N`` are this process's
  open file descriptor ``N``, written where it points at its current offset (``sys.stdout`` and
  ``sys.stderr`` for 1 and 2, so a command that sends native output elsewhere meanwhile still
  writes to its real standard output), never opened again by name.

Every step is checked: a failed write, flush, ``fsync``, close or rename (a full disk:
``ENOSPC``) raises :class:`OSError` whose ``filename`` is the path the caller gave, so the
message names the file and the reason. A device that cannot ``fsync`` (``EINVAL``) is not an
error.
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import secrets
import stat
import sys
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

    A device, FIFO or standard stream is written in place instead (see the module docstring).

    Args:
        path: target file; its directory must exist.
        data: the bytes to write.

    Raises:
        OSError: the directory does not exist or is not writable, the target is refused, or a
            write, flush, sync, close or rename failed (see the module docstring); its
            ``filename`` is ``path``; a regular target is unchanged.
    """
    fd_number = own_descriptor(path)
    if fd_number is not None:
        _write_descriptor(fd_number, data, path)
        return Path(path)
    target = resolve_target(path)
    try:
        mode = target.stat().st_mode
    except FileNotFoundError:
        mode = stat.S_IFREG
    if not stat.S_ISREG(mode):
        _write_in_place(target, data, path)
        return target
    directory = target.parent if str(target.parent) else Path()
    remove_stale_temporaries(directory)
    name = f".{target.name}.wobjcal-{os.getpid()}-{secrets.token_hex(4)}.tmp"
    tmp = directory / name
    fd, named = _open_temporary(directory, tmp, path)
    try:
        try:
            _write_all(fd, data)
            os.fsync(fd)
            if not named:  # give the finished file its temporary name
                _link_unnamed(fd, directory, tmp.name)
                named = True
        finally:
            os.close(fd)  # a close error (NFS, a full quota) is a failed write too
        if target.exists():
            # keep the permissions of the file being replaced
            with contextlib.suppress(OSError):
                tmp.chmod(target.stat().st_mode & 0o7777)
        else:
            umask = os.umask(0)
            os.umask(umask)
            tmp.chmod(0o666 & ~umask)
        tmp.replace(target)  # os.replace: atomic
    except BaseException as exc:
        if named:
            with contextlib.suppress(OSError):
                tmp.unlink()
        if isinstance(exc, OSError):
            raise _naming(exc, path) from None
        raise
    _fsync_directory(directory)
    return target


def write_text_atomic(path: str | os.PathLike[str], text: str, encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` atomically (newlines written as given) and return the path."""
    return write_bytes_atomic(path, text.encode(encoding))


#: ``/proc/<pid>/fd/<n>`` (or a thread's ``/proc/<pid>/task/<tid>/fd/<n>``).
_PROC_FD_RE = re.compile(r"/proc/(?P<pid>\d+)(?:/task/\d+)?/fd/(?P<fd>\d+)")


def own_descriptor(path: str | os.PathLike[str]) -> int | None:
    """The file descriptor of this process that ``path`` names (``/dev/stdout`` is 1,
    ``/dev/fd/5`` and ``/proc/self/fd/5`` are 5), or ``None`` for any other path.

    Symbolic links are followed one at a time up to ``/proc/<pid>/fd/<n>``, whose own link
    (``pipe:[...]``, or a file that may have been replaced meanwhile) is not followed.
    """
    current = Path(path).absolute()
    try:
        for _ in range(40):  # the kernel's limit of nested links
            parent = current.parent.resolve()
            current = parent / current.name
            m = _PROC_FD_RE.fullmatch(str(current))
            if m is not None:
                return int(m.group("fd")) if int(m.group("pid")) == os.getpid() else None
            if not current.is_symlink():
                return None
            current = parent / current.readlink()
    except (OSError, RuntimeError):  # a loop, an unreadable link: an ordinary path
        return None
    return None


def _write_descriptor(fd: int, data: bytes, path: str | os.PathLike[str]) -> None:
    """Write ``data`` to this process's descriptor ``fd`` where it stands (standard output and
    error through ``sys.stdout`` and ``sys.stderr``, after what they hold), checked."""
    stream = {1: sys.stdout, 2: sys.stderr}.get(fd)
    try:
        if stream is None:
            _write_all(fd, data)
            return
        stream.flush()
        binary = getattr(stream, "buffer", None)
        if binary is not None:
            binary.write(data)
            binary.flush()
        else:
            stream.write(data.decode(getattr(stream, "encoding", None) or "utf-8", "replace"))
            stream.flush()
    except OSError as exc:
        raise _naming(exc, path) from None


def _write_in_place(target: Path, data: bytes, path: str | os.PathLike[str]) -> None:
    """Write ``data`` into the existing non-regular file ``target`` (a device, a FIFO): open,
    write, sync (where the device can), close, each checked; the node stays."""
    try:
        fd = os.open(target, os.O_WRONLY | getattr(os, "O_NOCTTY", 0))
        try:
            _write_all(fd, data)
            try:
                os.fsync(fd)
            except OSError as exc:  # a terminal, pipe or /dev/null has nothing to sync
                if exc.errno not in (errno.EINVAL, errno.EROFS, errno.ENOTSUP, errno.ENOTTY):
                    raise
        finally:
            os.close(fd)
    except OSError as exc:
        raise _naming(exc, path) from None


def _write_all(fd: int, data: bytes) -> None:
    """``os.write`` until every byte of ``data`` is written (a write may take only part)."""
    view = memoryview(data)
    while view:
        written = os.write(fd, view)
        if written <= 0:  # never for a blocking descriptor; do not loop forever
            raise OSError(errno.EIO, "nothing written")
        view = view[written:]


def _naming(exc: OSError, path: str | os.PathLike[str]) -> OSError:
    """``exc`` with ``filename`` the path the user gave (not a temporary file's)."""
    if exc.filename == os.fspath(path) and exc.filename2 is None:
        return exc
    reason = exc.strerror or str(exc)
    return OSError(exc.errno, reason, os.fspath(path))


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
