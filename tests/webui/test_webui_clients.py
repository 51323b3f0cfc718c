"""Per-tab things (issue 14, items 3 and 7): the framed first view holds part and robot for
any part, and error notifications stay until read."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
import trimesh

from calib.frames import make_transform, matrix_from_rotvec
from webui import clients


def _in_frustum(points: np.ndarray, position: np.ndarray, look_at: np.ndarray, fov: float,
                aspect: float) -> bool:  # fmt: skip
    d = (look_at - position) / np.linalg.norm(look_at - position)
    right = np.cross(d, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, d)
    rel = points - position
    z = rel @ d
    return bool(
        np.all(z > 0)
        and np.all(np.abs(rel @ right) / z <= np.tan(fov / 2) * aspect)
        and np.all(np.abs(rel @ up) / z <= np.tan(fov / 2))
    )


@pytest.mark.slow
def test_first_view_holds_part_and_robot_whatever_the_part(demo_app: Any) -> None:
    base = demo_app.view
    rng = np.random.default_rng(14)
    for size, where in ((0.02, (0.8, 0.3, 0.5)), (3.0, (2.5, -1.0, 0.0)), (0.3, (-1.0, 1.2, 1.4))):
        mesh = trimesh.creation.box(extents=(size, 0.6 * size, 0.2 * size))
        T = make_transform(matrix_from_rotvec(rng.normal(size=3)), where)
        view = dataclasses.replace(base, wobj_mesh=mesh, T_world_wobj=T)
        for direction in [clients.ISO_DIRECTION, *(d for d in clients.VIEWS.values() if d)]:
            position, look_at = clients.framed_camera(view, direction, clients.DEFAULT_FOV, 1.5)
            part, robot = clients.cell_points(view)
            assert _in_frustum(
                np.vstack([part, robot]), position, look_at, clients.DEFAULT_FOV, 1.5
            )
            centre = 0.5 * (part.min(axis=0) + part.max(axis=0))
            # the view is centred on the part, pulled a quarter of the way to the robot
            np.testing.assert_allclose(
                look_at, centre + clients.ROBOT_PULL * (robot.mean(axis=0) - centre), atol=1e-12
            )


def test_errors_stay_until_closed_and_other_notes_close() -> None:
    calls: list[dict[str, Any]] = []
    client = SimpleNamespace(add_notification=lambda *a, **kw: calls.append(kw))
    clients.notify(SimpleNamespace(), "Upload refused", "part.stl: empty", client, error=True)
    clients.notify(SimpleNamespace(), "Plan loaded", "", client, error=False)
    assert calls[0]["auto_close_seconds"] is None and calls[0]["with_close_button"]
    assert calls[1]["auto_close_seconds"] == clients.OK_SECONDS
