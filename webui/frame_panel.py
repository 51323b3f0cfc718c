"""The work-object frame by three points, in the Cell tab, as a controller's 3-point user
frame: click the origin, a point on +x and a point in the xy-plane (+y side) on the part.

The frame is :func:`calib.user_frame.three_point_frame` of the three surface points; the plan
is re-expressed in it (:func:`webui.cell_edits.reframed`: points, the work object's cell pose
and ``work_object.T_wobj_mesh``), so nothing moves in the world; its cell is built first, then
the session changes in one undoable, autosaved step. A click that misses the part, or a point
that coincides with or lies on a line with the ones before, is refused with a message and the
panel waits for that point again.

While the points are picked, each pick is a dot (red origin, green +x, blue xy-plane) and, once
the origin and +x are picked, the frame they define is drawn as a triad at the origin
(:func:`preview_frame`: x towards the +x point, z out of the face clicked at the origin, y = z
cross x; red, green, blue): a third point on its green (+y) side keeps that z. The triad goes when
the frame is applied (the work object's own axes then show it) or the mode is cancelled.
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
from webui.panel import Panel
from webui.scene import pose_kwargs

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
#: The preview triad's axes: this share of the part's largest extent, within the bounds, m.
TRIAD_SHARE = 0.25
TRIAD_MIN_M, TRIAD_MAX_M = 0.03, 0.3
#: Scene node of the preview triad.
TRIAD_NODE = "/frame3/triad"


def preview_frame(
    origin_wobj: ArrayLike, x_point_wobj: ArrayLike, origin_normal_wobj: ArrayLike
) -> NDArray[np.float64] | None:
    """``(4, 4)`` the frame the 3-point method gives, wobj frame (m), for a third point on the
    face clicked at the origin, on the +y side: x from the origin to ``x_point_wobj``, z the
    origin's face normal made perpendicular to x, y = z cross x. ``None`` when the normal runs
    along x (the third point alone decides z then)."""
    o = np.asarray(origin_wobj, dtype=np.float64).reshape(3)
    x = np.asarray(x_point_wobj, dtype=np.float64).reshape(3) - o
    n = np.asarray(origin_normal_wobj, dtype=np.float64).reshape(3)
    if float(np.linalg.norm(x)) < MIN_SEPARATION_M:
        return None
    x = x / np.linalg.norm(x)
    z = n - float(n @ x) * x
    if float(np.linalg.norm(z)) < 1e-6:
        return None
    z = z / np.linalg.norm(z)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, o
    return T


class FramePanel(Panel):
    """The "Define frame by 3 points" widgets (in the Cell tab) and their click mode.

    Args:
        app: the app whose work-object frame is defined.
    """

    TAB = "Cell"
    REFUSED = "Frame not changed"
    ACTION = "3-point frame"

    def __init__(self, app: AppContext) -> None:
        super().__init__(app)
        #: The points picked so far, wobj frame (the frame before the new one), m.
        self.picked: list[NDArray[np.float64]] = []
        #: The face normal at the picked origin, wobj frame (``None``: not picked yet).
        self.origin_normal: NDArray[np.float64] | None = None
        #: The preview triad drawn (wobj frame), or ``None``.
        self.triad: NDArray[np.float64] | None = None
        gui = app.server.gui
        with app.tab(self.TAB):
            self.start = gui.add_button("Define frame by 3 points")
            self.cancel = gui.add_button("Cancel 3-point frame", visible=False)
            self.status = gui.add_markdown("")
        self.start.on_click(lambda ev: self.guard(ev, self.begin))
        self.cancel.on_click(lambda ev: self.guard(ev, self.stop))
        app.click_handlers[MODE] = self._on_click

    def begin(self) -> None:
        """Start picking: the next clicks on the part are the origin, +x, the xy-plane."""
        if not isinstance(self._app.state.doc.source, Plan) or self._app.picker is None:
            raise InputError("load a plan first: there is no work object to give a frame")
        self.picked, self.origin_normal = [], None
        self._app.click_mode = MODE
        self.start.visible, self.cancel.visible = False, True
        self._show()

    def stop(self) -> None:
        """Leave the 3-point mode without changing anything; clicks place points again."""
        self.picked, self.origin_normal = [], None
        if self._app.click_mode == MODE:
            self._app.click_mode = "place"
        self.start.visible, self.cancel.visible = True, False
        self._show()

    def _show(self) -> None:
        scene = self._app.server.scene
        view = self._app.view
        for i in range(3):
            scene.remove_by_name(f"/frame3/p{i}")
        scene.remove_by_name(TRIAD_NODE)
        self.triad = None
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
                radius=0.008,
                color=colours[i],
                position=tuple(transform_points(view.T_world_wobj, p)),
            )
        if len(self.picked) == 2 and self.origin_normal is not None:
            self.triad = preview_frame(self.picked[0], self.picked[1], self.origin_normal)
        if self.triad is not None:
            size = float(np.max(view.wobj_mesh.extents)) * TRIAD_SHARE
            T = view.T_world_wobj @ self.triad
            scene.add_frame(
                TRIAD_NODE, axes_length=float(np.clip(size, TRIAD_MIN_M, TRIAD_MAX_M)),
                axes_radius=0.005, origin_radius=0.008, **pose_kwargs(T),
            )  # fmt: skip
            self.status.content += (
                " The triad shows the frame (x red, y green, z blue): click the third point "
                "on its green (+y) side to keep this z."
            )

    def _on_click(self, event: Any) -> None:
        picker = self._app.picker
        hit = None if picker is None else picker.pick(event.ray_origin, event.ray_direction)
        if hit is None:
            raise InputError(
                f"3-point frame: the click missed the work object; click {STEPS[len(self.picked)]}"
                " on the part (or Cancel 3-point frame in the Cell tab)"
            )
        self.pick(hit.position_wobj, hit.normal_wobj)

    def pick(self, point_wobj: ArrayLike, normal_wobj: ArrayLike | None = None) -> None:
        """Take the next of the three points (wobj frame, m); the third defines the frame.
        ``normal_wobj``: the face normal there (default: of the nearest surface point), which
        the preview triad takes as z at the origin.

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
            if not self.picked:
                self.origin_normal = self._normal_at(p, normal_wobj)
            self.picked.append(p)
            self._show()
            return
        try:
            T_old_new = three_point_frame(self.picked[0], self.picked[1], p)
        except InputError as exc:
            raise InputError(f"3-point frame: {exc}") from None
        self.apply(T_old_new)
        self.stop()

    def _normal_at(
        self, p: NDArray[np.float64], normal_wobj: ArrayLike | None
    ) -> NDArray[np.float64] | None:
        if normal_wobj is not None:
            return np.asarray(normal_wobj, dtype=np.float64).reshape(3)
        picker = self._app.picker
        return None if picker is None else picker.project(p).normal_wobj

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
