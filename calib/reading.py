"""Bounded file reads: every file wobjcal reads is a regular file of a bounded size.

A plan path to ``/dev/zero`` used to read until memory ran out, and a directory was reported
as "file not found". :func:`check_regular_file` refuses directories, devices and pipes and
files above a size limit, with a message naming the file and the limit, before anything is
read; :func:`read_bytes_capped` then reads at most the limit (a file that grows meanwhile is
refused too). The limits, per kind of file, are here:

- :data:`MAX_JSON_BYTES` 16 MiB: plans and measurements (the shipped plan is 12 kB);
- :data:`MAX_URDF_BYTES` 16 MiB: robot and tool descriptions (a vendor URDF is ~30 kB);
- :data:`MAX_MESH_BYTES` 256 MiB: mesh files (a 2-million-triangle binary STL is 100 MB; the
  triangle limit is checked by the loader, :mod:`planner.cell.scene.workobject`).
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

from calib.errors import InputError

MiB = 1 << 20
#: Largest plan or measurements file, bytes.
MAX_JSON_BYTES = 16 * MiB
#: Largest URDF (robot or tool), bytes.
MAX_URDF_BYTES = 16 * MiB
#: Largest mesh file, bytes.
MAX_MESH_BYTES = 256 * MiB


def check_regular_file(
    path: str | os.PathLike[str], limit: int, what: str, error: type[InputError] = InputError
) -> int:
    """The size of ``path`` in bytes, after checking it is a regular file within ``limit``.

    Args:
        path: the file.
        limit: largest size accepted, bytes.
        what: what the file should be, for messages (e.g. ``"plan file"``).
        error: the exception class to raise (a subclass of :class:`InputError`).

    Raises:
        FileNotFoundError: no such file (``filename`` is ``path``).
        error: a directory, a device, a pipe or a file larger than ``limit``.
    """
    p = Path(path)
    try:
        st = p.stat()
    except FileNotFoundError:
        raise FileNotFoundError(errno.ENOENT, "No such file or directory", str(p)) from None
    if stat.S_ISDIR(st.st_mode):
        raise error(f"{p}: is a directory, not a {what}")
    if not stat.S_ISREG(st.st_mode):
        raise error(f"{p}: not a regular file (a device, a pipe or a socket), so not a {what}")
    if st.st_size > limit:
        raise error(
            f"{p}: {st.st_size / MiB:.1f} MiB is more than a {what} may have "
            f"({limit / MiB:.0f} MiB)"
        )
    return int(st.st_size)


def read_bytes_capped(
    path: str | os.PathLike[str], limit: int, what: str, error: type[InputError] = InputError
) -> bytes:
    """The bytes of ``path``, read only after :func:`check_regular_file` and never more than
    ``limit`` of them.

    Raises:
        FileNotFoundError: no such file; OSError: it cannot be read.
        error: not a regular file, or larger than ``limit`` (also when it grew while read).
    """
    check_regular_file(path, limit, what, error)
    with Path(path).open("rb") as handle:
        data = handle.read(limit + 1)
    if len(data) > limit:
        raise error(f"{path}: grew beyond {limit / MiB:.0f} MiB while being read as a {what}")
    return data


__all__ = [
    "MAX_JSON_BYTES",
    "MAX_MESH_BYTES",
    "MAX_URDF_BYTES",
    "check_regular_file",
    "read_bytes_capped",
]
