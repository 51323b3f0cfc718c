"""A planar face's outline in its own plane, to check a footprint that may shift on it.

:class:`FaceOutlines` projects each planar face's triangles into the face's in-plane basis
(:func:`calib.estimators.steering.plane_basis` of its normal), unions them (holes and notches
stay open) and erodes the union by the sensor's footprint radius: a footprint centred at ``c``
lies wholly on the face exactly when ``c`` lies in that eroded region. A search whose point
may land anywhere in a convex set of in-plane shifts (``steering.shift_outline``) keeps its
footprint on the face when the point plus that set, grown by a floor, lies in it
(:meth:`FaceOutlines.holds`). Outlines are built on first use, per face.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence

import numpy as np
import shapely
from numpy.typing import NDArray

from calib.estimators.steering import plane_basis
from planner.faces.detection import PlanarFaces

FloatArray = NDArray[np.float64]

#: Welds the projected triangles (float noise between neighbours), metres.
_WELD_M = 1e-7


class FaceOutlines:
    """The eroded in-plane outlines of a part's planar faces (wobj frame, metres)."""

    def __init__(self, faces: PlanarFaces, footprint_radius_m: float) -> None:
        """Args:
        faces: the part's planar faces.
        footprint_radius_m: the sensor footprint's radius, metres.
        """
        self._faces = faces
        self._radius = float(footprint_radius_m)
        self._free: dict[int, shapely.Geometry] = {}
        self._face: dict[int, shapely.Geometry] = {}
        self._rim: dict[int, tuple[FloatArray, FloatArray]] = {}
        self._basis: dict[int, FloatArray] = {}
        self._clearance: dict[tuple[int, bytes], float] = {}

    def basis(self, face_id: int) -> FloatArray:
        """``(3, 2)`` the face's in-plane basis (computed once per face; read-only)."""
        if face_id not in self._basis:
            b = np.asarray(plane_basis(self._faces.faces[face_id].normal), dtype=np.float64)
            b.setflags(write=False)
            self._basis[face_id] = b
        return self._basis[face_id]

    def face(self, face_id: int) -> shapely.Geometry:
        """The face itself (not eroded), in :meth:`basis` coordinates."""
        if face_id not in self._face:
            tri = np.asarray(self._faces.mesh.triangles, dtype=np.float64)
            mine = tri[self._faces.face_id == face_id]  # (T, 3, 3)
            uv = mine @ self.basis(face_id)  # (T, 3, 2)
            self._face[face_id] = _union(uv).buffer(_WELD_M)
        return self._face[face_id]

    def normal(self, face_id: int) -> FloatArray:
        """``(3,)`` the face's unit outward normal."""
        return np.asarray(self._faces.faces[face_id].normal, dtype=np.float64)

    def height_m(self, face_id: int) -> float:
        """The face plane's offset along its normal, metres (``normal . x`` on the face)."""
        tri = np.asarray(self._faces.mesh.triangles, dtype=np.float64)
        first = tri[self._faces.face_id == face_id][0, 0]
        return float(self.normal(face_id) @ first)

    def rim(self, face_id: int) -> tuple[FloatArray, FloatArray]:
        """The face's boundary as the mesh has it, with what lies across it.

        Returns:
            ``(ends, across)``: ``(E, 2, 2)`` the ends of each mesh edge between a triangle of
            the face and one that is not, in :meth:`basis` coordinates (metres), and ``(E, 3)``
            the unit normal of the triangle across it (wobj frame). An edge of an open mesh
            with nothing across is left out.
        """
        if face_id not in self._rim:
            mesh = self._faces.mesh
            pairs = np.asarray(mesh.face_adjacency, dtype=np.int64).reshape(-1, 2)
            edges = np.asarray(mesh.face_adjacency_edges, dtype=np.int64).reshape(-1, 2)
            mine = self._faces.face_id[pairs] == face_id  # (A, 2)
            one = mine[:, 0] != mine[:, 1]
            other = np.where(mine[one, 0], pairs[one, 1], pairs[one, 0])
            verts = np.asarray(mesh.vertices, dtype=np.float64)[edges[one]]  # (E, 2, 3)
            normals = np.asarray(mesh.face_normals, dtype=np.float64)[other]
            self._rim[face_id] = (verts @ self.basis(face_id), normals)
        return self._rim[face_id]

    def free(self, face_id: int) -> shapely.Geometry:
        """Where a footprint's centre may lie on the face, in :meth:`basis` coordinates."""
        if face_id not in self._free:
            self._free[face_id] = self.face(face_id).buffer(-(self._radius + _WELD_M))
        return self._free[face_id]

    def holds(
        self, face_id: int, point_m: FloatArray, shifts_m: FloatArray, floor_m: float
    ) -> bool:
        """The footprint at ``point_m`` (``(3,)``, on the face) stays on the face for every
        shift in the convex hull of ``shifts_m`` (``(M, 2)``, in :meth:`basis` coordinates,
        metres), grown by ``floor_m``."""
        shifts = np.asarray(shifts_m, dtype=np.float64).reshape(1, -1, 2)
        return bool(self.holds_many([face_id], np.reshape(point_m, (1, 3)), shifts, floor_m)[0])

    def holds_many(
        self,
        face_ids: Sequence[int] | NDArray[np.int64],
        points_m: FloatArray,
        shifts_m: FloatArray,
        floor_m: float,
    ) -> NDArray[np.bool_]:
        """:meth:`holds` of many footprints in one batch of geometry calls.

        Args:
            face_ids: ``(C,)`` each footprint's face.
            points_m: ``(C, 3)`` the footprints' centres, on their faces, wobj frame, metres.
            shifts_m: ``(C, M, 2)`` each one's shifts, in its face's :meth:`basis`
                coordinates, metres.
            floor_m: what every shift is grown by, metres.

        Returns:
            ``(C,)`` whether each footprint stays on its face.
        """
        ids = [int(f) for f in face_ids]
        P = np.asarray(points_m, dtype=np.float64).reshape(len(ids), 3)
        shifts = np.asarray(shifts_m, dtype=np.float64).reshape(len(ids), -1, 2)
        if not ids:
            return np.zeros(0, dtype=bool)
        c = np.stack([p @ self.basis(f) for p, f in zip(P, ids, strict=True)])
        hulls = shapely.convex_hull(shapely.multipoints(c[:, None, :] + shifts))
        regions = shapely.buffer(hulls, max(floor_m, _WELD_M), quad_segs=4)
        free = np.empty(len(ids), dtype=object)
        free[:] = [self.free(f) for f in ids]
        return np.asarray(shapely.contains(free, regions), dtype=bool)

    def clearance_m(self, face_id: int, point_m: FloatArray) -> float:
        """How far the footprint at ``point_m`` may move in any direction and stay on the
        face, metres (negative: it is already off)."""
        p = np.asarray(point_m, dtype=np.float64)
        key = (int(face_id), p.tobytes())
        if key not in self._clearance:
            free = self.free(face_id)
            c = shapely.Point(p @ self.basis(face_id))
            d = float(free.boundary.distance(c))
            self._clearance[key] = d if free.contains(c) else -d
        return self._clearance[key]


#: The outlines of recent parts (their unions take a second on a stator), shared by the jobs
#: of one process (suggest's design and the check of the plan it writes): ``{(ids of the
#: mesh, the triangles' face ids and the faces; radius): (faces, outlines)}``, the faces kept
#: so the ids stay theirs. A detection renamed for messages shares its outlines.
_SHARED: dict[tuple[int, int, int, float], tuple[PlanarFaces, FaceOutlines]] = {}
_SHARED_MAX = 8
_SHARED_LOCK = threading.Lock()  # suggest (cell worker) and the layout panel share them


def shared_outlines(faces: PlanarFaces, footprint_radius_m: float) -> FaceOutlines:
    """The :class:`FaceOutlines` of ``faces`` with a footprint of ``footprint_radius_m``
    (metres), the same object for the same detection and radius (built once, then its
    faces' outlines built once each)."""
    key = (id(faces.mesh), id(faces.face_id), id(faces.faces), float(footprint_radius_m))
    with _SHARED_LOCK:
        hit = _SHARED.get(key)
        if hit is not None:
            return hit[1]
        if len(_SHARED) >= _SHARED_MAX:
            _SHARED.pop(next(iter(_SHARED)))
        outlines = FaceOutlines(faces, footprint_radius_m)  # cheap: the unions come lazily
        _SHARED[key] = (faces, outlines)
        return outlines


def _union(uv: FloatArray) -> shapely.Geometry:
    """The union of triangles ``(T, 3, 2)`` that tile a face (in-plane coordinates, metres).

    The triangles of a planar face of a mesh share their edges exactly (each vertex projects
    to one point), so their union is a coverage union, which only dissolves the shared edges
    (the same geometry as ``union_all``, which overlays every pair: 0.13 against 2.4 s for the
    stator's side face of 26,000 triangles). It is taken only when it is surely right: every
    triangle turns the same way (none folded over) and the result is a valid polygon whose
    area is the triangles' (no overlap); anything else goes through ``union_all``.
    """
    polys = shapely.polygons(uv)
    e1, e2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    twice = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]  # signed areas (x2)
    if len(uv) and (np.all(twice > 0.0) or np.all(twice < 0.0)):
        merged = shapely.coverage_union_all(polys)
        total = 0.5 * float(np.abs(twice).sum())
        if shapely.is_valid(merged) and abs(merged.area - total) <= 1e-9 * total:
            return merged
    return shapely.union_all(polys)
