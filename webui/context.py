"""What a panel of the UI may use of the app: :class:`AppContext`.

The panels (points, files, validation, calibration, heat map) are built by
:class:`webui.app.WobjcalApp` and talk back to it through this protocol, never through the
app's class, so no panel imports :mod:`webui.app` (the app imports the panels).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from numpy.typing import ArrayLike

if TYPE_CHECKING:
    import viser

    from calib.plan.file import Plan
    from planner.check import PointCheck
    from webui.backend import CellSession, CellView
    from webui.busy import BusyIndicator
    from webui.plan_doc import UiPlan
    from webui.robot_view import RobotView
    from webui.role_check import RoleFlags
    from webui.scene import PlanScene
    from webui.state import SessionState
    from webui.surface import SurfacePicker
    from webui.worker import CellWorker


class HeatMapControl(Protocol):
    """The heat map as the panels see it."""

    def stop(self) -> None:
        """Stop a heat map being computed (and keep what is drawn)."""


class AppContext(Protocol):
    """The app, as the panels see it.

    Attributes:
        server: the viser server (its ``gui`` and ``scene``).
        scene: what the app draws of the plan.
        state: the edited plan with undo/redo and autosave.
        worker: the one thread that owns the cell.
        plan_dir: folder the plan's relative file references resolve against.
        view: the cell's geometry (``None`` before a cell is loaded).
        picker: click-to-place on the work object (``None`` before a cell is loaded).
        robot: the robot drawn in the scene, or ``None``.
        selected: the selected point's id, or ``None``.
        busy: the busy indicator (``with app.busy("checking B"): ...``).
        flags: the points the procedure cannot use where they are (role or face), and why.
        click_mode: what a click on the 3D view does (a key of ``click_handlers``).
        click_handlers: ``{mode: handler(event)}`` of scene clicks; ``"place"`` places points.
    """

    server: viser.ViserServer
    scene: PlanScene
    state: SessionState[UiPlan]
    worker: CellWorker[CellSession | None]
    plan_dir: Path
    view: CellView | None
    picker: SurfacePicker | None
    robot: RobotView | None
    selected: str | None
    busy: BusyIndicator
    flags: RoleFlags
    click_mode: str
    click_handlers: dict[str, Any]

    def tab(self, name: str) -> Any:
        """The control panel's tab ``name`` (a context for a panel's widgets)."""

    @property
    def heatmap(self) -> HeatMapControl:
        """The reachability heat map."""

    def notify(
        self, title: str, body: str, client: viser.ClientHandle | None = None, error: bool = True
    ) -> None:
        """Show a notification to one tab, or to every tab when ``client`` is None."""

    def load_cell(self, plan: Plan, plan_dir: Path) -> None:
        """Build the plan's cell and redraw; raise (keeping the old cell) when it fails."""

    def replace_source(self, plan: Plan, label: str) -> None:
        """Make ``plan`` (another cell) the session's in one undoable step; raise (changing
        nothing) when its cell cannot be built."""

    def select(self, point_id: str | None) -> None:
        """Select a point (or none)."""

    def move_point_to(self, point_id: str, point_wobj: ArrayLike) -> PointCheck | None:
        """Move a point to the surface point nearest ``point_wobj`` (wobj frame, m)."""

    def show_reachability(self, n_samples: int = 1000) -> None:
        """Start the reachability heat map."""

    def check_of(self, point_id: str) -> PointCheck | None:
        """The latest check of a point, or ``None`` while it is being computed."""

    def checks(self) -> dict[str, PointCheck]:
        """The latest check of every point that has one."""
