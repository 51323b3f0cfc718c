"""The cell's PyBullet scene: one DIRECT client holding robot, tool, work object and fixtures.

Owns :class:`CellScene` (bodies, joint state, frames, the clearance query, ``saved_state()``,
``close()``/``with``), the bodies and how they are loaded (robot, tool and its sensor face,
work object and its units, fixtures, the PyBullet client without its banner), the
allowed-collision list, the clearance query and its result, and what a ray meets first. Of
:mod:`planner.cell` it imports only :mod:`planner.cell.disk_cache`; every query above takes a
:class:`CellScene`.

Modules:

- :mod:`~planner.cell.scene.acl`: the allowed-collision list (ACL) of a robot + tool, sampled once
  and cached;
- :mod:`~planner.cell.scene.bodies`: PyBullet bodies of the cell: URDF loading, static mesh bodies
  and pose conversions;
- :mod:`~planner.cell.scene.cell_scene`: the cell's scene: one PyBullet DIRECT client holding robot,
  tool, work object, fixtures;
- :mod:`~planner.cell.scene.clearance`: results and parts of clearance queries (see
  :mod:`planner.cell.scene.collision`);
- :mod:`~planner.cell.scene.collision`: collision checking of the cell: the clearance query with its
  allowed-collision list;
- :mod:`~planner.cell.scene.fixtures`: fixtures of the cell: tables, clamps and other static
  obstacles, named and placed;
- :mod:`~planner.cell.scene.mesh_units`: which unit a mesh file is in, when the plan says ``auto``,
  and whether given units make sense;
- :mod:`~planner.cell.scene.pybullet_client`: importing and connecting PyBullet without its
  build-time banner in the output;
- :mod:`~planner.cell.scene.ray_hit`: what a ray in the cell hits first: the robot, its tool, a
  fixture or the work object;
- :mod:`~planner.cell.scene.robot_body`: the robot in a PyBullet client: joint indices, flange link,
  static links, adjacency;
- :mod:`~planner.cell.scene.tool`: the tool on the robot flange and its TCP frames;
- :mod:`~planner.cell.scene.tool_face`: where a tool's sensor face lies behind its sensor TCP: the
  gap the TCP calibration must match;
- :mod:`~planner.cell.scene.workobject`: work-object meshes: loading any format trimesh reads,
  units, light repair, PyBullet body.
"""

from planner.cell.scene.bodies import BodyLinks, pb_transform, set_link_pose, world_link_pose
from planner.cell.scene.cell_scene import CellScene
from planner.cell.scene.clearance import Clearance, QueryPart, QueryPlan
from planner.cell.scene.collision import DEFAULT_MARGIN_M, report_distance_m
from planner.cell.scene.pybullet_client import pb
from planner.cell.scene.ray_hit import RayHit, first_hit
from planner.cell.scene.tool import FLANGE, Tool, load_tool, mesh_tool_description, tool_mount
from planner.cell.scene.tool_face import gap_mismatch
from planner.cell.scene.workobject import WorkObject, load_work_object

__all__ = [
    "DEFAULT_MARGIN_M",
    "FLANGE",
    "BodyLinks",
    "CellScene",
    "Clearance",
    "QueryPart",
    "QueryPlan",
    "RayHit",
    "Tool",
    "WorkObject",
    "first_hit",
    "gap_mismatch",
    "load_tool",
    "load_work_object",
    "mesh_tool_description",
    "pb",
    "pb_transform",
    "report_distance_m",
    "set_link_pose",
    "tool_mount",
    "world_link_pose",
]
