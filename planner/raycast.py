"""Batched first-hit ray casting against one mesh, for the proximity-sensor model.

:class:`MeshRayCaster` uses Embree through trimesh (``trimesh.ray.ray_pyembree``, backed by
``embreex``) to find the first triangle each ray hits, then recomputes the hit distance in float64
from that triangle's plane, so distances are exact to float64 on flat faces even though Embree
works in float32. ``bench/bench_rays.py`` measures it against PyBullet's ``rayTestBatch``; Embree
is faster (figures in ``docs/simulation.md``).

The caster works in the mesh's own frame; callers transform rays into it (cheaper than moving
the mesh), so one caster serves every misplaced copy of the same part.
"""

from __future__ import annotations

import numpy as np
import trimesh
from numpy.typing import NDArray

from planner.errors import MeshError

FloatArray = NDArray[np.float64]


class MeshRayCaster:
    """First-hit distances of ray batches against a fixed mesh (mesh frame, metres).

    Args:
        mesh: the triangle mesh; must have at least one face.
    """

    def __init__(self, mesh: trimesh.Trimesh) -> None:
        if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
            raise MeshError("mesh must be a trimesh.Trimesh with at least one face")
        self.mesh = mesh
        try:
            from trimesh.ray.ray_pyembree import RayMeshIntersector

            self._intersector = RayMeshIntersector(mesh, scale_to_box=False)
            self.backend = "embree"
        except ImportError:  # pragma: no cover - embreex is a dependency on x86_64
            from trimesh.ray.ray_triangle import RayMeshIntersector as TriIntersector

            self._intersector = TriIntersector(mesh)
            self.backend = "trimesh"
        tri = np.asarray(mesh.triangles, dtype=np.float64)
        normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        lengths = np.linalg.norm(normals, axis=1)
        lengths[lengths == 0] = 1.0
        self._normals = normals / lengths[:, None]
        self._offsets = np.einsum("ij,ij->i", self._normals, tri[:, 0])

    def first_hits(self, origins: FloatArray, directions: FloatArray) -> FloatArray:
        """Distance along each ray to the first surface it meets, metres.

        Args:
            origins: ``(N, 3)`` ray origins, mesh frame, metres.
            directions: ``(N, 3)`` unit ray directions, mesh frame.

        Returns:
            ``(N,)`` distances; ``inf`` where the ray misses; ``0`` where the ray starts inside
            the part (its first hit is a face seen from behind).
        """
        o = np.ascontiguousarray(origins, dtype=np.float64)
        d = np.ascontiguousarray(directions, dtype=np.float64)
        out = np.full(len(o), np.inf)
        if len(o) == 0:
            return out
        tri = np.asarray(self._intersector.intersects_first(o, d), dtype=np.int64)
        hit = tri >= 0
        if not np.any(hit):
            return out
        n = self._normals[tri[hit]]
        denom = np.einsum("ij,ij->i", n, d[hit])
        num = self._offsets[tri[hit]] - np.einsum("ij,ij->i", n, o[hit])
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(np.abs(denom) > 1e-15, num / denom, 0.0)
        t = np.where(denom > 0, 0.0, np.maximum(t, 0.0))  # back face first: origin inside
        out[hit] = t
        return out
