"""Robot descriptions wobjcal prepared itself: plain URDF files PyBullet can open.

A xacro file, or a URDF whose ``package://`` meshes are found through a ROS package path, is
turned into a plain URDF whose mesh references are absolute paths
(:mod:`planner.robot.description`). PyBullet needs a file, so that text is written here:
``$WOBJCAL_CACHE_DIR/robots/<digest>.urdf`` (default ``~/.cache/wobjcal/robots``), named by the
SHA-256 of its bytes and of the folders its meshes may be read from. Beside it,
``<digest>.roots`` lists those folders, one a line: :func:`planner.robot.urdf.load_urdf`
reads a prepared file's meshes only there (:func:`prepared_roots`), so the rule that a robot
description reads nothing outside its own package or the ROS packages it names holds for
the prepared file too. Writing the same text again rewrites nothing. The files are a few
kilobytes each; nothing evicts them. The cache is optional: where its folder cannot be written
(read-only, full), the file goes to a temporary folder of this process, removed at its exit,
with one warning.
"""

from __future__ import annotations

import atexit
import hashlib
import logging
import os
import shutil
import tempfile
from pathlib import Path

from calib.atomic_io import write_bytes_atomic
from planner.errors import URDFError

#: The cache kind (sub-folder of the cache root) of prepared robot descriptions.
KIND = "robots"
#: A ``.roots`` file larger than this is not a list wobjcal wrote.
MAX_ROOTS_BYTES = 1 << 20

log = logging.getLogger(__name__)
#: This process's folder for prepared files when the cache cannot be written (made once).
_FALLBACK: list[Path] = []
#: Cache folders whose failure was said already.
_WARNED: set[str] = set()


def _fallback_dir() -> Path:
    """A temporary folder of this process, removed at its exit."""
    if not _FALLBACK:
        folder = Path(tempfile.mkdtemp(prefix="wobjcal-robots-"))
        atexit.register(shutil.rmtree, folder, True)
        _FALLBACK.append(folder)
    return _FALLBACK[0]


def prepared_dir() -> Path:
    """``$WOBJCAL_CACHE_DIR/robots`` (default ``~/.cache/wobjcal/robots``; the root the
    cell's caches use, :func:`planner.cell.disk_cache.cache_root`, which this layer cannot
    import)."""
    root = os.environ.get("WOBJCAL_CACHE_DIR") or Path.home() / ".cache" / "wobjcal"
    return Path(root) / KIND


def write_prepared(urdf: bytes, roots: tuple[Path, ...]) -> Path:
    """Store a prepared URDF and the folders its meshes may be read from; return its path
    (in the cache, or in this process's temporary folder when the cache cannot be written).

    Raises:
        URDFError: neither the cache nor a temporary folder can be written (the message names
            the cache folder, the reason and ``WOBJCAL_CACHE_DIR``).
    """
    listed = "".join(f"{r}\n" for r in roots).encode("utf-8")
    digest = hashlib.sha256(urdf + b"\0" + listed).hexdigest()[:40]
    folder = prepared_dir()
    try:
        return _write(folder, digest, urdf, listed)
    except OSError as exc:
        why = f"cannot write the prepared robot description to {folder}: {exc.strerror or exc}"
    try:
        path = _write(_fallback_dir(), digest, urdf, listed)
    except OSError as exc:
        raise URDFError(
            f"{why}, nor to a temporary folder ({exc.strerror or exc}); set WOBJCAL_CACHE_DIR "
            "to a writable folder"
        ) from None
    if str(folder) not in _WARNED:  # once a cache folder in this process
        _WARNED.add(str(folder))
        log.warning("%s; using a temporary folder for this run", why)
    return path


def _write(folder: Path, digest: str, urdf: bytes, listed: bytes) -> Path:
    path = folder / f"{digest}.urdf"
    side = path.with_suffix(".roots")
    if not (_same(side, listed) and _same(path, urdf)):
        folder.mkdir(parents=True, exist_ok=True)
        write_bytes_atomic(side, listed)  # the roots first: a URDF is never without them
        write_bytes_atomic(path, urdf)
    return path


def _same(path: Path, data: bytes) -> bool:
    try:
        return path.is_file() and path.stat().st_size == len(data) and path.read_bytes() == data
    except OSError:
        return False


def prepared_roots(path: Path) -> tuple[Path, ...]:
    """The folders the meshes of ``path`` may be read from, when it is a prepared file
    (in :func:`prepared_dir`, with its ``.roots`` beside it); else ``()``."""
    try:
        folders = {prepared_dir().resolve(), *(f.resolve() for f in _FALLBACK)}
        if path.resolve().parent not in folders:
            return ()
        side = path.with_suffix(".roots")
        if not side.is_file() or side.stat().st_size > MAX_ROOTS_BYTES:
            return ()
        lines = side.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return ()
    return tuple(Path(line) for line in lines if line.strip() and Path(line).is_absolute())


__all__ = ["KIND", "prepared_dir", "prepared_roots", "write_prepared"]
