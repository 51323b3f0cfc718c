"""The "Cell" panel: set up the cell: move and rotate the work object, the robot base and the
fixtures with numeric fields (mm, deg) or a gizmo, and snap the part onto a fixture; below, the
tool and its TCP (:mod:`webui.cell_tool`), the sensor and the search speed
(:mod:`webui.cell_sensor`), and fixtures added or deleted (:mod:`webui.cell_fixtures`).

Each change is a new plan source (:mod:`webui.cell_edits`, :mod:`webui.cell_setup_edits`): its
cell is built first, and only when that works does the session change, in one undoable,
autosaved step; every point is then checked again in the new cell.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Any

import numpy as np

from calib.errors import InputError
from calib.frames import make_transform, matrix_from_quat_wxyz, quat_wxyz_from_matrix
from calib.models import ProximitySensor
from calib.plan.file import Plan
from planner.cell.scene import gap_mismatch
from webui import cell_edits
from webui.cell_edits import ROBOT_BASE, WORK_OBJECT
from webui.cell_fixtures import FixturesSection
from webui.cell_sensor import SensorSection
from webui.cell_tool import ToolSection
from webui.panel import Panel

if TYPE_CHECKING:
    from webui.context import AppContext

logger = logging.getLogger(__name__)

NO_FIXTURE = "(no fixture)"
#: A gizmo drag that ends within this of where it started changes nothing, m and rad.
GIZMO_TOL = 1e-6


class CellPanel(Panel):
    """GUI widgets of the cell setup (shared by all tabs); its tool, sensor and fixture
    sections run their edits through its :meth:`guard`.

    Args:
        app: the app whose plan's cell is edited.
    """

    TAB = "Cell"
    REFUSED = "Cell not changed"
    ACTION = "cell edit"

    def __init__(self, app: AppContext) -> None:
        super().__init__(app)
        self._mismatch_key: tuple[str, str, float] | None = None
        self._mismatch = ""
        self._gizmo: Any = None
        self._gizmo_T: np.ndarray | None = None
        gui = app.server.gui
        with app.tab(self.TAB):
            gui.add_markdown("Move the work object, the robot base or a fixture (world frame).")
            self.target = gui.add_dropdown("Move", (WORK_OBJECT, ROBOT_BASE))
            self.position = gui.add_vector3("Position (mm)", (0.0, 0.0, 0.0), step=1.0)
            self.rotation = gui.add_vector3("Rot z-y'-x'' (deg)", (0.0, 0.0, 0.0), step=1.0)
            self.apply = gui.add_button("Apply pose")
            self.use_gizmo = gui.add_checkbox("Move with gizmo", False)
            self.snap_to = gui.add_dropdown("Snap onto", (NO_FIXTURE,))
            self.snap = gui.add_button("Snap part onto fixture")
            self.tool = ToolSection(app, self.guard)
            self.sensor = SensorSection(app, self.guard)
            self.fixtures = FixturesSection(app, self.guard, self._show_target)
        self.target.on_update(lambda _ev: self.refresh())
        self.apply.on_click(lambda ev: self.guard(ev, self.apply_fields))
        self.use_gizmo.on_update(lambda ev: self.guard(ev, self._update_gizmo))
        self.snap.on_click(lambda ev: self.guard(ev, self.snap_part, str(self.snap_to.value)))
        app.state.subscribe(lambda _change: self.refresh())
        self.refresh()

    def _plan(self) -> Plan:
        source = self._app.state.doc.source
        if not isinstance(source, Plan):
            raise InputError("load a plan first: there is no cell to set up")
        return source

    def _show_target(self, target: str) -> None:
        """Choose ``target`` under Move (e.g. a fixture just added) and show its pose."""
        self.refresh()
        self.target.value = target

    def _tcp_mismatch(self, plan: Plan) -> str:
        """Why the plan's proximity sensor does not fit its tool's sensor TCP (its sensing
        distance is not the TCP's distance from the sensor face,
        :func:`planner.cell.scene.tool_face. gap_mismatch`), or ``""``."""
        sensor = plan.validation.sensor
        if not isinstance(sensor, ProximitySensor):
            return ""
        key = (plan.cell.tool.name, plan.cell.tool.tcp, sensor.standoff_m)
        if key != self._mismatch_key:  # asked on every edit: the tool's files read on a change
            self._mismatch_key, self._mismatch = key, self._tool_mismatch(plan, sensor)
        return self._mismatch

    def _tool_mismatch(self, plan: Plan, sensor: ProximitySensor) -> str:
        try:
            tool = self.tool.tool_of(plan.cell.tool.name)
        except (InputError, OSError):  # the tool section says why it has no tool
            return ""
        if tool.sensor_tcp is None or tool.sensor_tcp != plan.cell.tool.tcp:
            return ""
        return gap_mismatch(tool, sensor.standoff_m)

    def refresh(self) -> None:
        """Show the current plan's things and the chosen one's pose."""
        doc = self._app.state.doc
        source = doc.source
        if not isinstance(source, Plan):
            return
        self.tool.refresh(source)
        self.sensor.refresh(doc)
        self.sensor.warn(self._tcp_mismatch(source))
        self.fixtures.refresh(source)
        options = cell_edits.movable(source)
        if tuple(self.target.options) != options:
            self.target.options = options
        fixtures = tuple(f.name for f in source.cell.fixtures) or (NO_FIXTURE,)
        if tuple(self.snap_to.options) != fixtures:
            self.snap_to.options = fixtures
        target = str(self.target.value)
        if target not in options:
            return
        position, angles = cell_edits.fields_of(cell_edits.pose_of(source, target))
        if tuple(self.position.value) != position:
            self.position.value = position
        if tuple(self.rotation.value) != angles:
            self.rotation.value = angles
        self._update_gizmo()

    # ---- edits ---------------------------------------------------------------------------
    def move(self, target: str, T_world: np.ndarray) -> None:
        """Put ``target`` at the world pose ``T_world`` (one undoable step; nothing when it is
        there already)."""
        source = self._plan()
        if np.allclose(cell_edits.pose_of(source, target), T_world, rtol=0.0, atol=GIZMO_TOL):
            return
        plan = cell_edits.with_pose(source, target, T_world)
        self._app.replace_source(plan, f"move {target}")

    def apply_fields(self) -> None:
        """Move the chosen thing to the pose in the fields."""
        T = cell_edits.pose_from_fields(self.position.value, self.rotation.value)
        self.move(str(self.target.value), T)

    def snap_part(self, fixture: str) -> None:
        """Rest the work object on the top face of ``fixture``, centred over it."""
        source = self._plan()
        view = self._app.view
        if fixture == NO_FIXTURE or view is None or fixture not in view.fixtures:
            have = sorted(view.fixtures) if view is not None else []
            raise InputError(f"no fixture {fixture!r} to snap onto; the cell has {have}")
        mesh, _ = view.fixtures[fixture]
        T = cell_edits.snapped_onto(source, view.wobj_mesh, fixture, mesh)
        self.move(WORK_OBJECT, T)

    # ---- gizmo ---------------------------------------------------------------------------
    def _update_gizmo(self) -> None:
        scene = self._app.server.scene
        source = self._app.state.doc.source
        if not self.use_gizmo.value or not isinstance(source, Plan):
            if self._gizmo is not None:
                self._gizmo.remove()
                self._gizmo = None
            return
        T = cell_edits.pose_of(source, str(self.target.value))
        view = self._app.view
        size = 0.5 if view is None else float(np.max(view.wobj_mesh.extents))
        if self._gizmo is None:
            self._gizmo = scene.add_transform_controls(
                "/cell_gizmo", scale=float(np.clip(size * 0.8, 0.15, 0.8)), line_width=4.0,
                depth_test=False,
            )  # fmt: skip
            self._gizmo.on_update(self._on_gizmo)
        self._gizmo_T = T
        self._gizmo.wxyz = quat_wxyz_from_matrix(T[:3, :3])
        self._gizmo.position = T[:3, 3]

    def _on_gizmo(self, event: Any) -> None:
        if event.phase != "end":
            return
        g = event.target
        T = make_transform(matrix_from_quat_wxyz(g.wxyz), g.position)
        self.guard(event, self.move, str(self.target.value), T)
