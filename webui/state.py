"""Session state: the plan being edited, undo/redo and atomic autosave.

The session holds one immutable document (the plan). Every edit replaces it with a new value
through :meth:`SessionState.apply`, which keeps the previous value for undo, clears the redo
stack, writes the autosave file atomically and tells the listeners. Because the document is
immutable, undo and redo are just swaps, and every browser tab sees the same plan.

The autosave is written on a thread of its own while the listeners run (the UI checks and
draws the edit meanwhile: its row does not wait for the disk's ``fsync``, 4-250 ms on a busy
machine), and the change returns only once both are done, so the file holds the edit when
:meth:`SessionState.update`, :meth:`~SessionState.undo` or :meth:`~SessionState.redo` returns.
Writes are numbered: when two changes overlap, the file ends up holding the later document.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Generic, TypeVar

from calib.atomic_io import write_bytes_atomic
from webui.autosave import AUTOSAVE_DIR, default_autosave_path

__all__ = ["AUTOSAVE_DIR", "DEFAULT_AUTOSAVE", "Change", "SessionState", "default_autosave_path"]

logger = logging.getLogger(__name__)

D = TypeVar("D")

#: Default location of the demo session's autosave on port 8080.
DEFAULT_AUTOSAVE = AUTOSAVE_DIR / "demo-8080.json"


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (creating its folder): see :mod:`calib.atomic_io`."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_bytes_atomic(path, data)


@dataclass(frozen=True)
class Change(Generic[D]):
    """One change of the session document, as told to listeners.

    Attributes:
        doc: the document after the change.
        previous: the document before the change.
        label: what happened, e.g. ``"move A"``, ``"undo move A"``.
    """

    doc: D
    previous: D
    label: str


@dataclass
class _Saving:
    """One autosave being written: its number, its thread and how it went (``""``: well)."""

    seq: int
    thread: threading.Thread | None = None
    error: str = ""


class SessionState(Generic[D]):
    """The edited document with undo/redo and autosave; safe to use from many threads.

    Args:
        doc: the initial document.
        serialize: turns a document into the bytes written to ``autosave_path``.
        autosave_path: where to autosave after each change; ``None`` disables autosave.
        max_undo: how many steps undo remembers.
    """

    def __init__(
        self,
        doc: D,
        serialize: Callable[[D], bytes] | None = None,
        autosave_path: Path | None = None,
        max_undo: int = 200,
    ) -> None:
        self._doc = doc
        self._undo: list[tuple[D, str]] = []
        self._redo: list[tuple[D, str]] = []
        self._serialize = serialize
        self._autosave_path = None if autosave_path is None else Path(autosave_path)
        self._max_undo = max_undo
        self._lock = threading.RLock()
        self._listeners: list[Callable[[Change[D]], None]] = []
        self.last_autosave_error: str = ""
        self._write_lock = threading.Lock()
        self._save_seq = 0  # the number of the latest autosave started
        self._written_seq = 0  # the number of the autosave the file holds
        self._reported_seq = 0  # the number of the autosave last_autosave_error speaks of
        self._latest: _Saving | None = None  # the autosave of the current document

    @property
    def doc(self) -> D:
        """The current document."""
        with self._lock:
            return self._doc

    @property
    def autosave_path(self) -> Path | None:
        """Where the session autosaves, or ``None``."""
        return self._autosave_path

    def docs(self) -> list[D]:
        """The document and every one undo or redo can bring back."""
        with self._lock:
            return [self._doc, *(d for d, _ in self._undo), *(d for d, _ in self._redo)]

    @property
    def can_undo(self) -> bool:
        """True when there is a change to undo."""
        with self._lock:
            return bool(self._undo)

    @property
    def can_redo(self) -> bool:
        """True when there is an undone change to redo."""
        with self._lock:
            return bool(self._redo)

    def subscribe(self, listener: Callable[[Change[D]], None]) -> None:
        """Call ``listener(change)`` after every change, in the thread that made it, unlocked."""
        with self._lock:
            self._listeners.append(listener)

    def apply(self, new_doc: D, label: str) -> Change[D]:
        """Replace the document with ``new_doc``; remember the old one for undo."""
        return self.update(lambda _old: new_doc, label)

    def update(self, edit: Callable[[D], D], label: str) -> Change[D]:
        """Apply ``edit(current_doc)`` atomically (no other edit can slip in between).

        If ``edit`` raises, nothing changes and the exception propagates.
        """
        with self._lock:
            previous = self._doc
            new_doc = edit(previous)
            self._undo.append((previous, label))
            del self._undo[: -self._max_undo]
            self._redo.clear()
            self._doc = new_doc
            change = Change(new_doc, previous, label)
            saving = self._start_autosave()
        self._notify_saving(change, saving)
        return change

    def undo(self) -> Change[D] | None:
        """Go back one change; ``None`` when there is nothing to undo."""
        with self._lock:
            if not self._undo:
                return None
            doc, label = self._undo.pop()
            self._redo.append((self._doc, label))
            change = Change(doc, self._doc, f"undo {label}")
            self._doc = doc
            saving = self._start_autosave()
        self._notify_saving(change, saving)
        return change

    def redo(self) -> Change[D] | None:
        """Re-apply the last undone change; ``None`` when there is nothing to redo."""
        with self._lock:
            if not self._redo:
                return None
            doc, label = self._redo.pop()
            self._undo.append((self._doc, label))
            change = Change(doc, self._doc, f"redo {label}")
            self._doc = doc
            saving = self._start_autosave()
        self._notify_saving(change, saving)
        return change

    def autosave(self) -> bool:
        """Write the current document to the autosave file; return True on success."""
        with self._lock:
            saving = self._start_autosave()
        return self._finish_autosave(saving)

    def _start_autosave(self) -> _Saving | None:
        """Serialize the current document (call with the lock held, so the writes are
        numbered in the order of the changes) and start writing it; ``None``: no autosave."""
        if self._autosave_path is None or self._serialize is None:
            return None
        self._save_seq += 1
        saving = _Saving(self._save_seq)
        self._latest = saving
        try:
            data = self._serialize(self._doc)
        except Exception as exc:  # a failed autosave must not lose the edit
            saving.error = f"{type(exc).__name__}: {exc}"
            return saving
        saving.thread = threading.Thread(
            target=self._write, args=(saving, data), name="wobjcal-autosave", daemon=True
        )
        saving.thread.start()
        return saving

    def _write(self, saving: _Saving, data: bytes) -> None:
        """Write autosave number ``saving.seq`` unless a later one is on disk already."""
        path = self._autosave_path
        if path is None:  # never: _start_autosave starts no write without a path
            return
        with self._write_lock:
            if saving.seq < self._written_seq:
                return  # a later document is written: this one must not replace it
            try:
                atomic_write_bytes(path, data)
            except Exception as exc:
                saving.error = f"{type(exc).__name__}: {exc}"
                return
            self._written_seq = saving.seq

    def wait_saved(self, timeout: float | None = None) -> bool:
        """Wait until the autosave file holds the current document (or its write failed).

        :attr:`doc` shows an edit as soon as it is made, while its autosave is still being
        written; a reader of the file waits here first. Returns True when the current document
        is on disk, False when its write failed, there is no autosave, or ``timeout`` (s) ran out.
        """
        with self._lock:
            saving = self._latest
        if saving is None:
            return False
        if saving.thread is not None:
            saving.thread.join(timeout)
            if saving.thread.is_alive():
                return False
        return not saving.error

    def _finish_autosave(self, saving: _Saving | None) -> bool:
        """Wait for the write; say how it went (:attr:`last_autosave_error`, which speaks
        of the newest write that has finished, never of an older one finishing later)."""
        if saving is None:
            return False
        if saving.thread is not None:
            saving.thread.join()
        if saving.error:  # a failed autosave must not lose the edit
            logger.warning("autosave to %s failed: %s", self._autosave_path, saving.error)
        with self._write_lock:
            if saving.seq >= self._reported_seq:
                self._reported_seq = saving.seq
                self.last_autosave_error = saving.error
        return not saving.error

    def _notify_saving(self, change: Change[D], saving: _Saving | None) -> None:
        """Tell the listeners while the autosave is written; return once both are done."""
        try:
            self._notify(change)
        finally:
            self._finish_autosave(saving)

    def _notify(self, change: Change[D]) -> None:
        # outside the lock: a listener may wait for the cell worker, which may read the doc
        for listener in list(self._listeners):
            try:
                listener(change)
            except Exception:
                logger.exception("session listener failed after %r", change.label)
