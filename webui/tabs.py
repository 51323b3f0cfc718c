"""The control panel's tabs: one tab per job, so no panel is cut off by another.

The app builds one :class:`AppTabs`; a panel asks for its tab by name (``app.tab("Points")``)
and builds its widgets inside it. The tabs in :data:`TAB_ORDER` exist from the start, in that
order; any other name gets a new tab at the end (e.g. a panel added later).
"""

from __future__ import annotations

import threading
from typing import Any

import viser

#: The tabs of the control panel, left to right.
TAB_ORDER: tuple[str, ...] = ("Points", "Cell", "Teach", "Validate", "Files")


class AppTabs:
    """The control panel's tab group.

    Args:
        gui: the server's GUI API (shared by all tabs of the browser).
    """

    def __init__(self, gui: viser.GuiApi) -> None:
        self._group = gui.add_tab_group()
        self._tabs: dict[str, Any] = {}
        self._lock = threading.Lock()
        for name in TAB_ORDER:
            self.tab(name)

    def tab(self, name: str) -> Any:
        """The tab called ``name`` (a context manager for its widgets), made when new."""
        with self._lock:
            if name not in self._tabs:
                self._tabs[name] = self._group.add_tab(name)
            return self._tabs[name]

    @property
    def names(self) -> tuple[str, ...]:
        """The tabs' names, left to right."""
        return tuple(self._tabs)
