"""A robot uploaded as a zip: its URDF or xacro file with the meshes it refers to.

:func:`unpack_robot_zip` extracts the archive safely (no absolute paths, no ``..``, no links, a
bounded count and total size), picks its robot file (:func:`robot_member`), and makes every
mesh reference resolve inside the unpacked folder:

* a ``.urdf``: ``package://<package>/<path>`` becomes the absolute path of the file when it is
  in the archive (in the ROS package of that name in the archive, or under ``<package>/<path>``
  or ``<path>``); a reference to a file that is not in the archive is an error naming it;
* a ``.xacro`` (a zip of ROS package folders, e.g. ``abb_irb2400_support/`` and
  ``abb_resources/``, each with its ``package.xml``): expanded with the packages found in the
  unpacked folder only (:func:`planner.robot.description.prepared_urdf`; ``$(find pkg)`` of a
  package not in the zip is an error naming it), every argument at its default, and written
  beside the packages as ``<name>.expanded.urdf`` with absolute mesh paths.
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
from calib.reading import MAX_URDF_BYTES
from planner.errors import URDFError
from planner.robot.description import prepared_urdf
from planner.robot.ros_packages import PackagePath, find_packages
from planner.robot.urdf_meshes import package_root

#: At most this many files in a robot zip.
MAX_MEMBERS = MAX_ZIP_MEMBERS
#: At most this many bytes unpacked (the URDF may refer to no more, :mod:`calib.limits`).
MAX_UNPACKED_BYTES = MAX_ZIP_UNPACKED_BYTES
#: Beyond this many bytes unpacked, a zip must not unpack to more than
#: :data:`calib.limits.MAX_ZIP_RATIO` times its size (a zip bomb).
RATIO_FREE_BYTES = 16 * 1024 * 1024
_MESH_REF = re.compile(r'filename\s*=\s*"([^"]+)"')
#: The opening ``<robot ...>`` tag of a robot description that names its robot (a xacro file of
#: macros only, included by others, names none).
_NAMED_ROBOT = re.compile(rb"<robot\b[^>]*\bname\s*=", re.S)


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


def robot_member(archive: zipfile.ZipFile, members: list[zipfile.ZipInfo], name: str) -> str:
    """The archive's robot file: its one ``.urdf`` or robot ``.xacro`` (a xacro whose
    ``<robot>`` names the robot; macro files included by others name none).

    A ``.urdf`` beside a xacro of the same name (``irb2400.urdf`` and ``irb2400.xacro``: the
    package's own expansion) gives way to the xacro. Of several, the one named as the zip is
    taken (``irb2400_12_155.zip`` picks ``irb2400_12_155.xacro``).

    Raises:
        InputError: none, or several and none named as the zip (the message lists them).
    """
    urdfs = [m.filename for m in members if m.filename.lower().endswith(".urdf")]
    xacros = [
        m.filename
        for m in members
        if m.filename.lower().endswith(".xacro")
        and m.file_size <= MAX_URDF_BYTES
        and _NAMED_ROBOT.search(archive.read(m))
    ]
    stems = {_stem(x) for x in xacros}
    found = [u for u in urdfs if _stem(u) not in stems] + xacros
    if len(found) == 1:
        return found[0]
    named = [f for f in found if _stem(f) == _stem(name)]
    if len(named) == 1:
        return named[0]
    listed = ", ".join(found) or "none"
    raise InputError(
        f"{name}: a robot zip must hold exactly one robot description (.urdf, or a .xacro "
        f"naming its <robot>), found {listed}; with several, name the zip after the one to "
        "use (e.g. irb2400.zip for irb2400.xacro)"
    )


def _stem(path: str) -> str:
    """``irb2400`` of ``a/irb2400.urdf``, ``irb2400.xacro``, ``irb2400.urdf.xacro``,
    ``irb2400.zip``."""
    base = PurePosixPath(path).name.lower()
    for suffix in (".xacro", ".zip", ".urdf"):
        base = base.removesuffix(suffix)
    return base


def unpack_robot_zip(name: str, content: bytes, folder: Path) -> Path:
    """Unpack a robot zip into ``folder``; return the path of its URDF (references rewritten,
    or the expansion of its xacro file).

    Raises:
        InputError: not a zip, unsafe or too large, no robot file or several
            (:func:`robot_member`), a mesh the URDF refers to that is not in the archive, or a
            xacro file that cannot be expanded from the archive's packages (each message
            names the file).
    """
    try:
        archive = zipfile.ZipFile(BytesIO(content))
    except zipfile.BadZipFile:
        raise InputError(f"{name}: not a zip archive") from None
    with archive:
        members = _safe_members(archive, name, len(content))
        chosen = robot_member(archive, members, name)
        for m in members:  # a file at a time, a MiB at a time: never a whole file in memory
            target = folder / m.filename
            target.parent.mkdir(parents=True, exist_ok=True)
            with archive.open(m) as src, target.open("wb") as dst:
                shutil.copyfileobj(src, dst, 1 << 20)
    packages = find_packages(
        (folder.resolve(),), f"the packages in {name}", "put that package's folder in the zip"
    )
    if chosen.lower().endswith(".xacro"):
        return _expanded(name, folder, folder / chosen, packages)
    urdf = folder / chosen
    text = urdf.read_text(encoding="utf-8", errors="replace")

    def resolve(match: re.Match[str]) -> str:
        ref = match.group(1)
        if ref.startswith("package://"):
            rest = PurePosixPath(ref[len("package://") :])
            inner = PurePosixPath(*rest.parts[1:])
            own = packages.packages.get(rest.parts[0]) if rest.parts else None
            candidates = [folder / rest, folder / inner]
            if own is not None and ".." not in inner.parts:
                candidates.insert(0, own / inner)
        elif ref.startswith("file://") or Path(ref).is_absolute():
            return match.group(0)
        else:
            candidates = [urdf.parent / ref]
        for c in candidates:
            if c.resolve().is_file() and c.resolve().is_relative_to(folder.resolve()):
                return f'filename="{c.resolve()}"'
        raise InputError(f"{name}: {chosen} refers to {ref!r}, which is not in the archive")

    write_bytes_atomic(urdf, _MESH_REF.sub(resolve, text).encode("utf-8"))
    return urdf


def _expanded(name: str, folder: Path, xacro: Path, packages: PackagePath) -> Path:
    """Expand the zip's ``xacro`` with its ``packages`` only; write ``<stem>.expanded.urdf``
    at the top of ``folder``."""
    top = folder.resolve()
    own = package_root(xacro.parent.resolve())
    if not own.is_relative_to(top):  # a package.xml above the upload folder
        raise InputError(f"{name}: the package of {xacro.name} ({own}) is outside the archive")
    try:
        urdf, roots = prepared_urdf(xacro, packages)
    except URDFError as exc:
        shown = str(exc).replace(str(top) + "/", "").replace(str(top), name)  # no cache path
        raise URDFError(f"{name}: {shown}") from None
    outside = [r for r in roots if not r.is_relative_to(top)]
    if outside:
        raise InputError(f"{name}: {xacro.name} reads meshes outside the archive: {outside}")
    out = folder / f"{_stem(xacro.name)}.expanded.urdf"
    write_bytes_atomic(out, urdf)
    return out
