"""Per-browser-tab things: the camera (first view framed on the cell, view buttons) and
notifications.

The first view of every tab, and the view after a new part is loaded, frames the work object
with the robot in view, whatever the part's size and place (:func:`framed_camera`). The view
buttons (:data:`VIEWS`) look from the front, the top or the side, or fit the cell from where the
camera is now; each moves only the camera of the tab whose button was pressed.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

import numpy as np
import viser
from numpy.typing import ArrayLike, NDArray

from calib.frames import transform_points
from webui.backend import CellView

logger = logging.getLogger(__name__)

#: View directions (world, from the camera towards the cell) of the view buttons; ``Fit``
#: keeps the tab's current direction. ``Iso`` is the first view.
VIEWS: dict[str, tuple[float, float, float] | None] = {
    "Fit": None,
    "Front": (0.0, 1.0, -0.15),
    "Top": (0.0, 0.02, -1.0),
    "Side": (-1.0, 0.0, -0.15),
}
ISO_DIRECTION = (0.25, 0.9, -0.45)
#: The part's share of the camera's focus: the view centres on the part, pulled this far
#: towards the robot (0: the part's centre, 1: the middle of part and robot).
ROBOT_PULL = 0.25
#: Share of the view's width and height the cell may use, centred (a margin around it).
WIDTH_SHARE = 0.85
#: Robot points are spheres of this radius in the framing (the links' size), m.
ROBOT_RADIUS_M = 0.25
#: Default vertical field of view of a tab, rad (viser's default).
DEFAULT_FOV = float(np.radians(75.0))
#: Notifications of successes close after this long, s; errors stay until closed.
OK_SECONDS = 8.0


def cell_points(view: CellView) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The points the view must hold (world, m): the part's bounding-box corners, and the
    robot's base and joint origins at zero joint values (clipped into the limits)."""
    lo, hi = view.wobj_mesh.bounds
    corners = np.array(
        [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    )
    part = transform_points(view.T_world_wobj, corners)
    robot = [view.T_world_base[:3, 3]]
    if view.chain is not None:
        q0 = np.clip(np.zeros(view.chain.n_joints), view.chain.lower, view.chain.upper)
        frames = np.asarray(view.chain.joint_frames(q0[None]))[0]
        robot.extend(transform_points(view.T_world_base, frames[:, :3, 3]))
    return part, np.asarray(robot, dtype=np.float64)


def framed_camera(
    view: CellView,
    direction: ArrayLike = ISO_DIRECTION,
    fov: float = DEFAULT_FOV,
    aspect: float = 1.5,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Camera ``(position, look_at)`` (world, m) looking along ``direction`` at the part, far
    enough back that the part and the robot (base and joint origins, each with
    :data:`ROBOT_RADIUS_M` around it) are all inside the middle :data:`WIDTH_SHARE` of the
    view. The camera orbits about the part (pulled :data:`ROBOT_PULL` towards the robot).

    Args:
        view: the cell's geometry.
        direction: from the camera towards the cell (world); need not be unit length.
        fov: the camera's vertical field of view, rad.
        aspect: width / height of the view.
    """
    part, robot = cell_points(view)
    centre = 0.5 * (part.min(axis=0) + part.max(axis=0))
    look_at = centre + ROBOT_PULL * (robot.mean(axis=0) - centre)
    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    up = np.array([0.0, 0.0, 1.0])
    right = np.cross(d, up)
    if np.linalg.norm(right) < 1e-6:
        right = np.array([1.0, 0.0, 0.0])
    right /= np.linalg.norm(right)
    cam_up = np.cross(right, d)
    tan_v = np.tan(0.5 * fov) * WIDTH_SHARE
    tan_h = np.tan(0.5 * fov) * aspect * WIDTH_SHARE
    distance = 0.3
    radius = np.r_[np.zeros(len(part)), np.full(len(robot), ROBOT_RADIUS_M)]
    for p, r in zip(np.vstack([part, robot]), radius, strict=True):
        rel = p - look_at
        along = float(rel @ d)
        need = max((abs(float(rel @ right)) + r) / tan_h, (abs(float(rel @ cam_up)) + r) / tan_v)
        distance = max(distance, need - along + r)
    return look_at - distance * d, look_at


def frame_client(client: viser.ClientHandle, view: CellView, direction: ArrayLike | None) -> None:
    """Point one tab's camera at the cell along ``direction`` (``None``: its current one)."""
    cam = client.camera
    if direction is None:
        current = np.asarray(cam.look_at, float) - np.asarray(cam.position, float)
        direction = current if np.linalg.norm(current) > 1e-9 else ISO_DIRECTION
    fov = float(cam.fov) if np.isfinite(cam.fov) and cam.fov > 0 else DEFAULT_FOV
    aspect = cam.image_width / cam.image_height if cam.image_height else 1.5
    position, look_at = framed_camera(view, direction, fov, aspect)
    with client.atomic():
        cam.up_direction = (0.0, 0.0, 1.0)
        cam.position = (float(position[0]), float(position[1]), float(position[2]))
        cam.look_at = (float(look_at[0]), float(look_at[1]), float(look_at[2]))


def set_default_camera(client: viser.ClientHandle, view: CellView) -> None:
    """The first view of a newly connected tab: framed on the part, the robot in view."""
    frame_client(client, view, ISO_DIRECTION)


def notify(
    server: viser.ViserServer,
    title: str,
    body: str,
    client: viser.ClientHandle | None = None,
    error: bool = True,
) -> None:
    """Show a notification to one tab, or to every tab when ``client`` is None.

    Errors stay until the user closes them; other notifications close after
    :data:`OK_SECONDS`.
    """
    logger.info("%s: %s", title, body)
    clients = [client] if client is not None else list(server.get_clients().values())
    for c in clients:
        c.add_notification(
            title,
            body,
            color="red" if error else "green",
            with_close_button=True,
            auto_close_seconds=None if error else OK_SECONDS,
        )


def add_view_bar(
    server: viser.ViserServer,
    view_of: Callable[[], CellView | None],
    notify: Callable[..., None],
    on_robot_display: Callable[[str], None] | None = None,
) -> None:
    """The view buttons (front, top, side, fit: each tab's own camera), the robot's display
    (shown, ghost, hidden: ``on_robot_display(display)``) and the colour legend.

    Args:
        server: the server whose control panel gets them.
        view_of: the cell's current geometry (``None`` before a cell is loaded).
        notify: ``notify(title, body, client=...)``: tells the tab why a button did nothing.
    """
    from webui.scene import legend_html

    gui = server.gui
    bar = gui.add_button_group("View", tuple(VIEWS))

    def on_click(event: Any) -> None:
        view = view_of()
        if view is None:
            notify("View not changed", "no cell is loaded yet", client=event.client)
            return
        frame_client(event.client, view, VIEWS[str(event.target.value)])

    bar.on_click(on_click)
    if on_robot_display is not None:
        from webui.robot_view import DISPLAYS

        robot = gui.add_dropdown(
            "Robot",
            DISPLAYS,
            initial_value="shown",
            hint="ghost: translucent, hidden: not drawn; either way clicks go through it to the "
            "part",
        )
        robot.on_update(lambda event: on_robot_display(str(event.target.value)))
    with gui.add_folder("Legend", expand_by_default=False):
        gui.add_html(legend_html())
