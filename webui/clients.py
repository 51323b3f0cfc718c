"""Per-browser-tab things: the first camera view and notifications."""

from __future__ import annotations

import logging

import numpy as np
import viser
from numpy.typing import NDArray

from webui.backend import CellView

logger = logging.getLogger(__name__)


def default_camera(view: CellView) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Camera ``(position, look_at)`` (world, m) that shows the robot and the work object.

    The camera looks from the side and above, between robot and part, like the screenshot in
    ``docs/webui.md``.
    """
    base = view.T_world_base[:3, 3]
    part = view.T_world_wobj[:3, 3] + view.T_world_wobj[:3, :3] @ view.wobj_mesh.centroid
    look_at = 0.7 * part + 0.3 * base
    reach = max(float(np.linalg.norm((part - base)[:2])), 0.5)
    position = look_at + np.array([-0.55, -2.2, 1.1]) * reach
    return position, look_at


def set_default_camera(client: viser.ClientHandle, view: CellView) -> None:
    """Point a newly connected tab's camera at the cell (z up)."""
    position, look_at = default_camera(view)
    client.camera.up_direction = (0.0, 0.0, 1.0)
    client.camera.position = (float(position[0]), float(position[1]), float(position[2]))
    client.camera.look_at = (float(look_at[0]), float(look_at[1]), float(look_at[2]))


def notify(
    server: viser.ViserServer,
    title: str,
    body: str,
    client: viser.ClientHandle | None = None,
    error: bool = True,
) -> None:
    """Show a notification to one tab, or to every tab when ``client`` is None."""
    logger.info("%s: %s", title, body)
    clients = [client] if client is not None else list(server.get_clients().values())
    for c in clients:
        c.add_notification(title, body, color="red" if error else "green", auto_close_seconds=8.0)
