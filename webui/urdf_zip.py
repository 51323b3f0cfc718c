"""A robot uploaded as a zip: its URDF with the meshes it refers to.

:func:`unpack_robot_zip` extracts the archive safely (no absolute paths, no ``..``, no links, a
bounded count and total size), finds its one URDF, and makes every mesh reference resolve
inside the unpacked folder: ``package://<package>/<path>`` becomes a path relative to the URDF
when the file is in the archive (under ``<package>/<path>`` or ``<path>``); a reference to a
file that is not in the archive is an error naming it.
"""

from __future__ import annotations

import re
import shutil
import zipfile
from io import BytesIO
from pathlib import Path, PurePosixPath

from calib.atomic_io import write_bytes_atomic
from calib.errors import InputError
from calib.limits import MAX_ZIP_MEMBERS, MAX_ZIP_RATIO, MAX_ZIP_UNPACKED_BYTES

#: At most this many files in a robot zip.
MAX_MEMBERS = MAX_ZIP_MEMBERS
#: At most this many bytes unpacked (the URDF may refer to no more, :mod:`calib.limits`).
MAX_UNPACKED_BYTES = MAX_ZIP_UNPACKED_BYTES
#: Beyond this many bytes unpacked, a zip must not unpack to more than
#: :data:`calib.limits.MAX_ZIP_RATIO` times its size (a zip bomb).
RATIO_FREE_BYTES = 16 * 1024 * 1024
_MESH_REF = re.compile(r'filename\s*=\s*"([^"]+)"')


def _safe_members(archive: zipfile.ZipFile, name: str, packed: int) -> list[zipfile.ZipInfo]:
    members = [m for m in archive.infolist() if not m.is_dir()]
    if len(members) > MAX_MEMBERS:
        raise InputError(f"{name}: {len(members)} files, more than the {MAX_MEMBERS} allowed")
    total = sum(m.file_size for m in members)
    if total > MAX_UNPACKED_BYTES:
        raise InputError(
            f"{name}: unpacks to {total / 2**20:.0f} MiB, at most "
            f"{MAX_UNPACKED_BYTES / 2**20:.0f} MiB (a robot's meshes are 5-40 MB; PyBullet and "
            "the drawings load them all); refused before unpacking"
        )
    if total > RATIO_FREE_BYTES and total > MAX_ZIP_RATIO * packed:
        raise InputError(
            f"{name}: {packed / 1024:.0f} KB unpack to {total / 2**20:.0f} MiB, "
            f"{total / max(packed, 1):.0f} times its size, at most {MAX_ZIP_RATIO} (meshes "
            "compress 3 to 10 times; this is a zip bomb); refused before unpacking"
        )
    for m in members:
        p = PurePosixPath(m.filename)
        if p.is_absolute() or ".." in p.parts or (m.external_attr >> 16) & 0o170000 == 0o120000:
            raise InputError(f"{name}: unsafe path in the archive: {m.filename!r}")
    return members


def unpack_robot_zip(name: str, content: bytes, folder: Path) -> Path:
    """Unpack a robot zip into ``folder``; return the path of its URDF (references rewritten).

    Raises:
        InputError: not a zip, unsafe or too large, no URDF or more than one, or a mesh the
            URDF refers to that is not in the archive (each message names the file).
    """
    try:
        archive = zipfile.ZipFile(BytesIO(content))
    except zipfile.BadZipFile:
        raise InputError(f"{name}: not a zip archive") from None
    with archive:
        members = _safe_members(archive, name, len(content))
        urdfs = [m.filename for m in members if m.filename.lower().endswith(".urdf")]
        if len(urdfs) != 1:
            found = ", ".join(urdfs) or "none"
            raise InputError(f"{name}: a robot zip must hold exactly one .urdf file, found {found}")
        for m in members:  # a file at a time, a MiB at a time: never a whole file in memory
            target = folder / m.filename
            target.parent.mkdir(parents=True, exist_ok=True)
            with archive.open(m) as src, target.open("wb") as dst:
                shutil.copyfileobj(src, dst, 1 << 20)
    urdf = folder / urdfs[0]
    text = urdf.read_text(encoding="utf-8", errors="replace")

    def resolve(match: re.Match[str]) -> str:
        ref = match.group(1)
        if ref.startswith("package://"):
            rest = PurePosixPath(ref[len("package://") :])
            candidates = [folder / rest, folder / PurePosixPath(*rest.parts[1:])]
        elif ref.startswith("file://") or Path(ref).is_absolute():
            return match.group(0)
        else:
            candidates = [urdf.parent / ref]
        for c in candidates:
            if c.resolve().is_file() and c.resolve().is_relative_to(folder.resolve()):
                return f'filename="{c.resolve()}"'
        raise InputError(f"{name}: {urdfs[0]} refers to {ref!r}, which is not in the archive")

    write_bytes_atomic(urdf, _MESH_REF.sub(resolve, text).encode("utf-8"))
    return urdf
