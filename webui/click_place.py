"""A click on the 3D view in place mode: select the marker it meets, place a point on the part,
or say why nothing was placed.

The click's ray (world frame, from viser's scene click) is cast in the cell
(:meth:`webui.backend.CellSession.first_hit`, PyBullet ``rayTest`` on the cell's worker) with
the robot at the pose the clicking tab shows: when the robot, its tool or a fixture is met
before the part, nothing is placed ("clicked the robot (link link_6), not the part"), and a
marker hidden behind them is not selected. ``bench/bench_click_ray.py`` measured this against
trimesh rays on the visual meshes (see ``bench/README.md``).
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from calib.errors import InputError
from calib.frames import transform_points
from planner.cell.scene import RayHit
from webui.scene import MARKER_RADIUS_M
from webui.surface import marker_on_ray

if TYPE_CHECKING:
    from webui.context import AppContext


def marker_at_ray(
    app: AppContext, origin_world: ArrayLike, direction_world: ArrayLike, front_world: Any = None
) -> str | None:
    """The point whose marker the ray passes through (see :func:`webui.surface.
    marker_on_ray`), not counting markers behind ``front_world`` (the first surface the ray
    meets, world, m), or ``None``."""
    view = app.view
    if view is None:
        return None
    doc = app.state.doc
    positions = [transform_points(view.T_world_wobj, p.probe.position_m) for p in doc.points]
    k = marker_on_ray(positions, origin_world, direction_world, 1.6 * MARKER_RADIUS_M, front_world)
    return None if k is None else doc.points[k].id


#: Robot and tool bodies a click looks past, at most, when the robot is a ghost or hidden.
SEE_THROUGH_HITS = 16
#: How far past a see-through body the ray is cast again, m.
SEE_THROUGH_STEP_M = 1e-4


def obstacle_on_ray(
    app: AppContext, origin_world: ArrayLike, direction_world: ArrayLike, client: Any
) -> RayHit | None:
    """The robot, tool or fixture the ray meets first, with the robot at the pose the tab of
    ``client`` shows; ``None`` when the first thing it meets is the part, or nothing."""
    robot = app.robot
    cid = None if client is None else client.client_id
    q = None if robot is None else robot.q_of(cid)
    o = np.asarray(origin_world, dtype=np.float64)
    d = np.asarray(direction_world, dtype=np.float64)
    see_through = robot is not None and robot.display != "shown"
    start = o
    for _ in range(SEE_THROUGH_HITS):
        hit = app.worker.call(lambda s, a=start: None if s is None else s.first_hit(a, d, q))
        if hit is None or not (see_through and hit.kind in ("robot", "tool")):
            break
        # a ghost or hidden robot does not stop the click: look on past it, along the same ray
        start = np.asarray(hit.position_world, dtype=np.float64) + SEE_THROUGH_STEP_M * d
    else:
        return None
    if hit is None or hit.kind == "work object":
        return None
    if start is not o:  # the distance along the whole ray, from where the click started
        hit = dataclasses.replace(hit, distance_m=float((np.asarray(hit.position_world) - o) @ d))
    return hit


def click_place(app: AppContext, event: Any) -> None:
    """A click in place mode: on a marker selects it (in the clicking tab), on the part places
    a point, on the robot, the tool, a fixture or nothing says that nothing was placed and why.

    Raises:
        InputError: nothing was placed, and why.
    """
    o = np.asarray(event.ray_origin, dtype=np.float64)
    d = np.asarray(event.ray_direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    picker = app.picker
    hit = None if picker is None else picker.pick(o, d)
    hit_world = None
    if hit is not None and app.view is not None:
        hit_world = transform_points(app.view.T_world_wobj, hit.position_wobj).reshape(3)
    obstacle = obstacle_on_ray(app, o, d, event.client) if app.view is not None else None
    t_part = np.inf if hit_world is None else float((hit_world - o) @ d)
    blocked = obstacle is not None and obstacle.distance_m < t_part
    front = np.asarray(obstacle.position_world) if blocked and obstacle else hit_world
    marker = marker_at_ray(app, o, d, front)
    if marker is not None:
        app.select(marker, event.client)
        return
    if picker is None:
        raise InputError("no work object is loaded: load a plan first")
    if blocked and obstacle is not None:
        raise InputError(f"nothing placed: clicked {obstacle.describe()}, not the part")
    if hit is None:
        raise InputError(
            "nothing placed: the click did not hit the work object (points go on the part; "
            "to select a point, click its marker or pick it under Selected)"
        )
    app.place_at_ray(o, d, client=event.client)
