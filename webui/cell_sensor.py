"""The Cell tab's **Sensor** folder: the sensor's kind and numbers, and the search speed.

**Sensor kind** (proximity sensor or touch probe), **Diameter (mm)** (the proximity sensor's
face, or the touch probe's ball), **Detection range (mm)** (the proximity sensor's nominal
sensing distance; a touch probe has none), **Noise 1σ (mm)** (the switching or trigger point's
scatter) and **Search speed (mm/s)**, which sets the speed of *every* point's search, are
applied together with **Apply sensor**: one undoable, autosaved step, after which every point
is checked again (the footprint on the face and the search's standoff follow the sensor).
Numbers beyond plausible (:data:`webui.cell_setup_edits.SENSOR_LIMITS`) are refused. The tool's
sensor TCP must be where the sensor switches: when the detection range is not the TCP's
distance from the tool's sensor face (:func:`planner.cell.scene.gap_mismatch`), the folder
says so in red, since every measured point would be off by the difference.
Picking another kind shows that kind's defaults (or the plan's, when it has that kind).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from calib.errors import InputError
from calib.models import SENSOR_KINDS, ProximitySensor, TouchProbe
from calib.plan.file import Plan
from webui.cell_setup_edits import SensorFields, sensor_fields, with_sensor
from webui.plan_doc import UiPlan

if TYPE_CHECKING:
    from webui.context import AppContext
    from webui.panel import Guard


def default_fields(kind: str, speed_mm_s: float | None) -> SensorFields:
    """The default sensor of ``kind`` as fields, with the search speed ``speed_mm_s``."""
    if kind == TouchProbe.KIND:
        t = TouchProbe()
        return SensorFields(
            kind, 1000.0 * t.tip_diameter_m, 0.0, 1000.0 * t.trigger_repeatability_sigma_m,
            speed_mm_s,
        )  # fmt: skip
    p = ProximitySensor()
    return SensorFields(
        kind, 1000.0 * p.face_diameter_m, 1000.0 * p.sensing_distance_m,
        1000.0 * p.repeatability_sigma_m, speed_mm_s,
    )  # fmt: skip


class SensorSection:
    """The Sensor folder of the Cell tab (shared by all tabs).

    Args:
        app: the app whose plan's sensor is edited.
        guard: the Cell panel's :meth:`webui.panel.Panel.guard`: runs an edit, a refusal told
            to the tab that acted.
    """

    def __init__(self, app: AppContext, guard: Guard) -> None:
        self._app = app
        self._shown: SensorFields | None = None  # what the fields were last set to
        gui = app.server.gui
        with gui.add_folder("Sensor"):
            self.kind = gui.add_dropdown("Sensor kind", SENSOR_KINDS)
            self.diameter = gui.add_number(
                "Diameter (mm)", 18.0, min=0.0, step=0.1,
                hint="the proximity sensor's face, or the touch probe's ball",
            )  # fmt: skip
            self.range = gui.add_number(
                "Detection range (mm)", 8.0, min=0.0, step=0.1,
                hint="the proximity sensor's nominal sensing distance (a touch probe has none)",
            )  # fmt: skip
            self.noise = gui.add_number(
                "Noise 1σ (mm)", 0.04, min=0.0, step=0.001,
                hint="1-sigma scatter of the switching (proximity) or trigger (touch) point",
            )  # fmt: skip
            self.speed = gui.add_number(
                "Search speed (mm/s)", 10.0, min=0.0, step=0.1,
                hint="applies to every point's search",
            )  # fmt: skip
            self.note = gui.add_markdown("")
            self.tcp_note = gui.add_markdown("")
            self.apply = gui.add_button("Apply sensor")
        self.kind.on_update(lambda ev: guard(ev, self._kind_chosen, ev))
        self.apply.on_click(lambda ev: guard(ev, self.apply_sensor))

    def _show(self, fields: SensorFields) -> None:
        self._shown = fields
        if self.kind.value != fields.kind:
            self.kind.value = fields.kind
        self.diameter.value = round(fields.diameter_mm, 6)
        self.range.value = round(fields.range_mm, 6)
        self.range.disabled = fields.kind == TouchProbe.KIND
        self.noise.value = round(fields.noise_mm, 6)
        if fields.speed_mm_s is not None:
            self.speed.value = round(fields.speed_mm_s, 6)

    def warn(self, why: str) -> None:
        """Say on the page why the sensor does not fit the tool's sensor TCP (``""``: it
        does): the measured points would be off by the difference."""
        text = f"**⚠ Sensor and tool disagree:** {why}." if why else ""
        if self.tcp_note.content != text:
            self.tcp_note.content = text

    def refresh(self, ui: UiPlan) -> None:
        """Show the plan's sensor and the points' search speed (only when they changed: numbers
        typed and not yet applied stay while points are edited)."""
        fields = sensor_fields(ui)
        speeds = {round(p.speed_m_s * 1000.0, 6) for p in ui.points}
        self.note.content = (
            "" if len(speeds) <= 1
            else f"The points search at {min(speeds):g}-{max(speeds):g} mm/s; a speed "
            "changed here sets them all."
        )  # fmt: skip
        if fields != self._shown:
            self._show(fields)

    def _kind_chosen(self, event: Any) -> None:
        """A user picked a kind: show the plan's numbers for it, or the kind's defaults."""
        if getattr(event, "client", None) is None:  # set by :meth:`refresh`
            return
        kind = str(self.kind.value)
        doc = self._app.state.doc
        if not isinstance(doc.source, Plan):
            return
        current = sensor_fields(doc)
        fields = current if current.kind == kind else default_fields(kind, current.speed_mm_s)
        shown = self._shown
        self._show(fields)
        self._shown = shown  # still what the plan has: a refresh must not undo the choice

    def fields(self) -> SensorFields:
        """The sensor the fields describe (the speed ``None`` when left as shown)."""
        speed: float | None = float(self.speed.value)
        shown = self._shown
        as_shown = (
            shown is not None
            and shown.speed_mm_s is not None
            and abs(float(self.speed.value) - round(shown.speed_mm_s, 6)) < 1e-9
        )
        if as_shown:
            speed = None  # left as shown: each point keeps its own speed
        return SensorFields(
            kind=str(self.kind.value),
            diameter_mm=float(self.diameter.value),
            range_mm=float(self.range.value),
            noise_mm=float(self.noise.value),
            speed_mm_s=speed,
        )

    def apply_sensor(self) -> None:
        """Make the fields the plan's sensor and search speed (one undoable step; nothing when
        they are already)."""
        doc = self._app.state.doc
        if not isinstance(doc.source, Plan):
            raise InputError("load a plan first: there is no sensor to set up")
        new = with_sensor(doc, self.fields())
        same_points = new.points == doc.points
        if same_points and new.source == doc.source:
            return
        self._app.state.update(lambda d: with_sensor(d, self.fields()), "sensor")
