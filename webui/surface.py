"""Click-to-place: cast the browser's click ray on the work-object mesh, project drags onto it.

The mesh is kept in the work-object frame; rays come from the browser in the world frame and are
mapped with ``T_world_wobj``. Ray casting uses trimesh's embree intersector when ``embreex`` is
installed (about a millisecond on a 100,000-triangle mesh), else trimesh's pure-numpy one.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_vector3
from calib.errors import DegenerateGeometryError
from calib.frames import (
    check_transform,
    invert_transform,
    transform_directions,
    transform_points,
)

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class SurfaceHit:
    """Where a ray or a projection meets the work-object surface.

    Attributes:
        position_wobj: ``(3,)`` the surface point, wobj frame, metres.
        normal_wobj: ``(3,)`` unit outward normal of the hit face, wobj frame.
        face_index: index of the hit triangle in the mesh.
        distance_m: distance from the ray origin (or from the projected point), metres.
    """

    position_wobj: FloatArray
    normal_wobj: FloatArray
    face_index: int
    distance_m: float


class SurfacePicker:
    """Ray casting and closest-point projection on one work-object mesh.

    Args:
        mesh: the work object in its own (wobj) frame, metres.
        T_world_wobj: ``(4, 4)`` pose of the work object in the world (scene) frame.
    """

    def __init__(self, mesh: trimesh.Trimesh, T_world_wobj: ArrayLike) -> None:
        if len(mesh.faces) == 0:
            raise DegenerateGeometryError("the work-object mesh has no faces to click on")
        self.mesh = mesh
        self.T_world_wobj = check_transform(T_world_wobj, "T_world_wobj")
        self._T_wobj_world = invert_transform(self.T_world_wobj)
        self._ray = _make_intersector(mesh)
        self._normals = np.asarray(mesh.face_normals, dtype=np.float64)

    @property
    def uses_embree(self) -> bool:
        """True when rays are cast with embree."""
        return type(self._ray).__module__.endswith("ray_pyembree")

    def pick(self, origin_world: ArrayLike, direction_world: ArrayLike) -> SurfaceHit | None:
        """The first surface hit of a ray given in the world frame, or ``None`` for a miss."""
        o = transform_points(self._T_wobj_world, check_vector3(origin_world, "ray_origin"))
        d = transform_directions(self._T_wobj_world, check_vector3(direction_world, "ray_dir"))
        norm = float(np.linalg.norm(d))
        if norm < 1e-12:
            raise DegenerateGeometryError("ray_direction must not be the zero vector")
        d = d / norm
        locations, _, faces = self._ray.intersects_location(
            o[None, :], d[None, :], multiple_hits=False
        )
        if len(faces) == 0:
            return None
        dist = np.linalg.norm(locations - o, axis=1)
        k = int(np.argmin(dist))
        face = int(faces[k])
        return SurfaceHit(
            position_wobj=np.asarray(locations[k], dtype=np.float64),
            normal_wobj=self._normals[face].copy(),
            face_index=face,
            distance_m=float(dist[k]),
        )

    def project(self, point_wobj: ArrayLike) -> SurfaceHit:
        """The closest surface point to ``point_wobj`` (wobj frame) and that face's normal."""
        p = check_vector3(point_wobj, "point_wobj")
        closest, dist, faces = trimesh.proximity.closest_point(self.mesh, p[None, :])
        face = int(faces[0])
        return SurfaceHit(
            position_wobj=np.asarray(closest[0], dtype=np.float64),
            normal_wobj=self._normals[face].copy(),
            face_index=face,
            distance_m=float(dist[0]),
        )

    def project_world(self, point_world: ArrayLike) -> SurfaceHit:
        """Like :meth:`project` for a point given in the world frame."""
        p = transform_points(self._T_wobj_world, check_vector3(point_world, "point_world"))
        return self.project(p)


def marker_on_ray(
    centres_world: Sequence[ArrayLike],
    origin_world: ArrayLike,
    direction_world: ArrayLike,
    radius_m: float,
    hit_world: ArrayLike | None = None,
) -> int | None:
    """Index of the marker (sphere of ``radius_m`` at each centre, world, m) the ray passes
    through nearest the camera, not counting markers hidden behind the surface point the ray
    hits (``hit_world``); ``None`` when it passes through none."""
    o = np.asarray(origin_world, dtype=np.float64)
    d = np.asarray(direction_world, dtype=np.float64)
    d = d / np.linalg.norm(d)
    t_part = np.inf if hit_world is None else float((np.asarray(hit_world) - o) @ d)
    best: tuple[float, int] | None = None
    for k, c in enumerate(centres_world):
        rel = np.asarray(c, dtype=np.float64) - o
        t = float(rel @ d)
        miss = float(np.linalg.norm(rel - t * d))
        if 0 < t <= t_part + 1.25 * radius_m and miss <= radius_m and (best is None or t < best[0]):
            best = (t, k)
    return None if best is None else best[1]


def _make_intersector(mesh: trimesh.Trimesh) -> Any:
    try:
        from trimesh.ray.ray_pyembree import RayMeshIntersector

        return RayMeshIntersector(mesh)
    except ImportError:  # embreex is optional on non-x86 machines
        from trimesh.ray.ray_triangle import RayMeshIntersector as NumpyIntersector

        return NumpyIntersector(mesh)
