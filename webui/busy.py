"""The busy indicator: one line at the top of the control panel while the cell loads or checks.

Every tab sees it. Jobs nest and overlap (a check from one browser tab while another uploads a
part): the line shows the newest job still running and disappears when the last one ends.
"""

from __future__ import annotations

import contextlib
import itertools
import threading
from collections.abc import Iterator

import viser


class BusyIndicator:
    """A line of Markdown that says what the server is doing, hidden when idle.

    Args:
        gui: the server's GUI API.
    """

    def __init__(self, gui: viser.GuiApi) -> None:
        self._md = gui.add_markdown("", visible=False, order=-1000.0)
        self._jobs: dict[int, str] = {}
        self._ids = itertools.count()
        self._lock = threading.Lock()
        #: How many jobs ran since start (tests use it to know a job was shown).
        self.shown = 0

    @contextlib.contextmanager
    def __call__(self, what: str) -> Iterator[None]:
        """Show ``what`` (e.g. ``"checking B"``) while the ``with`` block runs."""
        with self._lock:
            key = next(self._ids)
            self._jobs[key] = what
            self.shown += 1
            self._show()
        try:
            yield
        finally:
            with self._lock:
                self._jobs.pop(key, None)
                self._show()

    @property
    def text(self) -> str:
        """What the line says now (``""`` when idle)."""
        return self._md.content if self._md.visible else ""

    def _show(self) -> None:
        if self._jobs:
            newest = self._jobs[max(self._jobs)]
            more = f" (+{len(self._jobs) - 1} more)" if len(self._jobs) > 1 else ""
            self._md.content = f"**Busy:** {newest}...{more}"
            self._md.visible = True
        else:
            self._md.visible = False
