"""The broad phase of the clearance query: which parts surely report nothing, for batches of poses.

Bullet is then asked only about the rest. Owns the links' collision shapes as Bullet holds
them, their sphere trees, the distance fields of meshes (cached on disk by mesh hash), the
arrays and part thresholds the kernels take, the slack bounds (GJK) that spare Bullet
queries, and the verdict of a sampled path, broad phase first. Built on
:mod:`planner.cell.scene` and :mod:`planner.cell.kernels`; ``docs/cell.md`` has the
measurements.

Modules:

- :mod:`~planner.cell.broad.broad_arrays`: the broad phase's arrays: its links, and the layouts its
  compiled kernels take;
- :mod:`~planner.cell.broad.broad_parts`: the parts of a clearance query on the broad phase's links
  and bodies: their thresholds;
- :mod:`~planner.cell.broad.broad_phase`: broad phase of the clearance query: which parts surely
  report nothing, for many candidates;
- :mod:`~planner.cell.broad.distance_field`: distance fields of triangle meshes: grid lower bounds
  of the distance to a mesh's surface;
- :mod:`~planner.cell.broad.link_geometry`: collision shapes of robot and tool links as PyBullet
  holds them, in URDF link frames;
- :mod:`~planner.cell.broad.path_clearance`: the clearance verdict of a sampled path (its first
  sample whose clearance query fails) and its samples' clearances;
- :mod:`~planner.cell.broad.slack_bounds`: upper bounds of probe candidates' slacks without Bullet:
  GJK on the exact shapes;
- :mod:`~planner.cell.broad.sphere_tree`: sphere covers of link collision shapes, as binary sphere
  trees (link frame).
"""

from planner.cell.broad.broad_arrays import EnvArrays, PartMap
from planner.cell.broad.broad_phase import BroadPhase, broad_phase_of
from planner.cell.broad.path_clearance import first_failure, first_failures, path_clearances
from planner.cell.broad.slack_bounds import SlackBounds

__all__ = [
    "BroadPhase",
    "EnvArrays",
    "PartMap",
    "SlackBounds",
    "broad_phase_of",
    "first_failure",
    "first_failures",
    "path_clearances",
]
