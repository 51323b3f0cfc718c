"""The work-object frame by three points, in the Cell tab, as a controller's 3-point user
frame: click the origin, a point on +x and a point in the xy-plane (+y side) on the part.

The frame is :func:`calib.user_frame.three_point_frame` of the three surface points; the plan
is re-expressed in it (:func:`webui.cell_edits.reframed`: points, the work object's cell pose
and ``work_object.T_wobj_mesh``), so nothing moves in the world; its cell is built first, then
the session changes in one undoable, autosaved step. A click that misses the part, or a point
that coincides with or lies on a line with the ones before, is refused with a message and the
panel waits for that point again.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.errors import InputError
from calib.frames import transform_points
from calib.plan.file import Plan
from calib.user_frame import MIN_SEPARATION_M, three_point_frame
from webui import cell_edits

if TYPE_CHECKING:
    from webui.context import AppContext

logger = logging.getLogger(__name__)

#: The app's click mode while the three points are picked.
MODE = "frame3"
#: What each click picks, in order.
STEPS = ("the origin", "a point on +x", "a point in the xy-plane (+y side)")
LABEL = "define the work-object frame (3 points)"
#: The frame's z axis is looked along from this far above its origin (off the surface), m ...
Z_START_M = 0.0005
#: ... for this far: the part or a fixture met within it means z points into it, m.
Z_LOOK_M = 0.5


class FramePanel:
    """The "Define frame by 3 points" widgets (in the Cell tab) and their click mode.

    Args:
        app: the app whose work-object frame is defined.
    """

    def __init__(self, app: AppContext) -> None:
        self._app = app
        #: The points picked so far, wobj frame (the frame before the new one), m.
        self.picked: list[NDArray[np.float64]] = []
        gui = app.server.gui
        with app.tab("Cell"):
            self.start = gui.add_button("Define frame by 3 points")
            self.cancel = gui.add_button("Cancel 3-point frame", visible=False)
            self.status = gui.add_markdown("")
        self.start.on_click(lambda ev: self._guard(ev, self.begin))
        self.cancel.on_click(lambda ev: self._guard(ev, self.stop))
        app.click_handlers[MODE] = self._on_click

    def _guard(self, event: Any, fn: Any, *args: Any) -> None:
        try:
            fn(*args)
        except InputError as exc:
            self._app.notify("Frame not changed", str(exc), client=getattr(event, "client", None))
        except Exception as exc:  # never a traceback in the browser
            logger.exception("3-point frame failed")
            self._app.notify("Frame not changed", f"{type(exc).__name__}: {exc}")

    def begin(self) -> None:
        """Start picking: the next clicks on the part are the origin, +x, the xy-plane."""
        if not isinstance(self._app.state.doc.source, Plan) or self._app.picker is None:
            raise InputError("load a plan first: there is no work object to give a frame")
        self.picked = []
        self._app.click_mode = MODE
        self.start.visible, self.cancel.visible = False, True
        self._show()

    def stop(self) -> None:
        """Leave the 3-point mode without changing anything; clicks place points again."""
        self.picked = []
        if self._app.click_mode == MODE:
            self._app.click_mode = "place"
        self.start.visible, self.cancel.visible = True, False
        self._show()

    def _show(self) -> None:
        scene = self._app.server.scene
        view = self._app.view
        for i in range(3):
            scene.remove_by_name(f"/frame3/p{i}")
        if self._app.click_mode != MODE:
            self.status.content = ""
            return
        self.status.content = f"3-point frame: click {STEPS[len(self.picked)]} on the part."
        if view is None:
            return
        colours = ((230, 60, 60), (60, 200, 60), (60, 60, 230))  # origin, +x, xy-plane
        for i, p in enumerate(self.picked):
            scene.add_icosphere(
                f"/frame3/p{i}",
                radius=0.006,
                color=colours[i],
                position=tuple(transform_points(view.T_world_wobj, p)),
            )

    def _on_click(self, event: Any) -> None:
        picker = self._app.picker
        hit = None if picker is None else picker.pick(event.ray_origin, event.ray_direction)
        if hit is None:
            raise InputError(
                f"3-point frame: the click missed the work object; click {STEPS[len(self.picked)]}"
                " on the part (or Cancel 3-point frame in the Cell tab)"
            )
        self.pick(hit.position_wobj)

    def pick(self, point_wobj: ArrayLike) -> None:
        """Take the next of the three points (wobj frame, m); the third defines the frame.

        Raises:
            InputError: not in the 3-point mode, or the point coincides with or is collinear
                with the ones before (the panel then waits for that point again).
        """
        if self._app.click_mode != MODE:
            raise InputError("click Define frame by 3 points first")
        p = np.asarray(point_wobj, dtype=np.float64).reshape(3)
        for name, q in zip(STEPS, self.picked, strict=False):
            d = float(np.linalg.norm(p - q))
            if d < MIN_SEPARATION_M:
                raise InputError(
                    f"3-point frame: {STEPS[len(self.picked)]} coincides with {name} "
                    f"({d * 1000:.3f} mm apart); click {STEPS[len(self.picked)]} again"
                )
        if len(self.picked) < 2:
            self.picked.append(p)
            self._show()
            return
        try:
            T_old_new = three_point_frame(self.picked[0], self.picked[1], p)
        except InputError as exc:
            raise InputError(f"3-point frame: {exc}") from None
        self.apply(T_old_new)
        self.stop()

    def apply(self, T_old_new: ArrayLike) -> None:
        """Make ``T_old_new`` (the new frame in the current one) the work-object frame: one
        undoable, autosaved step; the cell is built first and nothing changes if that fails."""
        app = self._app
        source = cell_edits.reframed(app.state.doc, T_old_new).source
        if not isinstance(source, Plan):
            raise InputError("load a plan first: there is no work object to give a frame")
        app.load_cell(source, app.plan_dir)
        app.state.update(lambda d: cell_edits.reframed(d, T_old_new), LABEL)
        into = self.z_points_into()
        if into:
            app.notify(
                "Frame z points into " + into,
                f"the new work-object frame's z axis points into {into}: programs and plans "
                "usually take z out of the part. Pick the +x and xy-plane points the other "
                "way round to turn z over (undo first)",
            )

    def z_points_into(self) -> str:
        """What the work-object frame's +z axis runs into within :data:`Z_LOOK_M` of its
        origin (``"the work object"``, ``"the fixture table"``), or ``""`` when nothing: a
        frame picked the wrong way round has z into the part."""
        view = self._app.view
        if view is None:
            return ""
        T = np.asarray(view.T_world_wobj, dtype=np.float64)
        z = T[:3, 2]
        origin = T[:3, 3] + Z_START_M * z
        hit = self._app.worker.call(lambda s: None if s is None else s.first_hit(origin, z, None))
        if hit is None or hit.kind not in ("work object", "fixture") or hit.distance_m > Z_LOOK_M:
            return ""
        return "the work object" if hit.kind == "work object" else f"the fixture {hit.name}"
