"""The "Points" panel: which point a click places, the selected point's settings, status list."""

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
from webui.plan_adapter import with_procedure
from webui.plan_doc import NO_ROLE, PAPER_IDS
from webui.scene import legend_html

if TYPE_CHECKING:
    from webui.context import AppContext

logger = logging.getLogger(__name__)

NEXT = "next"
NONE = "(none)"
#: The role dropdown's entry for "no role" (:data:`webui.plan_doc.NO_ROLE`).
NO_ROLE_LABEL = "(none)"


def _set_options(dropdown: Any, options: tuple[str, ...]) -> None:
    """Send new dropdown options only when they changed (each update re-renders the panel)."""
    if tuple(dropdown.options) != options:
        dropdown.options = options


class PointsPanel:
    """GUI widgets for placing, selecting, editing and inspecting points (shared by all tabs).

    Args:
        app: the app whose plan the panel edits.
    """

    def __init__(self, app: AppContext) -> None:
        self._app = app
        self._syncing = threading.local()
        gui = app.server.gui
        self._gizmo: Any = None
        self._gizmo_for: tuple[str, tuple[float, ...]] | None = None
        with app.tab("Points"):
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
            self.selected = gui.add_dropdown("Selected", (NONE,), initial_value=NONE)
            self.role = gui.add_dropdown("Role", (*PAPER_IDS, NO_ROLE_LABEL), initial_value="A")
            self.kind = gui.add_dropdown("Search", ("approach", "edge"), initial_value="approach")
            self.start_mm = gui.add_number("Start offset (mm)", 30.0, min=0.1, step=0.5)
            self.over_mm = gui.add_number("Overtravel (mm)", 20.0, min=0.1, step=0.5)
            self.edge_dir = gui.add_vector3("Edge direction", (0.0, 0.0, 1.0), step=0.1)
            self.apply = gui.add_button("Apply settings")
            self.delete = gui.add_button("Delete point", color="red")
            self.undo = gui.add_button("Undo")
            self.redo = gui.add_button("Redo")
            self.drag = gui.add_checkbox("Drag selected point", False)
            self.play = gui.add_button("Play search path")
            self.heat = gui.add_checkbox("Reachability heat map", False)
            self.heat_legend = gui.add_html(
                legend_html(heatmap.CATEGORY_MEANING, heatmap.CATEGORY_RGB), visible=False
            )
            self.status_md = gui.add_markdown("")
        self.selected.on_update(self._on_selected)
        self.procedure.on_update(self._on_procedure)
        self.apply.on_click(self._on_apply)
        self.delete.on_click(self._on_delete)
        self.undo.on_click(lambda ev: self._guard(ev, self._app.state.undo))
        self.redo.on_click(lambda ev: self._guard(ev, self._app.state.redo))
        self.drag.on_update(lambda ev: self._guard(ev, self._update_gizmo))
        self.play.on_click(self._on_play)
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

    def _guard(self, event: Any, fn: Any, *args: Any) -> Any:
        """Run ``fn``; turn input errors into a notification for the event's client."""
        try:
            return fn(*args)
        except InputError as exc:
            self._app.notify("Not done", str(exc), client=getattr(event, "client", None))
        except Exception as exc:
            logger.exception("panel action failed")
            self._app.notify("Error", f"{type(exc).__name__}: {exc}", client=event.client)
        return None

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
            _set_options(self.place, (NEXT, *PAPER_IDS, *extra))
            _set_options(self.selected, (NONE, *doc.ids))
            _set_options(self.role, (*doc.roles, NO_ROLE_LABEL))
            if self.procedure.value != doc.method:
                self.procedure.value = doc.method
            sel = self._app.selected
            self.selected.value = sel if sel in doc.ids else NONE
        kind = PROCEDURES.get(doc.method)
        summary = "" if kind is None else f"*{kind.summary}*; roles: {', '.join(kind.roles)}"
        if self.procedure_md.content != summary:
            self.procedure_md.content = summary
        flags = self._app.flags
        rows = ["| point | role | x, y, z (mm) | status | reason |", "|---|---|---|---|---|"]
        for p in doc.points:
            c = checks.get(p.id)
            status: str = "checking..." if c is None else c.status
            reason = "" if c is None else c.reason
            if p.id in flags.by_point:  # the procedure cannot use it: said at once
                status = f"**role** / {status}"
                reason = "; ".join(r for r in (flags.by_point[p.id], reason) if r)
            xyz = ", ".join(f"{v * 1e3:.1f}" for v in p.probe.position_m)
            role = p.role or NO_ROLE_LABEL
            rows.append(f"| {p.id} | {role} | {xyz} | {status} | {reason.replace('|', '/')} |")
        if not doc.points:
            rows.append("| - | - | - | no points yet | |")
        if flags.layout:  # what `wobjcal check` and `calibrate` would refuse, said while editing
            rows += ["", f"**Layout:** {flags.layout.replace('|', '/')}"]
        content = "\n".join(rows)
        if self.status_md.content != content:
            self.status_md.content = content
        self._update_gizmo()

    def on_select(self, point_id: str | None) -> None:
        """Show the selected point's settings in the widgets."""
        doc = self._app.state.doc
        if point_id is None or point_id not in doc.ids:
            return
        p = doc.get(point_id)
        s = p.probe.search
        with self._programmatic():
            self.selected.value = point_id
            role = p.role or NO_ROLE_LABEL
            if role in self.role.options:
                self.role.value = role
            self.kind.value = s.kind
            self.start_mm.value = round(s.start_offset_m * 1000.0, 3)
            self.over_mm.value = round(s.overtravel_m * 1000.0, 3)
            if s.edge_direction is not None:
                dx, dy, dz = (round(v, 4) for v in s.edge_direction)
                self.edge_dir.value = (dx, dy, dz)

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
    def _on_selected(self, event: Any) -> None:
        if self._is_programmatic():
            return
        value = str(self.selected.value)
        self._guard(event, self._app.select, None if value == NONE else value)

    def _on_apply(self, event: Any) -> None:
        sel = self._app.selected
        if sel is None:
            self._app.notify("Not done", "select a point first", client=event.client)
            return

        def edit(doc: plan_doc.UiPlan) -> plan_doc.UiPlan:
            return plan_doc.edit_search(
                doc,
                sel,
                kind=str(self.kind.value),
                start_offset_m=float(self.start_mm.value) / 1000.0,
                overtravel_m=float(self.over_mm.value) / 1000.0,
                edge_direction=self.edge_dir.value if self.kind.value == "edge" else None,
                role=NO_ROLE if self.role.value == NO_ROLE_LABEL else str(self.role.value),
            )

        self._guard(event, self._app.state.update, edit, f"edit {sel}")

    def _on_procedure(self, event: Any) -> None:
        if self._is_programmatic():
            return
        method = str(self.procedure.value)
        if method == self._app.state.doc.method:
            return
        self._guard(
            event,
            self._app.state.update,
            lambda d: with_procedure(d, method),
            f"procedure {method}",
        )

    def _on_delete(self, event: Any) -> None:
        sel = self._app.selected
        if sel is None:
            self._app.notify("Not done", "select a point first", client=event.client)
            return
        self._guard(
            event, self._app.state.update, lambda d: plan_doc.delete_point(d, sel), f"delete {sel}"
        )

    def _on_gizmo(self, event: Any) -> None:
        """While dragging, preview where the point lands on the surface; at the end, move it.

        A drag that ends where it started records nothing and changes no coordinate.
        """
        scene = self._app.server.scene
        picker = self._app.picker
        sel = self._app.selected
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
        self._guard(event, self._app.move_point_to, sel, pos)

    def _on_play(self, event: Any) -> None:
        sel = self._app.selected
        check = None if sel is None else self._app.check_of(sel)
        robot = self._app.robot
        if check is None or check.q_path is None or robot is None:
            why = "select a point whose search path was computed" if robot else "no robot loaded"
            self._app.notify("Nothing to play", why, client=event.client)
            return
        robot.play(check.q_path)

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
        self._guard(event, self._app.show_reachability)
