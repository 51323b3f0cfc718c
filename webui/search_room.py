"""How far a new point's approach search may run past the surface before it meets something.

An approach search runs the sensor TCP along ``-normal`` to ``overtravel`` past the nominal
point; the sensor face stands the sensing distance behind the TCP (:mod:`planner.cell.scene.tool`).
Behind a point of a thin plate the part ends after its thickness and a table often follows:
the UI's default overtravel (20 mm) ran the 18 mm sensor of the built-in tool into the table
under a 12.7 mm plate. :func:`room_behind_m` casts a ray from the point along ``-normal``
through the part (wobj mesh) and the fixtures; :func:`overtravel_cap_m` turns that room into
the longest overtravel that keeps the sensor face the cell's collision clearance
(:data:`planner.cell.scene.DEFAULT_MARGIN_M`, plus :data:`SPARE_M`) short of it.
:func:`webui.plan_doc.place_point` takes that cap for a new point's default.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray

from calib.frames import invert_transform, transform_directions, transform_points
from planner.cell.scene import DEFAULT_MARGIN_M

if TYPE_CHECKING:
    from calib.plan.file import Plan
    from webui.backend import CellView
    from webui.surface import SurfacePicker

#: The ray starts this far inside the part, below the point (off the point's own face), m.
INSIDE_M = 1e-4
#: Kept free beyond the collision clearance, so the default is not on the check's boundary, m.
SPARE_M = 0.001


def _first_hit_m(
    mesh: trimesh.Trimesh, origin: NDArray[np.float64], d: NDArray[np.float64]
) -> float:
    """Distance along the ray to ``mesh`` (its own frame), or ``inf`` for a miss."""
    locations, _, _ = mesh.ray.intersects_location(origin[None, :], d[None, :])
    if len(locations) == 0:
        return float("inf")
    return float(np.min(np.linalg.norm(np.asarray(locations) - origin, axis=1)))


def room_behind_m(
    picker: SurfacePicker,
    fixtures: Mapping[str, tuple[trimesh.Trimesh, ArrayLike]],
    point_wobj: ArrayLike,
    normal_wobj: ArrayLike,
) -> float | None:
    """Free travel behind a surface point, m: along ``-normal_wobj`` from ``point_wobj`` (wobj
    frame) to where the ray leaves the part or meets a fixture, whichever comes first;
    ``None`` when it meets neither (an open mesh, nothing behind).

    Args:
        picker: ray casting on the work object (wobj mesh, its pose in the world).
        fixtures: ``{name: (mesh, T_world_fixture)}``, each mesh in its own frame, m.
        point_wobj: ``(3,)`` the surface point, wobj frame, m.
        normal_wobj: ``(3,)`` its outward unit normal, wobj frame.
    """
    p = np.asarray(point_wobj, dtype=np.float64).reshape(3)
    n = np.asarray(normal_wobj, dtype=np.float64).reshape(3)
    n = n / np.linalg.norm(n)
    T = np.asarray(picker.T_world_wobj, dtype=np.float64)
    origin_w = transform_points(T, p - INSIDE_M * n)
    d_w = transform_directions(T, -n)
    hit = picker.pick(origin_w, d_w)
    best = float("inf") if hit is None else hit.distance_m + INSIDE_M
    for mesh, T_world_fixture in fixtures.values():
        T_f_w = invert_transform(np.asarray(T_world_fixture, dtype=np.float64))
        o_f = transform_points(T_f_w, origin_w)
        d_f = transform_directions(T_f_w, d_w)
        best = min(best, _first_hit_m(mesh, o_f, d_f) + INSIDE_M)
    return None if not np.isfinite(best) else best


def overtravel_cap_m(room_m: float | None, sensing_distance_m: float) -> float | None:
    """The longest overtravel (m) that keeps the sensor face the collision clearance short of
    what lies ``room_m`` behind the point: ``room + sensing distance - clearance - spare``
    (the face stands the sensing distance behind the TCP); ``None`` when nothing is behind.
    May be zero or negative: then nothing fits, and the misplacement's need decides."""
    if room_m is None:
        return None
    return float(room_m + sensing_distance_m - DEFAULT_MARGIN_M - SPARE_M)


def new_point_overtravel_cap_m(
    view: CellView | None,
    picker: SurfacePicker | None,
    plan: Plan | None,
    point_wobj: ArrayLike,
    normal_wobj: ArrayLike,
) -> float | None:
    """:func:`overtravel_cap_m` for a point placed in the UI's cell (``None`` without a cell or
    plan, or with nothing behind the point), with the plan's sensor's sensing distance."""
    if view is None or picker is None or plan is None:
        return None
    room = room_behind_m(picker, view.fixtures, point_wobj, normal_wobj)
    return overtravel_cap_m(room, float(plan.validation.sensor.standoff_m))
