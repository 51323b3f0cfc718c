"""Uploaded files kept on disk, and their cleaning (issue 27).

An uploaded mesh or robot is kept under ``~/.cache/wobjcal/uploads/<16 hex of its digest>/``
(:class:`webui.files_panel.FilesPanel`): the plan refers to it by that path, so it must outlive
the request, and an autosave of a session that uses it must find it at the next start. A folder
is *in use* while a plan refers to it: the session's plan, a step of its undo history, or an
autosave on disk (``~/.cache/wobjcal/autosave/``, set-aside ``.bak`` files included). The rest
is removed:

- an upload that is refused, cancelled or replaced before it is used: at once;
- at the start of a server: every folder no plan uses, unless it was written within
  :data:`RECENT_S` (another server may be using it right now);
- at the end of a server: the folders it wrote that its last plan does not use;
- beyond :data:`calib.limits.MAX_UPLOADS_KEPT_BYTES` in total: the oldest unused first; when
  the folders in use alone exceed it a new upload is refused, naming the sizes.
"""

from __future__ import annotations

import contextlib
import logging
import re
import shutil
import time
from collections.abc import Iterable
from pathlib import Path

from calib.errors import InputError
from calib.limits import MAX_UPLOADS_KEPT_BYTES, MiB
from calib.plan.file import Plan

logger = logging.getLogger(__name__)

#: A folder written within this many seconds is left alone at start (another server's), s.
RECENT_S = 3600.0
_FOLDER = re.compile(r"^[0-9a-f]{16}$")

__all__ = [
    "RECENT_S",
    "check_room",
    "folder_bytes",
    "plan_refs",
    "prune",
    "referenced",
    "remove_unused",
    "upload_folders",
]


def plan_refs(plan: Plan) -> list[str]:
    """Every file reference of ``plan`` (work object, robot, tool, fixture meshes)."""
    refs = [plan.work_object.mesh, plan.cell.robot.urdf, plan.cell.tool.name]
    return refs + [f.mesh for f in plan.cell.fixtures if f.mesh is not None]


def upload_folders(upload_dir: Path) -> list[Path]:
    """The upload folders (``<16 hex>``) under ``upload_dir``, oldest first."""
    if not upload_dir.is_dir():
        return []
    found = []
    for p in upload_dir.iterdir():
        with contextlib.suppress(OSError):
            if _FOLDER.match(p.name) and p.is_dir() and not p.is_symlink():
                found.append((p.stat().st_mtime, p))
    return [p for _, p in sorted(found)]


def folder_bytes(folder: Path) -> int:
    """Bytes of the files under ``folder``."""
    total = 0
    for p in folder.rglob("*"):
        with contextlib.suppress(OSError):
            if p.is_file() and not p.is_symlink():
                total += p.stat().st_size
    return total


def referenced(texts: Iterable[str], folders: Iterable[Path]) -> set[str]:
    """Names of the ``folders`` some text of ``texts`` mentions (a plan's references, an
    autosave's JSON)."""
    names = {f.name for f in folders}
    used: set[str] = set()
    for text in texts:
        used.update(n for n in names if n in text)
    return used


def _autosave_texts(autosave_dir: Path | None) -> list[str]:
    if autosave_dir is None or not autosave_dir.is_dir():
        return []
    texts = []
    for p in autosave_dir.iterdir():
        if p.suffix in (".json", ".bak") and p.is_file():
            with contextlib.suppress(OSError):
                texts.append(p.read_text(encoding="utf-8", errors="replace"))
    return texts


def _remove(folder: Path) -> bool:
    try:
        shutil.rmtree(folder)
    except OSError as exc:
        logger.warning("upload folder %s not removed: %s", folder, exc)
        return False
    logger.info("removed the unused upload folder %s", folder)
    return True


def prune(
    upload_dir: Path,
    in_use: Iterable[str],
    autosave_dir: Path | None,
    *,
    recent_s: float = RECENT_S,
    only: Iterable[Path] | None = None,
) -> list[Path]:
    """Remove the upload folders no plan uses; return those removed.

    Args:
        upload_dir: the uploads folder.
        in_use: file references of the plans in use (see :func:`plan_refs`).
        autosave_dir: the autosave folder whose files (``.json``, ``.bak``) keep their
            uploads too (``None``: none).
        recent_s: leave folders written within this many seconds.
        only: consider only these folders (default: all).
    """
    folders = upload_folders(upload_dir)
    if only is not None:
        chosen = {Path(p).name for p in only}
        folders = [f for f in folders if f.name in chosen]
    if not folders:
        return []
    used = referenced([*in_use, *_autosave_texts(autosave_dir)], folders)
    now = time.time()
    removed = []
    for f in folders:
        try:
            young = now - f.stat().st_mtime < recent_s
        except OSError:
            continue
        if f.name not in used and not young and _remove(f):
            removed.append(f)
    return removed


def remove_unused(
    upload_dir: Path, folders: Iterable[Path], in_use: Iterable[str], autosave_dir: Path | None
) -> list[Path]:
    """Remove ``folders`` (an upload refused, cancelled or replaced) unless a plan uses them."""
    return prune(upload_dir, in_use, autosave_dir, recent_s=0.0, only=folders)


def check_room(
    upload_dir: Path,
    incoming: int,
    in_use: Iterable[str],
    autosave_dir: Path | None,
    limit: int = MAX_UPLOADS_KEPT_BYTES,
) -> None:
    """Make room for ``incoming`` bytes of upload under ``limit``: remove the oldest folders
    no plan uses, then refuse when the folders in use leave too little.

    Raises:
        InputError: the uploads in use and this one exceed ``limit`` (the message names them).
    """
    folders = upload_folders(upload_dir)
    sizes = {f.name: folder_bytes(f) for f in folders}
    total = sum(sizes.values())
    if total + incoming <= limit:
        return
    used = referenced([*in_use, *_autosave_texts(autosave_dir)], folders)
    for f in folders:  # oldest first
        if total + incoming <= limit:
            return
        if f.name not in used and _remove(f):
            total -= sizes[f.name]
    if total + incoming > limit:
        raise InputError(
            f"the uploads kept in {upload_dir} ({total / MiB:.0f} MiB, all used by this "
            f"session's plans or autosaves) and this one ({incoming / MiB:.1f} MiB) exceed the "
            f"{limit / MiB:.0f} MiB kept for uploads; remove old autosaves "
            "(~/.cache/wobjcal/autosave) or start with --fresh"
        )
