"""The "Calibrate" panel: upload points measured on the robot, see the calibrated WOCS frame.

Thin over ``planner.calibrate.job.calibrate_plan`` (what ``wobjcal calibrate`` runs): the
calibrated frame is drawn beside the nominal one, with the shift, 1 sigma per degree of freedom
and the residual per point. A result the gross-error screen does not trust (a point off its
face beyond the plan's noise, a frame beyond the misplacement bound) is not drawn: the panel
lists the problems and names the point to re-measure, as ``wobjcal calibrate`` does on stderr.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from calib.errors import InputError
from calib.frames import motion_between
from calib.plan.measurements import measurements_from_json
from planner.calibrate.job import CalibrationOutput, calibrate_plan
from planner.plan_cell import plan_controller_base
from webui.files_panel import check_upload
from webui.panel import Panel
from webui.plan_adapter import plan_from_ui

if TYPE_CHECKING:
    from webui.context import AppContext


class CalibratePanel(Panel):
    """GUI widgets of the calibration from measured points (a folder of the Files tab).

    Args:
        app: the app whose plan the measurements belong to.
    """

    TAB = "Files"
    REFUSED = "Not calibrated"
    ACTION = "calibration"

    def __init__(self, app: AppContext) -> None:
        super().__init__(app)
        self.last_output: CalibrationOutput | None = None
        gui = app.server.gui
        with app.tab(self.TAB), gui.add_folder("Calibrate", expand_by_default=False):
            self.upload = gui.add_upload_button("Upload measurements (.json)", mime_type=".json")
            self.result_md = gui.add_markdown(
                "Upload a `wobjcal.measurements/1` file to compute the calibrated frame."
            )
        self.upload.on_upload(
            lambda ev: self.guard(ev, self.calibrate, ev.target.value.name, ev.target.value.content)
        )

    def calibrate(self, name: str, content: bytes) -> CalibrationOutput:
        """Calibrate the session plan with uploaded measurements; draw and describe the result."""
        check_upload(name, content, (".json",), "measurements file")
        try:
            text = content.decode("utf-8")
        except UnicodeDecodeError:
            raise InputError(f"{name}: not UTF-8 text, so not a measurements file") from None
        measurements = measurements_from_json(text, source=name)
        plan = plan_from_ui(self._app.state.doc)
        # base-frame measurements are the controller's: its base frame, which may not be the
        # robot's base link (a UR arm's is turned 180 deg about z)
        base = plan_controller_base(plan, self._app.plan_dir)
        out = calibrate_plan(plan, measurements, T_base_controller=base.T_base_controller)
        self.last_output = out
        delta = motion_between(out.T_base_wobj_nominal, out.T_base_wobj)
        rows = [f"**{out.method}** with {len(out.used_ids)} points", ""]
        if not out.trusted:
            rows += ["**NOT TRUSTED, frame not drawn:**", ""]
            rows += [f"- {problem}" for problem in out.problems]
            rows.append("")
        rows += [f"- note: {note}" for note in out.notes]
        rows += [""] if out.notes else []  # the list ends before the next paragraph
        rows += [
            f"shift from nominal: {np.round(delta[:3] * 1000.0, 3).tolist()} mm, "
            f"{np.round(np.degrees(delta[3:]), 4).tolist()} deg (wobj axes)",
            "",
        ]
        sd = out.sigma_dof
        if sd is not None:
            rows += [
                f"1 sigma: {np.round(sd[:3] * 1000.0, 3).tolist()} mm, "
                f"{np.round(np.degrees(sd[3:]), 4).tolist()} deg",
                "",
            ]
        rows += ["| point | residual (mm) |", "|---|---|"]
        for pid, r in out.residuals_m.items():
            rows.append(f"| {pid} | {r * 1000.0:+.3f} |")
        self.result_md.content = "\n".join(rows)
        # the outcome is every tab's (the frame is drawn, or removed, in the shared scene)
        if not out.trusted:
            self._app.scene.draw_calibrated_frame(None)
            self._app.notify("Calibration not trusted", " ".join(out.problems), error=True)
            return out
        T_world_base = plan.cell.robot.T_world_base.matrix()
        self._app.scene.draw_calibrated_frame(T_world_base @ out.T_base_wobj)
        self._app.notify("Calibrated", f"{name}: calibrated frame drawn", error=False)
        return out
