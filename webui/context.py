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
    from planner.check.job import PointCheck
    from planner.program.cycle_time import CycleTime
    from webui.backend import CellSession, CellView
    from webui.busy import BusyIndicator
    from webui.plan_doc import UiPlan
    from webui.role_check import RoleFlags
    from webui.scene import PlanScene
    from webui.state import SessionState
    from webui.surface import SurfacePicker
    from webui.tab_robots import TabRobots
    from webui.worker import CellWorker


class HeatMapControl(Protocol):
    """The heat map as the panels see it."""

    def stop(self) -> None:
        """Stop a heat map being computed (and keep what is drawn)."""


class SelectionControl(Protocol):
    """Each tab's selection as the panels see it (:class:`webui.tab_selection.Selections`)."""

    def of(self, client_id: int | None) -> str | None:
        """The point tab ``client_id`` has selected (``None``: the latest anywhere)."""


class UploadStore(Protocol):
    """Where the session keeps uploaded files (:class:`webui.files_panel.FilesPanel`): the
    folder, the folders this session created, and the file references its plans still use."""

    upload_dir: Path
    created: set[Path]

    def in_use(self) -> list[str]:
        """The file references of the session's plans (undo history included)."""
        ...


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
        robot: the robot drawn in every tab (each at its own pose), or ``None``.
        selected: the latest point selected in any tab or by a script, or ``None``.
        selection: each tab's selected point (:mod:`webui.tab_selection`).
        busy: the busy indicator (``with app.busy("checking B"): ...``).
        flags: the points the procedure cannot use where they are (role or face), and why.
        click_mode: what a click on the 3D view does (a key of ``click_handlers``).
        click_handlers: ``{mode: handler(event)}`` of scene clicks; ``"place"`` places points.
        cycle: the estimated cycle time of the plan as edited (``None``: not known yet).
        files_panel: the Files panel, which owns the upload folder (tool and fixture uploads
            of the Cell tab are kept there too; built after the Cell tab, used on upload).
    """

    server: viser.ViserServer
    scene: PlanScene
    state: SessionState[UiPlan]
    worker: CellWorker[CellSession | None]
    plan_dir: Path
    view: CellView | None
    picker: SurfacePicker | None
    robot: TabRobots | None
    busy: BusyIndicator
    flags: RoleFlags
    click_mode: str
    click_handlers: dict[str, Any]
    cycle: CycleTime | None

    @property
    def files_panel(self) -> UploadStore:
        """The Files panel, which owns the upload folder (the Cell tab keeps its uploads there)."""
        ...

    def tab(self, name: str) -> Any:
        """The control panel's tab ``name`` (a context for a panel's widgets)."""

    @property
    def selection(self) -> SelectionControl:
        """Each tab's selected point."""

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

    @property
    def selected(self) -> str | None:
        """The latest point selected in any tab or by a script."""

    def selection_of(self, client: viser.ClientHandle | None) -> str | None:
        """The point the tab of ``client`` has selected (``None``: the latest anywhere)."""

    def select(self, point_id: str | None, client: viser.ClientHandle | None = None) -> None:
        """Select a point (or none) in the tab of ``client``, or in every tab (``None``)."""

    def robot_to_selected(self, client: viser.ClientHandle | None = None) -> None:
        """Show the robot of the tab of ``client`` (every tab: ``None``) at its selected
        point's probe pose; raise ``InputError`` saying why not."""

    def place_at_ray(
        self,
        origin_world: ArrayLike,
        direction_world: ArrayLike,
        point_id: str | None = None,
        client: viser.ClientHandle | None = None,
    ) -> PointCheck | None:
        """Put a point where a ray (world) hits the work object, selected in ``client``'s tab."""

    def move_point_to(self, point_id: str, point_wobj: ArrayLike) -> PointCheck | None:
        """Move a point to the surface point nearest ``point_wobj`` (wobj frame, m)."""

    def show_reachability(self, n_samples: int = 1000) -> None:
        """Start the reachability heat map."""

    def check_of(self, point_id: str) -> PointCheck | None:
        """The latest check of a point, or ``None`` while it is being computed."""

    def checks(self) -> dict[str, PointCheck]:
        """The latest check of every point that has one."""
