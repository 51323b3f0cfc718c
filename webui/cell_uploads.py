"""Tool and fixture uploads of the cell panel, kept where the Files panel keeps uploads.

An upload is checked (:func:`webui.files_panel.check_upload`: size, empty, suffix) and written
atomically under ``~/.cache/wobjcal/uploads/<16 hex of its digest>/`` (:mod:`webui.uploads`):
room is made first, the folder is one the session wrote (removed at the end unless a plan or an
autosave uses it), and a refused upload's folder is removed at once. Errors name the user's
file, never the upload cache.
"""

from __future__ import annotations

import hashlib
import logging
from pathlib import Path
from typing import TYPE_CHECKING

from calib.errors import InputError
from webui import autosave, uploads
from webui.files_panel import UploadError, check_upload
from webui.state import atomic_write_bytes

if TYPE_CHECKING:
    from webui.context import AppContext

logger = logging.getLogger(__name__)


def named(text: str, kept: Path | None, name: str) -> str:
    """``text`` about an upload kept at ``kept``, naming the user's file ``name`` instead."""
    if kept is not None:
        text = text.replace(str(kept), name).replace(str(kept.parent), "uploads")
    return text if name in text else f"{name}: {text}"


class CellUploads:
    """The upload cache as the cell panel uses it (the Files panel's folders and rules).

    Args:
        app: the app; its ``files_panel`` owns the upload folder.
    """

    def __init__(self, app: AppContext) -> None:
        self._app = app

    def _autosave_dir(self) -> Path | None:
        """The autosave folder beside the uploads (``None`` when elsewhere, as in tests)."""
        folder = autosave.AUTOSAVE_DIR
        return folder if folder.parent == self._app.files_panel.upload_dir.parent else None

    def folder(self, content: bytes) -> Path:
        """The folder an upload of ``content`` is kept in; room is made for it first.

        Raises:
            InputError: the uploads in use leave no room (the message names the sizes).
        """
        files = self._app.files_panel
        folder = files.upload_dir / hashlib.sha256(content).hexdigest()[:16]
        if not folder.exists():
            uploads.check_room(files.upload_dir, len(content), files.in_use(), self._autosave_dir())
            files.created.add(folder)
        return folder

    def keep(
        self, name: str, content: bytes, suffixes: tuple[str, ...], what: str
    ) -> tuple[Path, str]:
        """Check and keep an uploaded file; returns where it is kept and its SHA-256 (hex).

        Raises:
            UploadError: empty, too large, or a name without one of ``suffixes``.
        """
        check_upload(name, content, suffixes, what)
        path = self.folder(content) / Path(name).name
        atomic_write_bytes(path, content)
        return path, hashlib.sha256(content).hexdigest()

    def discard(self, path: Path | None) -> None:
        """Remove the folder of a refused upload, unless a plan uses it."""
        files = self._app.files_panel
        if path is None or not path.is_relative_to(files.upload_dir):
            return
        folder = files.upload_dir / path.relative_to(files.upload_dir).parts[0]
        if folder in files.created or self._autosave_dir() is not None:
            uploads.remove_unused(files.upload_dir, [folder], files.in_use(), self._autosave_dir())

    def refused(self, exc: BaseException, kept: Path | None, name: str) -> UploadError:
        """The error to show for an upload ``name`` refused with ``exc`` (its folder removed)."""
        self.discard(kept)
        if not isinstance(exc, InputError):
            logger.error("upload %s refused", name, exc_info=exc)
        text = str(exc) if isinstance(exc, InputError) else f"{type(exc).__name__}: {exc}"
        return UploadError(named(text, kept, name))
