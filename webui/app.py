"""The wobjcal web UI: a viser server over one plan, its cell and its checks.

:func:`webui.server.run` starts the server (127.0.0.1:8080 by default), loads a plan or the
built-in demo and returns the :class:`WobjcalApp`. The app is thin: browser events become edits
of the session plan (:mod:`webui.state`), and every edit is checked in the cell on the one
worker thread (:mod:`webui.worker`) and drawn back (:mod:`webui.scene`).
"""

from __future__ import annotations

import logging
import threading
from pathlib import Path
from typing import Any

import numpy as np
import viser
from numpy.typing import ArrayLike

from calib.errors import InputError
from calib.frames import transform_points
from calib.plan.file import CellSpec, Plan, WorkObjectSpec
from calib.probing import ProbePoint
from planner.check import PointCheck
from webui import clients, plan_doc
from webui.autosave import AutosaveLock
from webui.backend import CellSession, CellView
from webui.busy import BusyIndicator
from webui.heatmap import HeatMap
from webui.plan_adapter import autosave_bytes, plan_point, with_source
from webui.plan_doc import UiPlan
from webui.robot_view import RobotView, robot_view_or_reason
from webui.role_check import RoleFlags, role_flags
from webui.scene import MARKER_RADIUS_M, PlanScene
from webui.state import DEFAULT_AUTOSAVE, Change, SessionState
from webui.surface import SurfacePicker, marker_on_ray
from webui.tabs import AppTabs
from webui.upload_guard import guard_uploads
from webui.worker import CellWorker

logger = logging.getLogger(__name__)

#: A move that lands within this of where the point is changes nothing, m.
MOVE_TOL_M = 1e-6


class WobjcalApp:
    """One UI session: the server, the plan being edited, the cell worker and the panels.

    Args:
        server: the viser server to draw on.
        plan: the initial plan (editable form).
        plan_dir: folder relative file references of the plan are resolved against.
        autosave_path: where the session plan autosaves (``None``: no autosave).
    """

    def __init__(
        self,
        server: viser.ViserServer,
        plan: UiPlan,
        plan_dir: Path,
        autosave_path: Path | None = DEFAULT_AUTOSAVE,
    ) -> None:
        from webui import (
            calibrate_panel,
            cell_panel,
            files_panel,
            frame_panel,
            layout_panel,
            points_panel,
            teach_panel,
            validate_panel,
        )

        self.server = server
        self.plan_dir = Path(plan_dir)
        self.busy = BusyIndicator(server.gui)
        clients.add_view_bar(server, lambda: self.view, self.notify)
        self.tabs = AppTabs(server.gui)
        self.scene = PlanScene(server)
        self.state: SessionState[UiPlan] = SessionState(
            plan, serialize=autosave_bytes, autosave_path=autosave_path
        )
        self.worker: CellWorker[CellSession | None] = CellWorker(None)
        self.view: CellView | None = None
        self.picker: SurfacePicker | None = None
        self.robot: RobotView | None = None
        self.selected: str | None = None
        self._checks: dict[str, tuple[ProbePoint, PointCheck]] = {}
        self._lock = threading.RLock()
        self._cell_key: tuple[CellSpec, WorkObjectSpec] | None = None
        self.flags = RoleFlags()
        #: Handlers of scene clicks by mode (``"place"``: click-to-place); a panel may set
        #: :attr:`click_mode` to its own (e.g. picking the points of a 3-point frame).
        self.click_handlers: dict[str, Any] = {"place": self._click_place}
        self.click_mode = "place"
        self.heatmap = HeatMap(self)
        self.points_panel = points_panel.PointsPanel(self)
        self.cell_panel = cell_panel.CellPanel(self)
        self.frame_panel = frame_panel.FramePanel(self)  # 3-point work-object frame
        self.teach_panel = teach_panel.TeachPanel(self)
        self.validate_panel = validate_panel.ValidatePanel(self)
        self.files_panel = files_panel.FilesPanel(self)
        self.calibrate_panel = calibrate_panel.CalibratePanel(self)
        self.layout_panel = layout_panel.LayoutPanel(self)  # issue 13: quality and suggest
        guard_uploads(server, files_panel.MAX_UPLOAD_BYTES, self._upload_refused)
        server.scene.on_click()(self._on_scene_click)
        self.state.subscribe(self._on_change)
        #: What the app said about the autosave at start (restored, set aside), for new tabs.
        self.autosave_note = ""
        self.autosave_lock: AutosaveLock | None = None
        server.on_client_connect(self._on_connect)
        if isinstance(plan.source, Plan):
            self.load_cell(plan.source, self.plan_dir)

    # ---- cell ---------------------------------------------------------------------------
    def load_cell(self, plan: Plan, plan_dir: Path) -> None:
        """Build the plan's cell on the worker and redraw the scene; raise if it fails.

        On failure the previous cell, scene and plan stay as they were.
        """
        self.heatmap.stop()
        with self.busy("loading the cell"):
            self.worker.replace_resource(lambda: CellSession(plan, plan_dir)).result(300)
        session = self.worker.call(lambda s: s)
        view = session.view
        picker = SurfacePicker(view.wobj_mesh, view.T_world_wobj)
        with self._lock:
            old_part = None if self.view is None else self.view.wobj_mesh
            self.plan_dir = Path(plan_dir)
            self.view, self.picker = view, picker
            self._cell_key = _cell_key(plan)
            self._checks.clear()
        self.scene.draw_work_object(view.wobj_mesh, view.T_world_wobj)
        self.scene.draw_fixtures(view.fixtures)
        if self.robot is not None:
            self.robot.remove()
            self.robot = None
        if view.robot_urdf is not None:
            self.robot, why = robot_view_or_reason(self.server, view)
            if why:
                logger.warning("%s", why)
                self.notify("Robot not drawn", why, error=True)
        self.teach_panel.on_cell()
        if old_part is not None and old_part is not view.wobj_mesh:  # a new part: reframe
            for client in self.server.get_clients().values():
                clients.set_default_camera(client, view)
        self.recheck(self.state.doc.ids)
        self.layout_panel.refresh()

    def replace_source(self, plan: Plan, label: str) -> None:
        """Make ``plan`` (another cell: part, robot, fixtures or their poses) the session's, in
        one undoable step; its cell is built first, and when that fails nothing changes."""
        self.load_cell(plan, self.plan_dir)
        self.state.update(lambda d: with_source(d, plan), label)

    # ---- checks ---------------------------------------------------------------------------
    def check_of(self, point_id: str) -> PointCheck | None:
        """The latest check of a point, or ``None`` while it is being computed."""
        with self._lock:
            entry = self._checks.get(point_id)
        return None if entry is None else entry[1]

    def checks(self) -> dict[str, PointCheck]:
        """The latest check of every point that has one."""
        with self._lock:
            return {pid: c for pid, (_, c) in self._checks.items()}

    def recheck(self, point_ids: tuple[str, ...] | list[str]) -> list[PointCheck]:
        """Check the given points in the cell (on the worker), store and draw the results."""
        doc = self.state.doc
        points = [doc.get(pid) for pid in point_ids if pid in doc.ids]
        if not points:
            return []
        edited = [plan_point(p) for p in points]
        with self.busy(f"checking {', '.join(p.id for p in points[:6])}"):
            results = self.worker.call(lambda s: [] if s is None else s.check_points(edited))
        current = self.state.doc
        with self._lock:
            for point, check in zip(points, results, strict=False):
                still = point.id in current.ids and current.get(point.id).probe == point.probe
                if still:  # drop results of a point that moved on meanwhile
                    self._checks[point.id] = (point.probe, check)
        self._redraw([p.id for p in points])
        return results

    def _redraw(self, point_ids: list[str] | None = None) -> None:
        """Redraw the given points (all when ``None``), drop removed ones, refresh the panel."""
        doc = self.state.doc
        before, self.flags = self.flags, role_flags(doc)
        if point_ids is not None:  # a point whose flag came or went is redrawn too
            moved = set(before.by_point) ^ set(self.flags.by_point)
            point_ids = [*point_ids, *(i for i in moved if i not in point_ids and i in doc.ids)]
        # the table first, on its own: the page applies a batch of GUI messages at once, but a
        # batch with scene messages only in its next frame (0.2-1 s with software WebGL)
        self.points_panel.refresh()
        self.server.flush()
        self.scene.draw_points(
            doc, self.checks(), self.selected, only=point_ids, flags=self.flags.by_point
        )
        self.server.flush()

    def _on_change(self, change: Change[UiPlan]) -> None:
        source = change.doc.source
        if isinstance(source, Plan) and _cell_key(source) != self._cell_key:
            try:  # e.g. undo of an upload: go back to the earlier cell
                self.load_cell(source, self.plan_dir)
            except Exception as exc:
                self.notify("Cell not loaded", str(exc), error=True)
            self._redraw()
            return
        before = {p.id: p for p in change.previous.points}
        changed = [p.id for p in change.doc.points if before.get(p.id) != p]
        with self._lock:
            for pid in [*changed, *(set(before) - set(change.doc.ids))]:
                self._checks.pop(pid, None)
        if len(changed) > 2 or not changed:  # grey "pending" markers for bulk changes
            self._redraw(changed)
        self.recheck(changed)  # draws the changed points (one round trip per click)
        if self.selected is not None and self.selected not in change.doc.ids:
            self.select(None)
        elif self.selected in changed:
            self._show_selected()

    def show_reachability(self, n_samples: int = 1000) -> None:
        """Start the reachability heat map (computed in chunks on the cell worker)."""
        self.heatmap.stop()
        self.heatmap.start(n_samples)

    # ---- editing ---------------------------------------------------------------------------
    def place_at_ray(
        self, origin_world: ArrayLike, direction_world: ArrayLike, point_id: str | None = None
    ) -> PointCheck | None:
        """Put a point where a ray (world frame) hits the work object; return its check.

        This is what a click on the work object does.

        Raises:
            InputError: no work object is loaded or the ray misses it.
        """
        picker = self.picker
        if picker is None:
            raise InputError("no work object is loaded")
        hit = picker.pick(origin_world, direction_world)
        if hit is None:
            raise InputError("the click missed the work object")
        pid = point_id or self.points_panel.target_id()

        def edit(doc: UiPlan) -> UiPlan:
            return plan_doc.place_point(doc, pid, hit.position_wobj, hit.normal_wobj)

        self.selected = pid
        self.state.update(edit, f"place {pid}")
        return self.check_of(pid)

    def move_point_to(self, point_id: str, point_wobj: ArrayLike) -> PointCheck | None:
        """Move a point to the surface point closest to ``point_wobj`` (e.g. after a drag).

        A move that lands where the point is (within :data:`MOVE_TOL_M`, same normal) records
        nothing: no undo step, no coordinate drifted by the projection.
        """
        if self.picker is None:
            raise InputError("no work object is loaded")
        hit = self.picker.project(point_wobj)
        p = self.state.doc.get(point_id).probe
        if np.allclose(hit.position_wobj, p.position_m, rtol=0.0, atol=MOVE_TOL_M) and np.allclose(
            hit.normal_wobj, p.normal, rtol=0.0, atol=1e-9
        ):  # lands where it is: no undo step, no drifted coordinate
            return self.check_of(point_id)
        self.state.update(
            lambda d: plan_doc.place_point(d, point_id, hit.position_wobj, hit.normal_wobj),
            f"move {point_id}",
        )
        return self.check_of(point_id)

    def select(self, point_id: str | None) -> None:
        """Select a point: highlight it and show the robot at its probe pose."""
        previous, self.selected = self.selected, point_id
        ids = self.state.doc.ids
        self._redraw([i for i in (previous, point_id) if i is not None and i in ids])
        self._show_selected()

    def _show_selected(self) -> None:
        """Robot at the selected point's probe pose; its settings in the panel."""
        point_id = self.selected
        check = None if point_id is None else self.check_of(point_id)
        if self.robot is not None and check is not None and check.q is not None:
            self.robot.stop()
            self.robot.set_q(check.q)
        self.points_panel.on_select(point_id)

    # ---- clicks ----------------------------------------------------------------------------
    def _on_scene_click(self, event: Any) -> None:
        """Every click on the 3D view: handled by the current mode, or told why it did nothing."""
        handler = self.click_handlers.get(self.click_mode, self._click_place)
        try:
            handler(event)
        except InputError as exc:
            self.notify("Click not used", str(exc), client=event.client, error=True)
        except Exception as exc:  # never a traceback in the browser
            logger.exception("a click failed")
            self.notify("Click not used", f"{type(exc).__name__}: {exc}", client=event.client)

    def marker_at_ray(
        self, origin_world: ArrayLike, direction_world: ArrayLike, hit: Any = None
    ) -> str | None:
        """The point whose marker the ray passes through (see :func:`webui.surface.
        marker_on_ray`), or ``None``."""
        view = self.view
        if view is None:
            return None
        doc = self.state.doc
        positions = [transform_points(view.T_world_wobj, p.probe.position_m) for p in doc.points]
        hit_world = None if hit is None else transform_points(view.T_world_wobj, hit.position_wobj)
        k = marker_on_ray(
            positions, origin_world, direction_world, 1.6 * MARKER_RADIUS_M, hit_world
        )
        return None if k is None else doc.points[k].id

    def _click_place(self, event: Any) -> None:
        """A click in place mode: on a marker selects it, on the part places a point, anywhere
        else says that nothing was placed and why."""
        picker = self.picker
        hit = None if picker is None else picker.pick(event.ray_origin, event.ray_direction)
        marker = self.marker_at_ray(event.ray_origin, event.ray_direction, hit)
        if marker is not None:
            self.select(marker)
            return
        if picker is None:
            raise InputError("no work object is loaded: load a plan first")
        if hit is None:
            raise InputError(
                "nothing placed: the click did not hit the work object (points go on the part; "
                "to select a point, click its marker or pick it under Selected)"
            )
        self.place_at_ray(event.ray_origin, event.ray_direction)

    # ---- clients ---------------------------------------------------------------------------
    def _upload_refused(self, client_id: int, name: str, message: str) -> None:
        client = self.server.get_clients().get(client_id)
        self.notify("Upload refused", message, client=client, error=True)

    def tab(self, name: str) -> Any:
        """The control panel's tab ``name`` (a context for a panel's widgets)."""
        return self.tabs.tab(name)

    def _on_connect(self, client: viser.ClientHandle) -> None:
        if self.view is not None:
            clients.set_default_camera(client, self.view)
        if self.autosave_note:
            self.notify("Autosave", self.autosave_note, client=client, error=False)

    def notify(
        self, title: str, body: str, client: viser.ClientHandle | None = None, error: bool = True
    ) -> None:
        """Show a notification to one tab, or to every tab when ``client`` is None."""
        clients.notify(self.server, title, body, client, error)

    def stop(self) -> None:
        """Stop the server and the worker."""
        if self.robot is not None:
            self.robot.stop()
        self.validate_panel.close()
        self.layout_panel.close()
        self.server.stop()
        self.worker.close()
        if self.autosave_lock is not None:
            self.autosave_lock.release()
            self.autosave_lock = None


def _cell_key(plan: Plan) -> tuple[CellSpec, WorkObjectSpec]:
    """What decides the cell: when it changes, the cell is rebuilt."""
    return (plan.cell, plan.work_object)
