"""The "Validate" panel: Monte Carlo validation of any plan with a progress bar, the report's
rows (simulated beside predicted), histograms, and the simulated error painted on the part.

The report opens in its own wide window ("Validation report", floating over the 3D view,
wide enough for the Table-1 rows; "Show report window" hides or shows it), with one
histogram per row on a value axis in the row's unit (mm or deg). When the plan changes after
a validation, the report is marked stale at once.

Validation runs on its own thread (:class:`webui.worker.CellWorker` without a shared resource),
not on the cell worker: point checks from any tab stay fast while it runs. Whatever simulator
state ``planner.sim.montecarlo`` needs it builds itself, inside that thread. A plan that cannot
be validated is refused before anything runs, with the point and the reason in a notification.
"""

from __future__ import annotations

import dataclasses
import logging
import os
import threading
import time
from concurrent.futures import Future
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from calib.errors import InputError, PlanError
from planner.sim.budget import check_run_size, run_size
from planner.sim.report import ValidationReport
from planner.validate.job import check_simulatable
from webui import validation
from webui.panel import Panel
from webui.plan_adapter import plan_from_ui
from webui.worker import CellWorker

if TYPE_CHECKING:
    from webui.context import AppContext

logger = logging.getLogger(__name__)

#: Size of the report window, px: the Table-1 rows (simulated, predicted, bias, the paper)
#: fit without cutting.
REPORT_WIDTH_PX = 640
REPORT_HEIGHT_PX = 560


class ValidatePanel(Panel):
    """GUI widgets of the validation, shared by all tabs.

    Args:
        app: the app whose plan is validated.
    """

    TAB = "Validate"
    REFUSED = "Validation not started"
    ACTION = "validation"

    def __init__(self, app: AppContext) -> None:
        super().__init__(app)
        self._worker: CellWorker[None] = CellWorker(None, name="wobjcal-validate")
        self._running = threading.Event()
        self._start_lock = threading.Lock()
        self.last_report: ValidationReport | None = None
        self.last_markdown = ""
        #: Why the shown report no longer fits the plan (``""``: it does).
        self.stale = ""
        gui = app.server.gui
        with app.tab(self.TAB):
            self.trials = gui.add_number("Trials", 200, min=10, max=100000, step=10)
            self.button = gui.add_button("Validate plan", color="blue")
            self.progress = gui.add_progress_bar(0.0, visible=False, animated=True)
            self.status_md = gui.add_markdown("")
            self.show_report = gui.add_checkbox("Show report window", False, disabled=True)
            self.show_error = gui.add_checkbox("Show error on part", False, disabled=True)
            self.error_md = gui.add_markdown("")
        self.report_window = gui.add_panel(visible=False)
        with self.report_window.add_tab("Validation report"):
            self.stale_md = gui.add_markdown("")
            self.result_md = gui.add_markdown("")
            self._plots_folder = gui.add_folder("Histograms", expand_by_default=True)
        # floating over the 3D view's top-left corner: wide enough for the whole table next to
        # the control panel docked on the right, also in a 1100 px window
        self.report_window.float(x=12, y=12, width=REPORT_WIDTH_PX, height=REPORT_HEIGHT_PX)
        self.plots: list[Any] = []
        self.button.on_click(lambda ev: self.guard(ev, self.start, int(self.trials.value)))
        self.show_error.on_update(self._on_show_error)
        self.show_report.on_update(lambda _ev: self._show_window(bool(self.show_report.value)))
        app.state.subscribe(self._on_plan_change)

    def start(self, trials: int) -> Future[validation.ValidationSummary]:
        """Start a validation of the session plan; return a future of the report.

        Raises:
            InputError: a validation is already running, or the plan is incomplete or cannot
                be simulated (:class:`calib.plan.file.PlanError` naming the field).
        """
        plan = plan_from_ui(self._app.state.doc)
        check_simulatable(plan)
        view = self._app.view
        size = run_size(plan, trials)  # this server and the run within 2 GB (issue 27)
        faces = 0 if view is None else len(view.wobj_mesh.faces)
        check_run_size(dataclasses.replace(size, triangles=faces, held_bytes=_rss_bytes()))
        with self._start_lock:  # two tabs may click at once
            if self._running.is_set():
                raise InputError("a validation is already running")
            self._running.set()
        self.button.disabled = True
        self.progress.value = 0.0
        self.progress.visible = True
        self.status_md.content = f"Running {trials} trials..."
        last = [0.0]

        def progress(done: int, total: int) -> None:
            now = time.monotonic()
            if now - last[0] > 0.1 or done == total:  # at most 10 updates a second
                last[0] = now
                self.progress.value = 100.0 * done / max(total, 1)

        plan_dir = self._app.plan_dir

        def job(_res: None) -> validation.ValidationSummary:
            return validation.run_validation(plan, trials, progress, plan_dir)

        fut = self._worker.submit(job)
        fut.add_done_callback(self._done)
        return fut

    def _done(self, fut: Future[validation.ValidationSummary]) -> None:
        try:
            self._show(fut)
        finally:  # only now is the validation over for whoever watches `running`
            self.progress.visible = False
            self.button.disabled = False
            self._running.clear()

    def _show(self, fut: Future[validation.ValidationSummary]) -> None:
        # the run's outcome, failure included, is every tab's: its report is shown to all
        try:
            summary = fut.result()
        except PlanError as exc:  # refused before any trial ran: the point and why
            self.status_md.content = f"**Validation not started:** {exc}"
            self._app.notify("Validation not started", str(exc))
            return
        except Exception as exc:
            logger.exception("validation failed")
            self.status_md.content = f"**Validation failed:** {exc}"
            self._app.notify("Validation failed", str(exc))
            return
        self.last_report = summary.report
        self.last_markdown = summary.markdown
        self.stale = ""
        self.stale_md.content = ""
        self.status_md.content = f"{summary.headline}; the report is in its own window."
        self.result_md.content = summary.markdown
        self.show_error.disabled = summary.report.error_map is None
        self.paint_error()
        for plot in self.plots:
            plot.remove()
        self.plots = []
        gui = self._app.server.gui
        with self._plots_folder:
            for title, unit, edges, counts in summary.histograms:
                self._add_plot(gui, title, unit, edges, counts)
        self.show_report.disabled = False
        self._show_window(True)
        if summary.T_world_wobj_example is not None:
            self._app.scene.draw_calibrated_frame(summary.T_world_wobj_example)
        self._app.notify("Validation done", summary.headline, error=False)

    def _add_plot(self, gui: Any, title: str, unit: str, edges: Any, counts: Any) -> None:
        """One histogram: bin centres on a value axis (not uPlot's default time axis) in
        ``unit``, sample counts up."""
        centers = 0.5 * (np.asarray(edges[:-1], float) + np.asarray(edges[1:], float))
        self.plots.append(
            gui.add_uplot(
                data=(centers, np.asarray(counts, dtype=np.float64)),
                series=(
                    {"label": f"error ({unit})"},
                    {"label": "samples", "stroke": "steelblue", "fill": "rgba(70,130,180,0.3)"},
                ),
                scales={"x": {"time": False}},
                axes=({"label": f"error ({unit})"}, {"label": "samples", "size": 60}),
                title=title,
                aspect=2.2,
            )
        )

    def _show_window(self, visible: bool) -> None:
        """Show or hide the report window (the box in the tab follows)."""
        self.report_window.visible = visible and self.last_report is not None
        if bool(self.show_report.value) != self.report_window.visible:
            self.show_report.value = self.report_window.visible

    def _on_plan_change(self, change: Any) -> None:
        """Mark the shown report stale when the plan changes after it was made."""
        if self.last_report is None or self.stale:
            return
        self.stale = f"the plan changed after this validation ({change.label})"
        self.stale_md.content = f"**Stale:** {self.stale}; validate again for current figures."
        self.status_md.content = f"**Stale report:** {self.stale}."

    def _on_show_error(self, _event: Any) -> None:
        self.paint_error()

    def paint_error(self) -> bool:
        """Paint the last report's simulated error on the work object while the box is ticked
        (green: the part's smallest error, red: its largest); clear it otherwise.

        Returns:
            True when a map is shown.
        """
        view = self._app.view
        report = self.last_report
        if not self.show_error.value or view is None or report is None:
            self._app.scene.color_work_object(None, layer="error")
            self.error_md.content = ""
            return False
        colours = validation.error_colours(report, view.wobj_mesh)
        if colours is None:
            return False
        rgb, lo, hi = colours
        self._app.scene.color_work_object(rgb, layer="error")
        level = report.error_map.level_percent if report.error_map else 95.5
        self.error_md.content = (
            f"{level:g} % of calibrations place each point within: green {lo * 1e3:.2f} mm "
            f"to red {hi * 1e3:.2f} mm"
        )
        return True

    @property
    def running(self) -> bool:
        """True while a validation runs."""
        return self._running.is_set()

    def close(self) -> None:
        """Stop the validation thread (after a running validation)."""
        self._worker.close(timeout=1.0)


def _rss_bytes() -> int:
    """This process's resident memory, bytes (0 where ``/proc`` is not there)."""
    try:
        pages = int(Path("/proc/self/statm").read_text().split()[1])
        return pages * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0
