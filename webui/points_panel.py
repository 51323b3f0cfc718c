"""The "Points" panel: which point a click places, Undo and Redo (also Ctrl+Z, Ctrl+Shift+Z),
the status table (:mod:`webui.status_table`: one row per point, above the fold), each tab's
selected point (:mod:`webui.tab_selection`), drag, playback and the heat map."""

from __future__ import annotations

import contextlib
import logging
import threading
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

import numpy as np

from calib.errors import InputError
from calib.procedures import PROCEDURES
from webui import heatmap, plan_doc
from webui.panel import Panel
from webui.plan_adapter import with_procedure
from webui.plan_doc import PAPER_IDS
from webui.scene import legend_html
from webui.status_table import HINT, table_rows
from webui.tab_selection import NO_ROLE_LABEL, Selections, set_options

if TYPE_CHECKING:
    from webui.context import AppContext

logger = logging.getLogger(__name__)

NEXT = "next"


class PointsPanel(Panel):
    """GUI widgets for placing and inspecting points and editing the plan (shared by all tabs;
    each tab's selection and its settings are :mod:`webui.tab_selection`'s, guarded by this
    panel's :meth:`guard`).

    Args:
        app: the app whose plan the panel edits.
    """

    TAB = "Points"
    ACTION = "points"

    def __init__(self, app: AppContext) -> None:
        super().__init__(app)
        self._syncing = threading.local()
        gui = app.server.gui
        self._gizmo: Any = None
        self._gizmo_for: tuple[str, tuple[float, ...]] | None = None
        with app.tab(self.TAB):
            self.procedure = gui.add_dropdown(
                "Procedure",
                tuple(PROCEDURES),
                initial_value=app.state.doc.method,
                hint="the calibration procedure (roles of the points)",
            )
            self.procedure_md = gui.add_markdown("")
            self.place = gui.add_dropdown(
                "Place", (NEXT, *PAPER_IDS), initial_value=NEXT, hint="id a click places"
            )
            gui.add_markdown(
                "Click the work object to place the point on its surface; click a marker to "
                "select it."
            )
            self.undo = gui.add_button("Undo", hint="Ctrl+Z")
            self.redo = gui.add_button("Redo", hint="Ctrl+Shift+Z")
            #: one row per point: icon and status, id, role, first cause (above the fold)
            self.status_md = gui.add_markdown("")
            #: each tab's own Selected dropdown, details and settings (:mod:`webui.tab_selection`)
            self.selection_folder = gui.add_folder("Selected point")
            self.drag = gui.add_checkbox("Drag selected point", False)
            self.follow = gui.add_checkbox(
                "Robot follows selection",
                False,
                hint="ticked, the robot stands at each point you select or place; unticked it "
                'stays where it is and "Robot to selected point" moves it',
            )
            self.robot_to = gui.add_button("Robot to selected point")
            self.play = gui.add_button("Play search path")
            self.heat = gui.add_checkbox("Reachability heat map", False)
            self.heat_legend = gui.add_html(
                legend_html(heatmap.CATEGORY_MEANING, heatmap.CATEGORY_RGB), visible=False
            )
        self.procedure.on_update(self._on_procedure)
        self.undo.on_click(lambda ev: self.guard(ev, self._app.state.undo))
        self.redo.on_click(lambda ev: self.guard(ev, self._app.state.redo))
        # the keys, through viser's command palette (its hotkeys are ignored while a text or
        # number field has the focus: there Ctrl+Z undoes the typing)
        self.undo_key = gui.add_command(
            "Undo", description="undo the last edit of the plan", hotkey="Z", modifier="cmd/ctrl"
        )
        self.redo_key = gui.add_command(
            "Redo", description="redo the edit undone last", hotkey="Z", modifier="cmd/ctrl+shift"
        )
        self.undo_key.on_trigger(lambda ev: self.guard(ev, self._app.state.undo))
        self.redo_key.on_trigger(lambda ev: self.guard(ev, self._app.state.redo))
        self.drag.on_update(lambda ev: self.guard(ev, self._update_gizmo))
        self.play.on_click(
            lambda ev: self.guard(ev, self.play_search, ev.client, title="Nothing to play")
        )
        self.robot_to.on_click(lambda ev: self.guard(ev, self._app.robot_to_selected, ev.client))
        self.heat.on_update(self._on_heat)

    # ---- helpers ---------------------------------------------------------------------------
    @contextlib.contextmanager
    def _programmatic(self) -> Iterator[None]:
        self._syncing.on = True
        try:
            yield
        finally:
            self._syncing.on = False

    def _is_programmatic(self) -> bool:
        return bool(getattr(self._syncing, "on", False))

    def target_id(self) -> str:
        """The id a click places: the chosen one, or the next free id."""
        choice = str(self.place.value)
        return plan_doc.next_id(self._app.state.doc) if choice == NEXT else choice

    # ---- refresh from state ----------------------------------------------------------------
    def refresh(self) -> None:
        """Update the lists and the status table from the session plan and checks."""
        doc = self._app.state.doc
        checks = self._app.checks()
        with self._programmatic():
            extra = tuple(i for i in doc.ids if i not in PAPER_IDS)
            set_options(self.place, (NEXT, *PAPER_IDS, *extra))
            if self.procedure.value != doc.method:
                self.procedure.value = doc.method
        kind = PROCEDURES.get(doc.method)
        summary = "" if kind is None else f"*{kind.summary}*; roles: {', '.join(kind.roles)}"
        if self.procedure_md.content != summary:
            self.procedure_md.content = summary
        flags = self._app.flags
        rows = table_rows(doc, checks, flags.by_point, NO_ROLE_LABEL)
        if doc.points:
            rows += ["", HINT]
        if flags.layout:  # what `wobjcal check` and `calibrate` would refuse, said while editing
            rows += ["", f"**Layout:** {flags.layout.replace('|', '/')}"]
        if (cycle := self._app.cycle) is not None:  # `wobjcal check`'s, docs/cycle_time.md
            untimed = f" (moves into {', '.join(cycle.untimed)} not timed)" if cycle.untimed else ""
            rows += ["", f"cycle time ~ {cycle.total_s:.0f} s{untimed}"]
        content = "\n".join(rows)
        if self.status_md.content != content:
            self.status_md.content = content
        selections = self._app.selection
        if isinstance(selections, Selections):  # each tab's details of its selected point
            selections.show_details(doc)
        self._update_gizmo()

    def gizmo_geometry(self) -> tuple[float, float]:
        """``(scale, offset)`` of the drag gizmo, m: sized for the part (a third of its largest
        extent, 5-40 cm), and held ``offset`` out along the point's normal so that it is drawn
        outside the part, clear of the markers."""
        view = self._app.view
        size = 0.5 if view is None else float(np.max(view.wobj_mesh.extents))
        scale = float(np.clip(size / 3.0, 0.05, 0.4))
        return scale, 0.35 * scale

    def _gizmo_pose(self, point_id: str) -> np.ndarray:
        """Where the gizmo of ``point_id`` sits (wobj frame, m): out along its normal."""
        p = self._app.state.doc.get(point_id).probe
        _, offset = self.gizmo_geometry()
        return np.asarray(p.position_m) + offset * np.asarray(p.normal)

    def _update_gizmo(self) -> None:
        sel = self._app.selected
        doc = self._app.state.doc
        scene = self._app.server.scene
        if not self.drag.value or sel is None or sel not in doc.ids:
            if self._gizmo is not None:
                self._gizmo.remove()
                self._gizmo = None
            self._gizmo_for = None
            return
        pos = self._gizmo_pose(sel)
        if self._gizmo is None:
            scale, _ = self.gizmo_geometry()
            self._gizmo = scene.add_transform_controls(
                "/wobj/gizmo",
                scale=scale,
                line_width=4.0,
                disable_rotations=True,
                depth_test=False,  # drawn over the part, never half inside it
                position=pos,
            )
            self._gizmo.on_update(self._on_gizmo)
        elif self._gizmo_for != (sel, tuple(pos)):
            self._gizmo.position = pos
        self._gizmo_for = (sel, tuple(pos))

    # ---- callbacks -------------------------------------------------------------------------
    def _on_procedure(self, event: Any) -> None:
        if self._is_programmatic():
            return
        method = str(self.procedure.value)
        if method == self._app.state.doc.method:
            return
        self.guard(
            event,
            self._app.state.update,
            lambda d: with_procedure(d, method),
            f"procedure {method}",
        )

    def _on_gizmo(self, event: Any) -> None:
        """While dragging, preview where the point lands on the surface; at the end, move it.

        A drag that ends where it started records nothing and changes no coordinate.
        """
        scene = self._app.server.scene
        picker = self._app.picker
        # the point the gizmo is drawn on (another tab may have selected another since)
        sel = None if self._gizmo_for is None else self._gizmo_for[0]
        if sel is None or picker is None or sel not in self._app.state.doc.ids:
            return
        start = self._gizmo_pose(sel)
        handle = np.asarray(event.target.position, dtype=np.float64)
        _, offset = self.gizmo_geometry()
        normal = np.asarray(self._app.state.doc.get(sel).probe.normal)
        pos = handle - offset * normal  # the gizmo is held out along the normal
        if event.phase != "end":
            hit = picker.project(pos)
            scene.add_icosphere(
                "/wobj/drag_preview",
                radius=0.01,
                color=(60, 120, 255),
                opacity=0.6,
                position=hit.position_wobj,
            )
            return
        scene.remove_by_name("/wobj/drag_preview")
        if np.linalg.norm(handle - start) < 1e-6:  # dropped where it was picked up
            return
        self.guard(event, self._app.move_point_to, sel, pos)

    def play_search(self, client: Any = None) -> None:
        """Play the search of the point the tab of ``client`` has selected, on its robot.

        Raises:
            InputError: no robot, or no search path computed for the selected point (why).
        """
        cid = None if client is None else client.client_id
        sel = self._app.selection.of(cid)
        check = None if sel is None else self._app.check_of(sel)
        robot = self._app.robot
        if check is None or check.q_path is None or len(check.q_path) == 0 or robot is None:
            why = "select a point whose search path was computed" if robot else "no robot loaded"
            if robot and check is not None and check.path_reason:
                why = f"no sample of its search path passed: {check.path_reason}"
            raise InputError(why)
        robot.play(check.q_path, client_id=cid)

    def _on_heat(self, event: Any) -> None:
        if self._is_programmatic():
            return
        self.heat_legend.visible = bool(self.heat.value)
        if not self.heat.value:
            self._app.heatmap.stop()
            return
        self._app.notify(
            "Reachability map",
            "checking surface samples; the map grows as they finish",
            client=getattr(event, "client", None),
            error=False,
        )
        self.guard(event, self._app.show_reachability)
