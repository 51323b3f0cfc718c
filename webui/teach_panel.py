"""The "Teach" panel: jog the robot and teach its pose as a probe point's approach or a via.

Joint sliders (deg, within the URDF's limits; coarse), a typed value and fine steps per joint
(:mod:`webui.joint_jog`) and a TCP gizmo driven by the inverse kinematics
(the solution nearest the current joint values, so the arm keeps its branch) move the drawn
robot; after every move the joint limits and the clearance of the whole robot are checked in
the cell (on the cell worker) and shown at once. **Teach pose** puts a probe point where the
sensor axis meets the part, with the search starting from the taught TCP position
(its distance from the surface is the start offset).

**Teach as via point** adds the jogged joint values as the last via before the selected point
(``points[i].vias``); :mod:`webui.moves_view` draws the vias and the checked moves.

The plan file does not store the sensor's rotation about the normal (the check picks it), so a
taught approach fixes the point and its start offset, not the wrist's roll.
"""

from __future__ import annotations

import contextlib
import logging
import threading
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.errors import InputError
from calib.frames import (
    make_transform,
    matrix_from_quat_wxyz,
    quat_wxyz_from_matrix,
    transform_points,
)
from calib.plan.cell import Pose
from calib.plan.vias import ViaPoint
from webui import plan_doc
from webui.backend import JogStatus
from webui.joint_jog import FineJog
from webui.moves_view import ViaView, draw_moves
from webui.panel import Panel
from webui.search_room import new_point_overtravel_cap_m

if TYPE_CHECKING:
    from webui.context import AppContext

logger = logging.getLogger(__name__)

NEW_POINT = "new point"
#: A ray cast from this far behind the TCP along the sensor axis finds the taught point, m.
BEHIND_M = 0.2
#: Smallest search start offset a taught pose gives, m.
MIN_START_M = 0.001


class TeachPanel(Panel):
    """Jog sliders, TCP gizmo and teaching (shared by all tabs).

    Args:
        app: the app whose robot is jogged.
    """

    TAB = "Teach"
    ACTION = "teach action"

    def __init__(self, app: AppContext) -> None:
        super().__init__(app)
        self._sync = threading.local()
        self.sliders: list[Any] = []
        self._gizmo: Any = None
        self.q: NDArray[np.float64] = np.zeros(0)
        self.last_status: JogStatus | None = None
        gui = app.server.gui
        with app.tab(self.TAB):
            gui.add_markdown("Jog the robot; teach the pose as a point's approach.")
            self.joints = gui.add_folder("Joints (deg)")
            self.fine = FineJog(app, self.guard, self.jog, lambda: self.q)
            self.status_md = gui.add_markdown("")
            self.from_point = gui.add_button("Jog to selected point")
            self.drag_tcp = gui.add_checkbox("Drag TCP (IK)", False)
            self.target = gui.add_dropdown("Teach as", (NEW_POINT,))
            self.teach_button = gui.add_button("Teach pose", color="blue")
            self.via_button = gui.add_button(
                "Teach as via point", hint="add the jogged pose as a via before the selected point"
            )
            self.unvia_button = gui.add_button(
                "Remove last via", hint="remove the selected point's last via"
            )
            self.show_moves = gui.add_checkbox("Show moves between points", False)
            self.moves_md = gui.add_markdown("")
        self.from_point.on_click(lambda ev: self.guard(ev, self.jog_to_selected, ev.client))
        self.drag_tcp.on_update(lambda ev: self.guard(ev, self._update_gizmo))
        self.teach_button.on_click(lambda ev: self.guard(ev, self.teach, str(self.target.value)))
        self.via_button.on_click(lambda ev: self.guard(ev, self.teach_via, ev.client))
        self.unvia_button.on_click(lambda ev: self.guard(ev, self.remove_via, ev.client))
        self.show_moves.on_update(lambda ev: self.guard(ev, self.draw_moves))
        self.via_view = ViaView(app)
        app.state.subscribe(lambda _c: self._on_change())
        #: ``{"A->B": problem}`` of the last drawn moves (``""``: clear).
        self.moves: dict[str, str] = {}

    # ---- helpers ---------------------------------------------------------------------------
    @contextlib.contextmanager
    def _programmatic(self) -> Iterator[None]:
        self._sync.on = True
        try:
            yield
        finally:
            self._sync.on = False

    def _tcp(self) -> str:
        source = self._app.state.doc.source
        return "sensor" if source is None else source.cell.tool.tcp

    def _on_change(self) -> None:
        self._refresh_targets()

    def after_checks(self, force: bool = False) -> None:
        """Once the app has checked an edit (or a new cell: ``force``), redraw the vias (only
        when they changed, unless ``force``) and, while "Show moves between points" is ticked,
        the checked moves of the plan as it now is."""
        try:
            self.via_view.draw(force=force)
            if self.show_moves.value:
                self.draw_moves()
        except Exception:  # a drawing problem must not break the edit
            logger.exception("drawing the vias or moves failed")

    def _refresh_targets(self) -> None:
        options = (NEW_POINT, *self._app.state.doc.ids)
        if tuple(self.target.options) != options:
            self.target.options = options

    # ---- joints ----------------------------------------------------------------------------
    def on_cell(self) -> None:
        """Rebuild the joint sliders for the loaded cell's robot (its limits, in degrees)."""
        self._build_sliders()

    def _build_sliders(self) -> None:
        view = self._app.view
        for s in self.sliders:
            s.remove()
        self.sliders = []
        if view is None or view.chain is None:
            self.fine.build(None, np.zeros(0))
            return
        chain = view.chain
        robot = self._app.robot
        q0 = robot.q if robot is not None and len(robot.q) == chain.n_joints else None
        q0 = np.clip(np.zeros(chain.n_joints), chain.lower, chain.upper) if q0 is None else q0
        gui = self._app.server.gui
        with self.joints:
            for i, name in enumerate(chain.joint_names):
                lo = -360.0 if not np.isfinite(chain.lower[i]) else np.degrees(chain.lower[i])
                hi = 360.0 if not np.isfinite(chain.upper[i]) else np.degrees(chain.upper[i])
                slider = gui.add_slider(
                    f"J{i + 1}", float(round(lo, 3)), float(round(hi, 3)), 0.1,
                    float(np.clip(round(np.degrees(q0[i]), 3), lo, hi)), hint=name,
                )  # fmt: skip
                slider.on_update(self._on_slider)
                self.sliders.append(slider)
        self.q = np.asarray(q0, dtype=np.float64)
        self.fine.build(chain, self.q)
        self._refresh_targets()

    def _on_slider(self, event: Any) -> None:
        if getattr(self._sync, "on", False):
            return
        q = np.radians([float(s.value) for s in self.sliders])
        self.guard(event, self.jog, q)

    def jog(self, q: ArrayLike) -> JogStatus:
        """Put the robot at ``q`` (rad): draw it, check limits and clearance, show the status."""
        qa = np.asarray(q, dtype=np.float64).reshape(-1)
        if len(qa) != len(self.sliders):
            raise InputError(f"jog: {len(self.sliders)} joint values expected, got {len(qa)}")
        self.q = qa
        robot = self._app.robot
        if robot is not None:
            robot.stop()
            robot.set_q(qa)
        with self._programmatic():
            for s, v in zip(self.sliders, np.degrees(qa), strict=True):
                if abs(float(s.value) - v) > 1e-6:
                    s.value = float(np.clip(round(v, 3), s.min, s.max))
        self.fine.show(qa)
        with self._app.busy("checking the jogged pose"):
            status: JogStatus = self._app.worker.call(lambda s: s.jog_status(qa))
        self.last_status = status
        colour = {"feasible": "green", "marginal": "orange", "infeasible": "red"}[status.status]
        self.status_md.content = (
            f"<span style='color:{colour}'>**{status.status}**</span>: {status.describe()}"
        )
        self._update_gizmo()
        return status

    def jog_to_selected(self, client: Any = None) -> JogStatus:
        """Jog to the probe pose (from its check) of the point the tab of ``client`` has
        selected (``None``: the latest selected anywhere)."""
        sel = self._app.selection_of(client)
        check = None if sel is None else self._app.check_of(sel)
        if check is None or check.q is None:
            raise InputError("select a point whose probe pose was found (a reachable point)")
        return self.jog(check.q)

    # ---- TCP gizmo ---------------------------------------------------------------------------
    def T_world_tcp(self) -> NDArray[np.float64]:
        """``(4, 4)`` the TCP at the jogged joint values, world frame."""
        q, tcp = self.q.copy(), self._tcp()
        return np.asarray(self._app.worker.call(lambda s: s.T_world_tcp(q, tcp)))

    def _update_gizmo(self) -> None:
        if not self.drag_tcp.value or len(self.q) == 0:
            if self._gizmo is not None:
                self._gizmo.remove()
                self._gizmo = None
            return
        T = self.T_world_tcp()
        if self._gizmo is None:
            self._gizmo = self._app.server.scene.add_transform_controls(
                "/teach_tcp", scale=0.2, line_width=4.0, depth_test=False
            )
            self._gizmo.on_update(self._on_gizmo)
        with self._programmatic():
            self._gizmo.wxyz = quat_wxyz_from_matrix(T[:3, :3])
            self._gizmo.position = T[:3, 3]

    def _on_gizmo(self, event: Any) -> None:
        if getattr(self._sync, "on", False):
            return
        g = event.target
        self.guard(event, self.move_tcp, make_transform(matrix_from_quat_wxyz(g.wxyz), g.position))

    def move_tcp(self, T_world_tcp: ArrayLike) -> JogStatus | None:
        """Jog so that the TCP is at ``T_world_tcp`` (IK nearest the current joints: the
        branch is kept); out of reach leaves the robot where it is and says so."""
        T = np.asarray(T_world_tcp, dtype=np.float64)
        q0, tcp = self.q.copy(), self._tcp()
        q = self._app.worker.call(lambda s: s.ik_near(T, q0, tcp))
        if q is None:
            self.status_md.content = (
                "<span style='color:red'>**out of reach**</span>: no joint values within the "
                "limits put the TCP there; the robot stays where it was"
            )
            return None
        return self.jog(q)

    # ---- moves between points --------------------------------------------------------------
    def draw_moves(self) -> dict[str, str]:
        """Draw and check the joint moves between consecutive points of the plan (from each
        feasible point's probe pose to the next one's, linear in joint space), while the box is
        ticked; say which collide. Recomputed when the box is ticked again."""
        scene = self._app.server.scene
        scene.remove_by_name("/moves")
        self.moves = {}
        if not self.show_moves.value:
            self.moves_md.content = ""
            return self.moves
        self.moves, self.moves_md.content = draw_moves(self._app, self._tcp())
        return self.moves

    # ---- teach -----------------------------------------------------------------------------
    def teach_via(self, client: Any = None) -> int:
        """Add the jogged joint values as the last via before the point the tab of ``client``
        has selected (``None``: the latest selected anywhere); one undo step, autosaved; return
        how many vias the point has now.

        Raises:
            InputError: no robot, or no point selected.
        """
        view, pid = self._app.view, self._app.selection_of(client)
        if view is None or len(self.q) == 0:
            raise InputError("load a plan with a robot first")
        if pid is None:
            raise InputError("select the point the via leads to (click its marker or row)")
        T_wobj_tcp = np.linalg.solve(view.T_world_wobj, self.T_world_tcp())
        via = ViaPoint(
            q_rad=[float(v) for v in self.q], tcp_wobj=Pose.from_matrix(T_wobj_tcp)
        )  # fmt: skip
        change = self._app.state.update(
            lambda d: plan_doc.add_via(d, pid, via), f"via before {pid}"
        )  # fmt: skip
        return len(change.doc.get(pid).vias)

    def remove_via(self, client: Any = None) -> int:
        """Remove the last via of the point the tab of ``client`` has selected (``None``: the
        latest selected anywhere); one undo step, autosaved; return how many vias it has left.

        Raises:
            InputError: no point selected, or it has no via.
        """
        pid = self._app.selection_of(client)
        if pid is None:
            raise InputError("select the point whose via to remove (click its marker or row)")
        change = self._app.state.update(
            lambda d: plan_doc.remove_last_via(d, pid), f"via of {pid} removed"
        )  # fmt: skip
        return len(change.doc.get(pid).vias)

    def teach(self, target: str) -> str:
        """Teach the jogged pose as ``target``'s approach (``"new point"``: the next free id):
        the point is where the sensor axis meets the part, the search starts at the TCP.

        Returns:
            The taught point's id.

        Raises:
            InputError: no robot or part, or the sensor axis does not meet the part.
        """
        picker, view = self._app.picker, self._app.view
        if picker is None or view is None or len(self.q) == 0:
            raise InputError("load a plan with a robot and a work object first")
        T = self.T_world_tcp()
        axis, origin = T[:3, 2], T[:3, 3]
        hit = picker.pick(origin - BEHIND_M * axis, axis)
        if hit is None:
            raise InputError(
                "the sensor axis does not meet the work object: jog the sensor to point at it"
            )
        hit_world = transform_points(view.T_world_wobj, hit.position_wobj)
        start = float((hit_world - origin) @ axis)
        doc = self._app.state.doc
        pid = plan_doc.next_id(doc) if target == NEW_POINT else target

        cap = new_point_overtravel_cap_m(
            view, picker, doc.source, hit.position_wobj, hit.normal_wobj
        )

        def edit(d: plan_doc.UiPlan) -> plan_doc.UiPlan:
            d = plan_doc.place_point(
                d, pid, hit.position_wobj, hit.normal_wobj, max_overtravel_m=cap
            )
            s = d.get(pid).probe.search
            if start < MIN_START_M:  # the TCP is at or inside the surface: keep the offset
                return d
            return plan_doc.edit_search(
                d, pid, kind=s.kind, start_offset_m=start, overtravel_m=s.overtravel_m,
                edge_direction=s.edge_direction,
            )  # fmt: skip

        self._app.state.update(edit, f"teach {pid}")
        self._app.select(pid)
        return pid
