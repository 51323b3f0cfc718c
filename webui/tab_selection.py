"""Each browser tab's own selection: the selected point, its settings widgets and its highlight.

The plan (points, edits, statuses, undo) is shared by every tab; what depends on the
selection is per tab: the **Selected** dropdown, the selected point's details (every cause of
its status, :func:`webui.status_table.details_markdown`) and its settings (Role, Search, Start
offset, Overtravel, Edge direction, Apply settings, Delete point) are widgets of the tab's own
GUI (``client.gui``) inside the Points tab's shared "Selected point" folder, and the highlight
(a blue sphere over the marker) is a node of the tab's own scene (``client.scene``).
:class:`Selections` keeps them, follows every edit of the plan (a point deleted in another tab
clears this tab's selection; a point moved there moves the highlight), and answers which point
a tab has selected. The robot's pose per tab is :class:`webui.tab_robots.TabRobots`'s.
"""

from __future__ import annotations

import logging
import threading
from typing import TYPE_CHECKING, Any

import numpy as np
import viser

from calib.errors import InputError
from calib.frames import transform_points
from webui import plan_doc
from webui.plan_doc import NO_ROLE, UiPlan
from webui.scene import MARKER_RADIUS_M, SELECTED_RGB
from webui.status_table import details_markdown

if TYPE_CHECKING:
    from webui.context import AppContext
    from webui.panel import Guard

logger = logging.getLogger(__name__)

NONE = "(none)"
#: The role dropdown's entry for "no role" (:data:`webui.plan_doc.NO_ROLE`).
NO_ROLE_LABEL = "(none)"
#: Name of a tab's highlight node in its own scene.
HIGHLIGHT = "/selection"
#: A typed position farther than this from the part's surface is said when it is moved on, m.
SNAP_NOTE_M = 0.0005


def set_options(widget: Any, options: tuple[str, ...]) -> None:
    """Send new dropdown options only when they changed (each update re-renders the panel)."""
    if tuple(widget.options) != options:
        widget.options = options


class TabSelection:
    """One tab's selection widgets (in ``folder``, a shared container) and highlight.

    Args:
        app: the app whose plan the tab edits.
        client: the tab.
        folder: the shared GUI container the tab's widgets go in.
        guard: the Points panel's :meth:`webui.panel.Panel.guard` (a refusal told to the tab
            that acted: this one, whose widgets these are).
    """

    def __init__(
        self, app: AppContext, client: viser.ClientHandle, folder: Any, guard: Guard
    ) -> None:
        self._app = app
        self.client = client
        self._guard = guard
        #: The tab's selected point, or ``None``.
        self.point_id: str | None = None
        self._syncing = False
        #: Where this tab's highlight is drawn (world, m), or ``None``.
        self._shown: tuple[float, ...] | None = None
        doc = app.state.doc
        gui = client.gui
        with folder:
            self.selected = gui.add_dropdown("Selected", (NONE, *doc.ids), initial_value=NONE)
            #: every cause of the selected point's status, its position and search
            self.details = gui.add_markdown("")
            self.position_mm = gui.add_vector3(
                "Position (mm)",
                (0.0, 0.0, 0.0),
                step=0.1,
                hint="wobj frame; Apply settings puts the point at the nearest spot of the "
                "part's surface, with that facet's normal",
            )
            self.normal = gui.add_vector3(
                "Normal",
                (0.0, 0.0, 1.0),
                step=0.01,
                hint="wobj frame, outward; the search runs against it (made unit length; "
                "applied with Apply settings)",
            )
            self.role = gui.add_dropdown("Role", (*doc.roles, NO_ROLE_LABEL))
            self.kind = gui.add_dropdown("Search", ("approach", "edge"), initial_value="approach")
            self.start_mm = gui.add_number("Start offset (mm)", 30.0, min=0.1, step=0.5)
            self.over_mm = gui.add_number("Overtravel (mm)", 20.0, min=0.1, step=0.5)
            self.edge_dir = gui.add_vector3("Edge direction", (0.0, 0.0, 1.0), step=0.1)
            self.apply = gui.add_button("Apply settings")
            self.delete = gui.add_button("Delete point", color="red")
        self.selected.on_update(self._on_selected)
        self.apply.on_click(lambda ev: guard(ev, self.apply_settings))
        self.delete.on_click(lambda ev: guard(ev, self.delete_selected))
        #: the widgets that describe the selected point (hidden while none is selected)
        self.settings = (
            self.details, self.position_mm, self.normal, self.role, self.kind, self.start_mm,
            self.over_mm, self.edge_dir, self.apply, self.delete,
        )  # fmt: skip
        self._show_fields(False)

    def _show_fields(self, visible: bool) -> None:
        for widget in self.settings:
            if widget.visible != visible:
                widget.visible = visible

    def _on_selected(self, event: Any) -> None:
        if self._syncing:
            return
        value = str(self.selected.value)
        self._guard(event, self._app.select, None if value == NONE else value, self.client)

    # ---- from the plan ---------------------------------------------------------------------
    def show(self, doc: UiPlan, settings: bool) -> None:
        """Update the lists, the dropdown's value and (``settings``) the point's settings."""
        self._syncing = True
        try:
            set_options(self.selected, (NONE, *doc.ids))
            set_options(self.role, (*doc.roles, NO_ROLE_LABEL))
            value = self.point_id if self.point_id in doc.ids else NONE
            if self.selected.value != value:
                self.selected.value = value
            if settings and self.point_id in doc.ids:
                self._show_settings(doc.get(self.point_id))
            self._show_fields(self.point_id in doc.ids)
        finally:
            self._syncing = False
        self.show_details(doc)
        self._highlight(doc)

    def show_details(self, doc: UiPlan) -> None:
        """Show every cause of the selected point's status (its latest check and role flag),
        its position and its search (:func:`webui.status_table.details_markdown`)."""
        pid = self.point_id
        content = ""
        if pid is not None and pid in doc.ids:
            flag = self._app.flags.by_point.get(pid, "")
            content = details_markdown(doc.get(pid), self._app.check_of(pid), flag)
        if self.details.content != content:
            self.details.content = content

    def _show_settings(self, point: plan_doc.UiPoint) -> None:
        s = point.probe.search
        role = point.role or NO_ROLE_LABEL
        if role in self.role.options:
            self.role.value = role
        self.kind.value = s.kind
        x, y, z = (round(v * 1000.0, 3) + 0.0 for v in point.probe.position_m)
        self.position_mm.value = (x, y, z)
        nx, ny, nz = (round(v, 6) + 0.0 for v in point.probe.normal)
        self.normal.value = (nx, ny, nz)
        self.start_mm.value = round(s.start_offset_m * 1000.0, 3)
        self.over_mm.value = round(s.overtravel_m * 1000.0, 3)
        if s.edge_direction is not None:
            dx, dy, dz = (round(v, 4) for v in s.edge_direction)
            self.edge_dir.value = (dx, dy, dz)

    def _highlight(self, doc: UiPlan) -> None:
        """A blue sphere over the selected marker in this tab's scene only (world frame)."""
        view = self._app.view
        if self.point_id is None or self.point_id not in doc.ids or view is None:
            if self._shown is not None:
                self.client.scene.remove_by_name(HIGHLIGHT)
                self._shown = None
            return
        p = transform_points(view.T_world_wobj, doc.get(self.point_id).probe.position_m)
        at = tuple(float(v) for v in np.asarray(p, dtype=np.float64).reshape(3))
        if at == self._shown:  # already there: nothing sent
            return
        self.client.scene.add_icosphere(
            HIGHLIGHT,
            radius=1.5 * MARKER_RADIUS_M,
            color=SELECTED_RGB,
            subdivisions=2,
            position=np.asarray(at),
        )
        self._shown = at

    # ---- actions ---------------------------------------------------------------------------
    def apply_settings(self) -> None:
        """Apply the settings widgets to the tab's selected point, as one undoable step: its
        Position and Normal (:meth:`typed_pose`) when they were changed, then its role and
        search."""
        sel = self.point_id
        doc = self._app.state.doc
        if sel is None or sel not in doc.ids:
            raise InputError("select a point first")
        pose = self.typed_pose(doc.get(sel).probe)

        def edit(doc: UiPlan) -> UiPlan:
            if pose is not None:
                doc = plan_doc.place_point(doc, sel, pose[0], pose[1])
            return plan_doc.edit_search(
                doc,
                sel,
                kind=str(self.kind.value),
                start_offset_m=float(self.start_mm.value) / 1000.0,
                overtravel_m=float(self.over_mm.value) / 1000.0,
                edge_direction=self.edge_dir.value if self.kind.value == "edge" else None,
                role=NO_ROLE if self.role.value == NO_ROLE_LABEL else str(self.role.value),
            )

        self._app.state.update(edit, f"edit {sel}")

    def typed_pose(self, probe: Any) -> tuple[np.ndarray, np.ndarray] | None:
        """The position and normal (wobj, m) the Position and Normal fields give ``probe``, or
        ``None`` when they were not changed: a new position goes to the nearest spot of the
        part's surface with that facet's normal (said when that is more than
        :data:`SNAP_NOTE_M` from the typed one); a new normal alone turns the search, the point
        staying where it is.

        Raises:
            InputError: not numbers, no part loaded, or a zero normal.
        """
        typed = np.asarray(self.position_mm.value, dtype=np.float64) / 1000.0
        n = np.asarray(self.normal.value, dtype=np.float64)
        if not np.all(np.isfinite(typed)) or not np.all(np.isfinite(n)):
            raise InputError("position and normal: numbers, please")
        length = float(np.linalg.norm(n))
        moved = not np.allclose(typed, probe.position_m, atol=5e-7)
        turned = not np.allclose(n / max(length, 1e-300), probe.normal, atol=5e-7)
        if moved:
            picker = self._app.picker
            if picker is None:
                raise InputError("no work object is loaded")
            hit = picker.project(typed)
            if hit.distance_m > SNAP_NOTE_M:
                self._app.notify(
                    f"{probe.id} put on the part",
                    f"the typed position is {hit.distance_m * 1000:.2f} mm off the surface: "
                    f"{probe.id} went to the nearest spot of the part, with its facet's normal",
                    client=self.client,
                    error=False,
                )
            return hit.position_wobj, hit.normal_wobj
        if turned:
            if length < 1e-9:
                raise InputError("normal: a non-zero vector")
            return np.asarray(probe.position_m, dtype=np.float64), n / length
        return None

    def delete_selected(self) -> None:
        """Delete the tab's selected point (one undoable step)."""
        sel = self.point_id
        if sel is None:
            raise InputError("select a point first")
        self._app.state.update(lambda d: plan_doc.delete_point(d, sel), f"delete {sel}")


class Selections:
    """Every tab's selection, and the selection scripts make (``client_id=None``: every tab).

    Args:
        app: the app.
        folder: the shared GUI container the tabs' selection widgets go in.
        guard: the Points panel's :meth:`webui.panel.Panel.guard`, which runs the tabs' actions.
    """

    def __init__(self, app: AppContext, folder: Any, guard: Guard) -> None:
        self._app = app
        self._folder = folder
        self._guard = guard
        self._lock = threading.RLock()
        self._build_lock = threading.Lock()
        self._tabs: dict[int, TabSelection] = {}
        #: The latest point selected anywhere (a tab or a script), or ``None``.
        self.latest: str | None = None

    def add_client(self, client: viser.ClientHandle) -> TabSelection:
        """Build a newly connected tab's widgets (nothing selected)."""
        # viser runs connect handlers on a thread pool, and a GUI container may be entered by
        # one thread at a time: tabs that connect together take turns
        with self._build_lock:
            tab = TabSelection(self._app, client, self._folder, self._guard)
        with self._lock:
            self._tabs[client.client_id] = tab
        return tab

    def remove_client(self, client_id: int) -> None:
        """Forget a tab that disconnected (its widgets and scene went with it)."""
        with self._lock:
            self._tabs.pop(client_id, None)

    def tab(self, client_id: int) -> TabSelection | None:
        """The selection of tab ``client_id``, or ``None`` when it is not connected."""
        with self._lock:
            return self._tabs.get(client_id)

    def of(self, client_id: int | None) -> str | None:
        """The point tab ``client_id`` has selected (``None``: the latest anywhere)."""
        with self._lock:
            if client_id is None:
                return self.latest
            tab = self._tabs.get(client_id)
            return None if tab is None else tab.point_id

    def by_tab(self) -> dict[int, str | None]:
        """``{client id: selected point or None}`` of every connected tab."""
        with self._lock:
            return {cid: t.point_id for cid, t in self._tabs.items()}

    def select(self, point_id: str | None, client_id: int | None = None) -> None:
        """Select ``point_id`` (or none) in one tab, or in every tab (``client_id=None``)."""
        doc = self._app.state.doc
        if point_id is not None and point_id not in doc.ids:
            raise InputError(f"no point {point_id!r}; points: {', '.join(doc.ids) or 'none'}")
        with self._lock:
            self.latest = point_id
            if client_id is None:
                tabs = list(self._tabs.values())
            else:
                one = self._tabs.get(client_id)
                tabs = [] if one is None else [one]
            for tab in tabs:
                tab.point_id = point_id
        for tab in tabs:
            tab.show(doc, settings=True)

    def show_details(self, doc: UiPlan) -> None:
        """Refresh every tab's details of its selected point (after new checks)."""
        with self._lock:
            tabs = list(self._tabs.values())
        for tab in tabs:
            tab.show_details(doc)

    def follow(self, doc: UiPlan, changed: set[str]) -> list[int]:
        """Follow an edit of the plan in every tab: a deleted point is no longer selected, a
        changed one shows its new settings and place. Returns the tabs whose selected point
        changed (their robot moves to its new pose)."""
        with self._lock:
            if self.latest is not None and self.latest not in doc.ids:
                self.latest = None
            tabs = list(self._tabs.items())
            for _, tab in tabs:
                if tab.point_id is not None and tab.point_id not in doc.ids:
                    tab.point_id = None
        moved = []
        for cid, tab in tabs:
            hit = tab.point_id in changed
            tab.show(doc, settings=hit)
            if hit:
                moved.append(cid)
        return moved
