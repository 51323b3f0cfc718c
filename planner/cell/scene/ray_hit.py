"""What a ray in the cell hits first: the robot, its tool, a fixture or the work object.

A click in the UI picks a point on the work object; a click whose ray meets the robot, the
tool or a fixture before the part must not place a point behind them. :func:`first_hit` casts
the ray in the cell's PyBullet client (``rayTest``: one call, tens of microseconds) with the
robot at the joint values the user sees, against the cell's collision bodies: the work object
and fixtures as their meshes or boxes, the robot and tool links as PyBullet's collision shapes
of their URDF meshes (convex hulls; a ray through a hollow of a link counts as a hit on it).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from calib.errors import ShapeError
from planner.cell.scene.cell_scene import CellScene
from planner.cell.scene.pybullet_client import pb

#: How far a ray is followed, m (a cell is a few metres across).
MAX_RAY_M = 100.0

HitKind = Literal["robot", "tool", "fixture", "work object"]


@dataclass(frozen=True)
class RayHit:
    """The first body a ray meets.

    Attributes:
        kind: ``"robot"``, ``"tool"``, ``"fixture"`` or ``"work object"``.
        name: the link name (robot, tool) or the fixture's or work object's name.
        distance_m: from the ray's origin to the hit, m.
        position_world: ``(3,)`` the hit point, world frame, m.
    """

    kind: HitKind
    name: str
    distance_m: float
    position_world: tuple[float, float, float]

    def describe(self) -> str:
        """E.g. ``the robot (link wrist_3)``, ``the fixture table``."""
        if self.kind in ("robot", "tool"):
            return f"the {self.kind} (link {self.name})"
        return f"the {self.kind} {self.name}"


def first_hit(
    scene: CellScene,
    origin_world: ArrayLike,
    direction_world: ArrayLike,
    q: ArrayLike | None = None,
    max_m: float = MAX_RAY_M,
) -> RayHit | None:
    """The first body the ray ``origin + t * direction`` (world, ``t`` in ``[0, max_m]``)
    meets with the robot at ``q`` (rad; default its current joint values), or ``None``.

    The scene's joint values are restored on return.

    Raises:
        ShapeError: origin or direction is not 3 finite numbers, or the direction is zero.
    """
    o = np.asarray(origin_world, dtype=np.float64).reshape(-1)
    d = np.asarray(direction_world, dtype=np.float64).reshape(-1)
    if o.shape != (3,) or d.shape != (3,) or not (np.isfinite(o).all() and np.isfinite(d).all()):
        raise ShapeError(f"ray origin and direction must be 3 finite numbers, got {o}, {d}")
    norm = float(np.linalg.norm(d))
    if norm < 1e-12:
        raise ShapeError("ray direction must not be zero")
    end = o + d / norm * float(max_m)
    with scene.saved_state():
        if q is not None:
            scene.set_joint_positions(q)
        body, link, fraction, position, _ = pb.rayTest(
            o.tolist(), end.tolist(), physicsClientId=scene.client
        )[0]
    if body < 0:
        return None
    kind, name = _body_name(scene, body, link)
    pos = (float(position[0]), float(position[1]), float(position[2]))
    return RayHit(kind, name, float(fraction) * float(max_m), pos)


def _body_name(scene: CellScene, body: int, link: int) -> tuple[HitKind, str]:
    """What body ``body`` (link ``link``) of the scene is, and its name."""
    if body == scene.robot.body_id:
        return "robot", scene.robot.names.get(link, str(link))
    tool = scene.tool_body
    if tool is not None and body == tool.body_id:
        return "tool", tool.names.get(link, str(link))
    name = scene.checker.environment.get(body, f"body {body}")
    return ("work object" if body == scene.checker.wobj_body else "fixture"), name
