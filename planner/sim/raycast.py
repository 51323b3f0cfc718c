"""Batched first-hit ray casting against one mesh, for the proximity-sensor model.

:class:`MeshRayCaster` uses Embree (``embreex``, as ``trimesh.ray.ray_pyembree`` does, but
without its per-call overhead and origin shift) to find the first triangle each ray hits, then
recomputes the hit distance in float64 from that triangle's plane, so distances are exact to
float64 on flat faces even though Embree works in float32. Embree also widens triangles by
about 1e-7 of the scene size, so a ray that passes just beyond a real edge of the part can be
reported as a hit; every hit is re-checked in float64 (distances to the triangle's edges), and
a ray that falls outside its triangle across a real (non-coplanar) edge is continued past that
face. Edges are thus located to float64 precision.

``bench/bench_rays.py`` measures it against PyBullet's ``rayTestBatch``; Embree is faster
(figures in ``docs/simulation.md``). The caster works in the mesh's own frame; callers
transform rays into it (cheaper than moving the mesh), so one caster serves every misplaced
copy of the same part.
"""

from __future__ import annotations

import numpy as np
import trimesh
from numpy.typing import NDArray

from planner.errors import MeshError
from planner.sim.hit_kernel import finish_hits

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
            from embreex import rtcore_scene
            from embreex.mesh_construction import TriangleMesh

            self._scene = rtcore_scene.EmbreeScene()
            TriangleMesh(
                scene=self._scene,
                vertices=np.asarray(mesh.vertices, dtype=np.float32),
                indices=np.asarray(mesh.faces, dtype=np.int32),
            )
            self.backend = "embree"
        except ImportError:  # pragma: no cover - embreex is a dependency on x86_64
            from trimesh.ray.ray_triangle import RayMeshIntersector

            self._scene = None
            self._intersector = RayMeshIntersector(mesh)
            self.backend = "trimesh"
        tri = np.asarray(mesh.triangles, dtype=np.float64)
        normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        lengths = np.linalg.norm(normals, axis=1)
        lengths[lengths == 0] = 1.0
        self._normals = normals / lengths[:, None]
        self._offsets = np.einsum("ij,ij->i", self._normals, tri[:, 0])
        self._triangles = tri
        self._sharp = self._sharp_local_edges(mesh)
        self._neighbour = self._local_neighbours(mesh)
        self._has_sharp: NDArray[np.bool_] = np.any(self._sharp, axis=1)
        # inward in-plane normals of the edge opposite each vertex, and their offsets
        edge_dir = tri[:, [2, 0, 1]] - tri[:, [1, 2, 0]]  # (F, 3 edges, 3)
        inward = np.cross(self._normals[:, None, :], edge_dir)
        inward /= np.maximum(np.linalg.norm(inward, axis=2, keepdims=True), 1e-300)
        self._edge_normals = inward
        self._edge_offsets = np.einsum("fkj,fkj->fk", inward, tri[:, [1, 2, 0]])
        self._scale = float(max(np.ptp(mesh.vertices, axis=0).max(), 1e-9))
        #: what the compiled float64 step of a cast reads (:mod:`planner.sim.hit_kernel`)
        self._kernel_arrays = tuple(
            np.ascontiguousarray(x)
            for x in (
                self._normals,
                self._offsets,
                self._has_sharp,
                self._sharp,
                self._edge_normals,
                self._edge_offsets,
                self._neighbour,
            )
        )

    @staticmethod
    def _sharp_local_edges(mesh: trimesh.Trimesh) -> NDArray[np.bool_]:
        """``(F, 3)``: True where a face's edge opposite vertex k is a real edge (not flat)."""
        nv = len(mesh.vertices)
        eu = np.sort(np.asarray(mesh.edges_unique, dtype=np.int64), axis=1)
        flat = np.asarray(mesh.face_adjacency_angles) < 1e-9
        ae = np.sort(np.asarray(mesh.face_adjacency_edges, dtype=np.int64)[flat], axis=1)
        smooth = np.isin(eu[:, 0] * nv + eu[:, 1], ae[:, 0] * nv + ae[:, 1])
        # faces_unique_edges columns are the edges (a, b), (b, c), (c, a)
        return ~smooth[np.asarray(mesh.faces_unique_edges)[:, [1, 2, 0]]]

    @staticmethod
    def _local_neighbours(mesh: trimesh.Trimesh) -> NDArray[np.int64]:
        """``(F, 3)``: the triangle across a face's edge opposite vertex k (``-1``: none)."""
        ue = np.asarray(mesh.faces_unique_edges, dtype=np.int64)[:, [1, 2, 0]]
        out = np.full(ue.shape, -1, dtype=np.int64)
        flat_e, flat_f = ue.ravel(), np.repeat(np.arange(len(ue)), 3)
        order = np.argsort(flat_e, kind="stable")
        e, f = flat_e[order], flat_f[order]
        pair = np.flatnonzero(e[1:] == e[:-1])  # an edge shared by two faces (manifold)
        first, second = f[pair], f[pair + 1]
        slot = np.arange(3)
        for a, b in ((first, second), (second, first)):
            k = np.argmax(ue[a] == e[pair][:, None], axis=1)
            out[a, slot[k]] = b
        return out

    def first_hits(self, origins: FloatArray, directions: FloatArray) -> FloatArray:
        """Distance along each ray to the first surface it meets, metres.

        Args:
            origins: ``(N, 3)`` ray origins, mesh frame, metres.
            directions: ``(N, 3)`` unit ray directions, mesh frame.

        Returns:
            ``(N,)`` distances; ``inf`` where the ray misses; ``0`` where the ray starts inside
            the part (its first hit is a face seen from behind).
        """
        return self.first_hits_ids(origins, directions)[0]

    def first_hits_ids(
        self, origins: FloatArray, directions: FloatArray, depth: int = 0
    ) -> tuple[FloatArray, NDArray[np.int64]]:
        """:meth:`first_hits` and the index of the triangle each ray hits (``-1``: none).

        ``depth`` is internal (continuations past real edges).
        """
        o = np.ascontiguousarray(origins, dtype=np.float64)
        d = np.ascontiguousarray(directions, dtype=np.float64)
        if len(o) == 0:
            return np.full(0, np.inf), np.full(0, -1, dtype=np.int64)
        if self._scene is not None:
            ids = self._scene.run(o.astype(np.float32), d.astype(np.float32))
        else:  # pragma: no cover
            ids = self._intersector.intersects_first(o, d)
        tri = np.ascontiguousarray(ids, dtype=np.int64)
        out, tri_out, cont, t_cont = finish_hits(
            o, d, tri, self._kernel_arrays, -1e-12 * self._scale, 1e-7 * self._scale
        )
        if depth < 4 and cont.any():  # continue just past the face that was not hit
            r = np.flatnonzero(cont)
            step = 1e-9 * self._scale
            more, more_tri = self.first_hits_ids(
                o[r] + (t_cont[r] + step)[:, None] * d[r], d[r], depth + 1
            )
            out[r] = t_cont[r] + step + more
            tri_out[r] = more_tri
        return out, tri_out

    def triangle_arrays(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``(normals (F, 3), offsets (F,), corners (F, 3, 3))`` of every triangle, mesh frame,
        m, float64 and C-contiguous (the caster's own arrays: read them, do not write)."""
        return self._normals, self._offsets, self._triangles

    def triangle_normal(self, triangle: int | NDArray[np.int64]) -> FloatArray:
        """``(3,)`` (or ``(K, 3)``) unit normal of a triangle (or triangles), mesh frame."""
        return np.array(self._normals[triangle], dtype=np.float64)

    def triangle_vertices(self, triangle: int | NDArray[np.int64]) -> FloatArray:
        """``(3, 3)`` (or ``(K, 3, 3)``) the corners of a triangle (or triangles), mesh frame."""
        return np.array(self._triangles[triangle], dtype=np.float64)

    def triangle_offset(self, triangle: int | NDArray[np.int64]) -> FloatArray:
        """Plane offset ``d`` of a triangle (or triangles): its plane is ``normal . x = d``, m."""
        return np.asarray(self._offsets[triangle], dtype=np.float64)
