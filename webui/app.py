"""The wobjcal web UI: a viser server over one plan, its cell and its checks.

:func:`webui.server.run` starts the server (127.0.0.1:8080 by default), loads a plan or the
built-in demo and returns the :class:`WobjcalApp`. The app is thin: browser events become edits
of the session plan (:mod:`webui.state`), and every edit is checked in the cell on the one
worker thread (:mod:`webui.worker`) and drawn back (:mod:`webui.scene`).
"""

from __future__ import annotations

import logging
import threading
from concurrent.futures import Future
from pathlib import Path
from typing import Any

import msgspec
import numpy as np
import viser
from numpy.typing import ArrayLike

from calib.errors import InputError
from calib.plan.file import CellSpec, Plan, WorkObjectSpec
from calib.probing import ProbePoint
from planner.check.job import PointCheck
from planner.program.cycle_time import CycleTime
from webui import click_place, clients, plan_doc
from webui.autosave import AutosaveLock
from webui.backend import CellSession, CellView
from webui.busy import BusyIndicator
from webui.doc_memo import DocMemo
from webui.guard import guarded
from webui.gui_first import flush_gui_first
from webui.heatmap import N_SAMPLES as HEAT_MAP_SAMPLES
from webui.heatmap import HeatMap
from webui.plan_adapter import autosave_bytes, plan_as_edited, plan_point, with_source
from webui.plan_doc import UiPlan
from webui.role_check import RoleFlags, role_flags
from webui.scene import PlanScene
from webui.search_room import new_point_overtravel_cap_m
from webui.state import DEFAULT_AUTOSAVE, Change, SessionState
from webui.surface import SurfacePicker
from webui.tab_robots import TabRobots, tab_robots_or_reason
from webui.tab_selection import Selections
from webui.tabs import AppTabs
from webui.upload_guard import guard_uploads
from webui.worker import CellWorker, ResourceTimeout

logger = logging.getLogger(__name__)

#: A move that lands within this of where the point is changes nothing, m.
MOVE_TOL_M = 1e-6
#: How long a cell may take to load before the UI gives it up (the cell shown stays), s.
CELL_LOAD_S = 300.0


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
        clients.add_view_bar(server, lambda: self.view, self.notify, self.set_robot_display)
        #: how the robot is drawn (shown, ghost, hidden); kept when the cell is rebuilt
        self.robot_display = "shown"
        self.tabs = AppTabs(server.gui)
        self.scene = PlanScene(server)
        self.state: SessionState[UiPlan] = SessionState(
            plan, serialize=autosave_bytes, autosave_path=autosave_path
        )
        self.worker: CellWorker[CellSession | None] = CellWorker(None)
        self.view: CellView | None = None
        self.picker: SurfacePicker | None = None
        self.robot: TabRobots | None = None  # one drawing per tab, each at its own pose
        self._checks: dict[str, tuple[ProbePoint, PointCheck]] = {}
        #: the moves between the points (:meth:`update_via_moves`): per point, its check as
        #: :attr:`_checks` holds it and that check with its moves checked (shown instead while
        #: the point's check is that one)
        self._via: dict[str, tuple[PointCheck, PointCheck]] = {}
        self.via_future: Future[Any] | None = None
        self._via_asked: tuple[object, ...] = ()
        # per point, bumped by every change that drops its check: a recheck started before the
        # change (say, for a sensor an undo has taken back) must not store its result after
        self._check_gen: dict[str, int] = {}
        # per point, the plan its stored check was made in (or a copy of it with the cell's
        # source, load_cell): a check made in the plan a change brings is not memoised as the
        # previous plan's
        self._checked_in: dict[str, UiPlan] = {}
        #: the cell's generation: what was worked out in an earlier cell is not reused
        self._cell_gen = 0
        #: what undo and redo bring back with a plan object seen before (:mod:`webui.doc_memo`):
        #: each point's check as it was shown in that plan, its role flags, its cycle time
        self._check_memo: DocMemo[tuple[ProbePoint, PointCheck]] = DocMemo()
        self._flags_memo: DocMemo[RoleFlags] = DocMemo()
        self._cycle_memo: DocMemo[tuple[tuple[tuple[str, PointCheck], ...], CycleTime | None]] = (
            DocMemo()
        )
        #: tabs that did not take the table's updates in time: not waited for again until
        #: they catch up (:func:`webui.gui_first.flush_gui_first`)
        self._stalled_tabs: set[int] = set()
        #: the estimated cycle time of the plan as edited, from the latest checks
        self.cycle: CycleTime | None = None
        #: the latest cycle-time estimate (:meth:`update_cycle_time`)
        self.cycle_future: Future[CycleTime | None] | None = None
        self._lock = threading.RLock()
        #: held through a whole change of cell (build, draw, recheck): two at once (an undo
        #: clicked twice, an edit during an undo) drew each other's nodes away half-made
        self._cell_lock = threading.RLock()
        self._cell_key: tuple[CellSpec, WorkObjectSpec] | None = None
        self._part: tuple[str, str | None, str] | None = None
        self._robot_key: tuple[object, ...] | None = None
        self.flags = RoleFlags()
        #: Handlers of scene clicks by mode (``"place"``: click-to-place); a panel may set
        #: :attr:`click_mode` to its own (e.g. picking the points of a 3-point frame).
        self.click_handlers: dict[str, Any] = {"place": lambda e: click_place.click_place(self, e)}
        self.click_mode = "place"
        self.heatmap = HeatMap(self)
        self.points_panel = points_panel.PointsPanel(self)
        #: each tab's selected point, its settings widgets and highlight (issue 14, item 9)
        self.selection = Selections(
            self, self.points_panel.selection_folder, self.points_panel.guard
        )
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
        #: Tabs whose own widgets, robot and first view are set up (connect handler finished).
        self.ready_clients: set[int] = set()
        server.on_client_connect(self._on_connect)
        server.on_client_disconnect(self._on_disconnect)
        if isinstance(plan.source, Plan):
            self.load_cell(plan.source, self.plan_dir)

    # ---- cell ---------------------------------------------------------------------------
    def load_cell(self, plan: Plan, plan_dir: Path) -> None:
        """Build the plan's cell on the worker and redraw the scene; raise if it fails.

        On failure the previous cell, scene and plan stay as they were. One cell loads at a
        time: a second waits for the first to be built and drawn whole.
        """
        with self._cell_lock:
            self._load_cell(plan, plan_dir)

    def _load_cell(self, plan: Plan, plan_dir: Path) -> None:
        self.heatmap.stop()
        with self.busy("loading the cell"):
            try:
                self.worker.replace_resource(lambda: CellSession(plan, plan_dir), CELL_LOAD_S)
            except ResourceTimeout:  # it has no message of its own; the cell shown stays
                raise InputError(
                    f"the cell of the plan ({len(plan.points)} points, work object "
                    f"{plan.work_object.mesh}) did not load within {CELL_LOAD_S:.0f} s"
                ) from None
        session = self.worker.call(lambda s: s)
        view = session.view
        picker = SurfacePicker(view.wobj_mesh, view.T_world_wobj)
        with self._lock:
            old_part = None if self.view is None else self.view.wobj_mesh
            self.plan_dir = Path(plan_dir)
            self.view, self.picker = view, picker
            self._cell_key = _cell_key(plan)
            self._checks.clear()
            self._via.clear()
            self._checked_in.clear()
            self._cell_gen += 1
            self._check_memo.clear()
            self._cycle_memo.clear()
        self.scene.draw_work_object(view.wobj_mesh, view.T_world_wobj)
        for layer in ("quality", "error"):  # painted again below for the new part, if ticked
            self.scene.color_work_object(None, layer=layer)
        self.scene.draw_fixtures(view.fixtures)
        robot_key = _robot_key(view, plan)
        if self.robot is not None and robot_key == self._robot_key:
            pass  # the same robot, base and tool (the part or a fixture changed): each tab's
            # robot stays drawn where it is, jogged or taught, with the Teach tab's fields
        elif self.robot is not None:
            self.robot.remove()
            self.robot = None
        self._robot_key = robot_key
        if self.robot is None and view.robot_urdf is not None:
            self.robot, why = tab_robots_or_reason(self.server, view, self.robot_display)
            if self.robot is not None:  # tabs that connected while it was being built
                for client in list(self.server.get_clients().values()):
                    self.robot.add_client(client)
            if why:
                logger.warning("%s", why)
                self.notify("Robot not drawn", why, error=True)
        self.teach_panel.on_cell()
        part = _part_key(plan)
        if old_part is None or part != self._part:  # first cell or a new part: frame it
            for client in self.server.get_clients().values():
                clients.set_default_camera(client, view)
        self._part = part  # moving, snapping or reframing the same part keeps the camera
        # the points checked as the plan will be (its tool's TCP, its sensor) in the new cell
        self.recheck(self.state.doc.ids, with_source(self.state.doc, plan))
        self.teach_panel.after_checks(force=True)  # vias and moves in the new cell
        self.layout_panel.refresh()
        try:  # the last report's error, on the part as it is now (when ticked)
            self.validate_panel.paint_error()
        except Exception:  # colours only: the cell is loaded whatever they do
            logger.exception("painting the validation's error on the new part failed")

    def replace_source(self, plan: Plan, label: str) -> None:
        """Make ``plan`` (another cell: part, robot, fixtures or their poses) the session's, in
        one undoable step; its cell is built first, and when that fails nothing changes."""
        with self._cell_lock:  # no other cell change between the cell and its plan
            self._load_cell(plan, self.plan_dir)
            self.state.update(lambda d: with_source(d, plan), label)

    # ---- checks ---------------------------------------------------------------------------
    def check_of(self, point_id: str) -> PointCheck | None:
        """The latest check of a point, or ``None`` while it is being computed; with the moves
        into it checked once :meth:`update_via_moves` has (as ``wobjcal check`` has them)."""
        with self._lock:
            entry = self._checks.get(point_id)
            return None if entry is None else self._with_moves(point_id, entry[1])

    def checks(self) -> dict[str, PointCheck]:
        """The latest check of every point that has one (moves included, :meth:`check_of`)."""
        with self._lock:
            return {pid: self._with_moves(pid, c) for pid, (_, c) in self._checks.items()}

    def _with_moves(self, point_id: str, check: PointCheck) -> PointCheck:
        via = self._via.get(point_id)
        return via[1] if via is not None and via[0] is check else check

    def update_via_moves(self) -> Future[Any]:
        """Check the moves between the points (joint moves through each point's vias, from
        every point a program probes before it) once every point of the plan as edited has
        its check, on the cell worker; then the table and the markers show a point whose moves
        fail as ``wobjcal check`` and the export do: infeasible, with its ``vias:`` cause. A
        single point's check leaves them out (they depend on the other points)."""
        done: Future[Any] = Future()
        done.set_result(None)
        doc = self.state.doc
        plan = plan_as_edited(doc)
        with self._lock:
            raw = {pid: c for pid, (_, c) in self._checks.items()}
            gen = self._cell_gen
        if plan is None or any(p.id not in raw for p in plan.points):
            return done  # a later check of the missing points asks again
        checks = [raw[p.id] for p in plan.points]
        asked: tuple[object, ...] = (doc, *checks)  # the very objects, compared by identity
        with self._lock:  # the same plan, checks and cell asked and still queued: that one
            pending, before = self.via_future, self._via_asked
            if (
                pending is not None
                and not pending.done()
                and before[:1] == (gen,)
                and len(before) == len(asked) + 1
                and all(a is b for a, b in zip(before[1:], asked, strict=True))
            ):
                return pending
            fut = self.worker.submit(lambda s: None if s is None else s.via_moves(plan, checks))
            self._via_asked, self.via_future = (gen, *asked), fut

        def show(f: Future[tuple[PointCheck, ...] | None]) -> None:
            try:
                moved = f.result()
            except Exception:  # the rows keep the points' own checks
                logger.exception("checking the moves between the points failed")
                return
            if moved is None or self.state.doc is not doc or gen != self._cell_gen:
                return  # a later edit's (or cell's) moves follow
            with self._lock:
                before = {pid: self._with_moves(pid, c) for pid, c in raw.items()}
                self._via = {c.point_id: (c, m) for c, m in zip(checks, moved, strict=True)}
                changed = [pid for pid in raw if self._with_moves(pid, raw[pid]) is not before[pid]]
            if changed and self.state.doc is doc:  # only the points whose status changed,
                # each drawn alone (no other marker touched, whatever another thread draws)
                self.points_panel.refresh()
                with self.server.atomic():
                    for pid in changed:
                        if pid in doc.ids:
                            self.scene.draw_point(
                                doc.get(pid), self.check_of(pid), False, pid in self.flags.by_point
                            )
                self.server.flush()

        fut.add_done_callback(show)
        return fut

    def recheck(
        self, point_ids: tuple[str, ...] | list[str], doc: UiPlan | None = None
    ) -> list[PointCheck]:
        """Check the given points in the cell (on the worker), store and draw the results.

        ``doc``: the plan to check them in (default the session's; a new cell's plan before
        the session takes it, :meth:`load_cell`)."""
        with self._lock:  # before the plan is read: a change after this read bumps them
            cell_gen = self._cell_gen  # a new cell drops every check (load_cell)
            gens = {pid: self._check_gen.get(pid, 0) for pid in point_ids}
        doc = self.state.doc if doc is None else doc
        points = [doc.get(pid) for pid in point_ids if pid in doc.ids]
        if not points:
            return []
        edited = [plan_point(p) for p in points]
        as_edited = plan_as_edited(doc)
        with self.busy(f"checking {', '.join(p.id for p in points[:6])}"):
            results = self.worker.call(
                lambda s: [] if s is None else s.check_points(edited, as_edited)
            )
        current = self.state.doc
        with self._lock:
            for point, check in zip(points, results, strict=False):
                still = (
                    point.id in current.ids
                    and current.get(point.id).probe == point.probe
                    and self._check_gen.get(point.id, 0) == gens[point.id]
                    and self._cell_gen == cell_gen
                )
                if still:  # drop results of a point that moved on (or was undone) meanwhile
                    self._checks[point.id] = (point.probe, check)
                    self._checked_in[point.id] = doc
        self._redraw([p.id for p in points])
        return results

    def _redraw(self, point_ids: list[str] | None = None) -> None:
        """Redraw the given points (all when ``None``), drop removed ones, refresh the panel."""
        doc = self.state.doc
        flags = self._flags_memo.get(doc)
        if flags is None:
            flags = role_flags(doc)
            self._flags_memo.put(doc, flags)
        before, self.flags = self.flags, flags
        if point_ids is not None:  # a point whose flag came or went is redrawn too
            moved = set(before.by_point) ^ set(self.flags.by_point)
            point_ids = [*point_ids, *(i for i in moved if i not in point_ids and i in doc.ids)]
        known = self._known_cycle(doc)
        if known is not None:  # undo or redo to a plan whose estimate is known: in this row
            self.cycle = known[0]
        # the table first, in a websocket message of its own: the page applies a message of
        # GUI updates at once, one with scene updates only in its next frame (0.2-1 s with
        # software WebGL), and viser sends what is queued together (:mod:`webui.gui_first`)
        self.points_panel.refresh()
        flush_gui_first(self.server, stalled=self._stalled_tabs)
        self.scene.draw_points(doc, self.checks(), None, only=point_ids, flags=self.flags.by_point)
        self.server.flush()
        self.update_cycle_time()  # after the rows: a click or undo does not wait for it
        self.update_via_moves()  # and the moves between the points, once all are checked

    def _sorted_checks(self) -> tuple[tuple[str, PointCheck], ...]:
        """The latest checks, by point id (what a cycle-time estimate is made from)."""
        with self._lock:
            return tuple(sorted(((pid, c) for pid, (_, c) in self._checks.items())))

    def _known_cycle(self, doc: UiPlan) -> tuple[CycleTime | None] | None:
        """The cycle time estimated before for this very plan object from these very checks,
        in this cell, as a 1-tuple (``(None,)``: a plan that has none, e.g. a point without a
        role); ``None`` when it is not known."""
        if plan_as_edited(doc) is None:  # no plan loaded, or an edit that breaks a plan rule
            return (None,)
        checks = self._sorted_checks()
        hit = self._cycle_memo.get(doc, self._cell_gen)
        if hit is None or len(hit[0]) != len(checks):
            return None
        same = all(a == b and x is y for (a, x), (b, y) in zip(hit[0], checks, strict=True))
        return (hit[1],) if same else None

    def update_cycle_time(self) -> Future[CycleTime | None]:
        """Estimate the cycle time of the plan as edited, from the latest checks, on the cell
        worker (it reads the cell's robot); once done, and only if the plan is still the same,
        :attr:`cycle` is set and the status table says it. Returns the estimate's future."""
        doc = self.state.doc
        plan = plan_as_edited(doc)
        if plan is None:  # no plan loaded, or an edit that breaks a plan rule
            self.cycle = None
            done: Future[CycleTime | None] = Future()
            done.set_result(None)
            self.cycle_future = done
            return done
        known = self._known_cycle(doc)
        if known is not None:  # undo or redo: estimated before, from the same checks
            self.cycle = known[0]
            self.points_panel.refresh()  # nothing is sent when the table already says it
            done = Future()
            done.set_result(known[0])
            self.cycle_future = done
            return done
        sorted_checks = self._sorted_checks()
        gen = self._cell_gen
        checks = [c for _, c in sorted_checks]
        fut = self.worker.submit(lambda s: None if s is None else s.cycle_time(plan, checks))

        def show(f: Future[CycleTime | None]) -> None:
            try:
                cycle = f.result()
            except Exception:  # the status table goes without it; checks are not affected
                logger.exception("the cycle time estimate failed")
                cycle = None
            else:
                if gen == self._cell_gen:
                    self._cycle_memo.put(doc, (sorted_checks, cycle), gen)
            if self.state.doc is not doc:  # a later edit's estimate follows
                return
            self.cycle = cycle
            self.points_panel.refresh()

        fut.add_done_callback(show)
        self.cycle_future = fut
        return fut

    def _load_latest_cell(self) -> None:
        """Load the cell of the session's latest plan, again until it is the one shown (with
        ``_cell_lock`` held). Changes are not queued: one that came while another cell was
        loading was compared with the cell shown then, and may have loaded nothing (a redo
        back to that cell while an undo's earlier cell was being built)."""
        while True:
            latest = self.state.doc.source
            if not isinstance(latest, Plan) or _cell_key(latest) == self._cell_key:
                return
            try:
                self._load_cell(latest, self.plan_dir)
            except Exception as exc:  # the previous cell stays; said, not retried
                self.notify("Cell not loaded", str(exc), error=True)
                return

    def _on_change(self, change: Change[UiPlan]) -> None:
        """Every change of the plan: its rows first (checked, drawn, sent), then the layout's
        quality, on the layout panel's own thread (after the rows: it does not slow them)."""
        try:
            self._show_change(change)
        finally:
            self.layout_panel.refresh()

    def _show_change(self, change: Change[UiPlan]) -> None:
        source = change.doc.source
        if isinstance(source, Plan) and _cell_key(source) != self._cell_key:
            with self._cell_lock:  # e.g. undo of an upload: go back to the earlier cell
                self._load_latest_cell()
            self._redraw()
            self.selection.follow(self.state.doc, set())  # deleted points, highlights moved
            was = change.previous.source
            new_part = not isinstance(was, Plan) or _part_key(was) != _part_key(source)
            self.files_panel.refresh_off_surface(part_changed=new_part)
            return
        self.files_panel.refresh_off_surface(part_changed=False)
        before = {p.id: p for p in change.previous.points}
        changed = [p.id for p in change.doc.points if before.get(p.id) != p]
        previous = change.previous.source
        sensor_changed = (
            isinstance(source, Plan)
            and isinstance(previous, Plan)
            and source.validation.sensor != previous.validation.sensor
        )
        if sensor_changed:  # the checks read it (footprint, standoff): all checked again
            changed = list(change.doc.ids)
            self.heatmap.stop()  # coloured with the old sensor's footprint: gone, not stale
        known = []  # points whose check in this very plan is known: undo or redo to it
        with self._lock:
            for pid in [*changed, *(set(before) - set(change.doc.ids))]:
                self._check_gen[pid] = self._check_gen.get(pid, 0) + 1
                entry = self._checks.pop(pid, None)
                checked_in = self._checked_in.pop(pid, None)
                # for an undo back to the plan it was shown in; not a check of the new plan
                # itself (a recheck that stored it before this change's listener ran)
                if entry is not None and checked_in is not change.doc:
                    self._check_memo.put(change.previous, entry, (pid, self._cell_gen))
            for pid in changed:
                entry = self._check_memo.get(change.doc, (pid, self._cell_gen))
                if entry is not None and entry[0] == change.doc.get(pid).probe:
                    self._checks[pid] = entry
                    self._checked_in[pid] = change.doc
                    known.append(pid)
        if len(changed) > 2 or not changed:  # grey "pending" markers for bulk changes
            self._redraw(changed)
        elif known:
            self._redraw(known)
        self.recheck([pid for pid in changed if pid not in known])  # draws them
        self.teach_panel.after_checks()  # vias and shown moves of the plan as it now is
        for cid in self.selection.follow(change.doc, set(changed)):  # tabs whose point changed
            if self.points_panel.follow.value:
                self._pose_robot(cid)

    def show_reachability(self, n_samples: int = HEAT_MAP_SAMPLES) -> None:
        """Start the reachability heat map of ``n_samples`` surface samples (500, as
        documented), computed in chunks on the cell worker."""
        self.heatmap.stop()
        self.heatmap.start(n_samples)

    # ---- editing ---------------------------------------------------------------------------
    def place_at_ray(
        self,
        origin_world: ArrayLike,
        direction_world: ArrayLike,
        point_id: str | None = None,
        client: viser.ClientHandle | None = None,
    ) -> PointCheck | None:
        """Put a point where a ray (world frame) hits the work object; return its check.

        This is what a click on the work object does; the new point is selected in the tab of
        ``client`` (every tab when ``None``).

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
        cap = new_point_overtravel_cap_m(
            self.view, picker, self.state.doc.source, hit.position_wobj, hit.normal_wobj
        )  # a new point's default overtravel stops short of the table behind it

        def edit(doc: UiPlan) -> UiPlan:
            return plan_doc.place_point(
                doc, pid, hit.position_wobj, hit.normal_wobj, max_overtravel_m=cap
            )

        self.state.update(edit, f"place {pid}")
        self.select(pid, client)
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

    @property
    def selected(self) -> str | None:
        """The latest point selected in any tab or by a script (see :meth:`selection_of`)."""
        return self.selection.latest

    def selection_of(self, client: viser.ClientHandle | None) -> str | None:
        """The point the tab of ``client`` has selected (``None``: the latest anywhere)."""
        return self.selection.of(None if client is None else client.client_id)

    def select(self, point_id: str | None, client: viser.ClientHandle | None = None) -> None:
        """Select a point in one tab (``client``) or in every tab (``None``, e.g. a script):
        highlight it there, and show that tab's robot at its probe pose when "Robot follows
        selection" is ticked (otherwise the robot stays where it is: :meth:`robot_to_selected`
        moves it when asked)."""
        cid = None if client is None else client.client_id
        self.selection.select(point_id, cid)
        if self.points_panel.follow.value:
            self._pose_robot(cid)
        self.points_panel.refresh()  # the drag gizmo follows the latest selection

    def set_robot_display(self, display: str) -> None:
        """Draw the robot ``"shown"``, ``"ghost"`` or ``"hidden"`` in every tab; a ghost or
        hidden robot does not stop a click on the part."""
        self.robot_display = display
        if self.robot is not None:
            self.robot.set_display(display)

    def robot_to_selected(self, client: viser.ClientHandle | None = None) -> None:
        """Show the robot of one tab (``client``; every tab: ``None``) at its selected point's
        probe pose.

        Raises:
            InputError: no point selected there, its check is still running, or it has no pose.
        """
        cid = None if client is None else client.client_id
        point_id = self.selection.of(cid)
        if point_id is None:
            raise InputError("select a point first")
        check = self.check_of(point_id)
        if check is None:
            raise InputError(f"{point_id} is still being checked")
        if check.q is None:
            raise InputError(f"{point_id} has no robot pose: {check.reason}")
        self._pose_robot(cid)

    def _pose_robot(self, client_id: int | None) -> None:
        """Robot of tab ``client_id`` (every tab: ``None``) at its selected point's probe pose."""
        point_id = self.selection.of(client_id)
        check = None if point_id is None else self.check_of(point_id)
        if self.robot is not None and check is not None and check.q is not None:
            self.robot.set_q(check.q, client_id)

    def _on_scene_click(self, event: Any) -> None:
        """Every click on the 3D view: handled by the current mode, or told why it did nothing."""
        handler = self.click_handlers.get(self.click_mode, self.click_handlers["place"])
        guarded(self, event.client, handler, event, title="Click not used", action="a click")

    # ---- clients ---------------------------------------------------------------------------
    def _upload_refused(self, client_id: int, name: str, message: str) -> None:
        client = self.server.get_clients().get(client_id)
        self.notify("Upload refused", message, client=client, error=True)

    def tab(self, name: str) -> Any:
        """The control panel's tab ``name`` (a context for a panel's widgets)."""
        return self.tabs.tab(name)

    def _on_connect(self, client: viser.ClientHandle) -> None:
        self.selection.add_client(client)
        if self.robot is not None:
            self.robot.add_client(client)
        if self.view is not None:
            clients.set_default_camera(client, self.view)
        if self.autosave_note:
            self.notify("Autosave", self.autosave_note, client=client, error=False)
        self.ready_clients.add(client.client_id)

    def _on_disconnect(self, client: viser.ClientHandle) -> None:
        self.ready_clients.discard(client.client_id)
        self.selection.remove_client(client.client_id)
        if self.robot is not None:
            self.robot.remove_client(client.client_id)

    def notify(
        self, title: str, body: str, client: viser.ClientHandle | None = None, error: bool = True
    ) -> None:
        """Show a notification to one tab, or to every tab when ``client`` is None."""
        clients.notify(self.server, title, body, client, error)

    def stop(self) -> None:
        """Stop the server and the worker; remove the uploads only this session used."""
        try:
            self.files_panel.close()
        except Exception:  # cleaning must not stop the stop
            logger.exception("upload folders not cleaned")
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


def _file_key(path: Path | None) -> tuple[str, int, int] | None:
    if path is None:
        return None
    try:
        st = path.stat()
    except OSError:
        return (str(path), -1, -1)
    return (str(path), st.st_mtime_ns, st.st_size)


def _robot_key(view: CellView, plan: Plan) -> tuple[object, ...]:
    """What decides how the robot and its tool are drawn: the plan's robot and tool (file,
    base and tip links, xacro arguments, package path, mount, TCP), their files (path, time,
    size), the base pose, the tool's mount and mesh. The same key after a cell change (the
    part or a fixture moved): the tabs' robots are kept, at their poses."""
    mesh = view.tool_mesh
    specs = msgspec.json.encode((plan.cell.robot, plan.cell.tool))
    return (
        specs,
        _file_key(view.robot_urdf),
        _file_key(view.tool_urdf),
        np.asarray(view.T_world_base, dtype=np.float64).tobytes(),
        np.asarray(view.T_flange_tool, dtype=np.float64).tobytes(),
        None if mesh is None else (mesh.vertices.tobytes(), mesh.faces.tobytes()),
    )


def _part_key(plan: Plan) -> tuple[str, str | None, str]:
    """What makes a new part (the camera is framed on it): its file, digest and units, not its
    pose nor its frame (moving, snapping or the 3-point frame keep the camera)."""
    wo = plan.work_object
    return (wo.mesh, wo.sha256, wo.units)
