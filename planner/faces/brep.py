"""Flat regions of a CAD part taken from its B-rep planes instead of clustering triangles.

A mesh triangulated from a B-rep (:mod:`planner.cad.part`) carries, per triangle, the B-rep
plane it lies on (``mesh.face_attributes[BREP_PLANE]``, ``-1`` on a curved face). Those planes
are exact: :func:`brep_regions` makes each one a region, so a plane's outline, holes and area
are the CAD face's (to the triangulation of its curved edges), and a curved face is never
mistaken for a flat one however finely or coarsely it is triangulated. Neighbouring B-rep planes
that are the same plane (a face split in CAD, or two bodies' faces flush across a joint) are
joined, as the sensor sees one surface there: same plane means normals within
:data:`COPLANAR_ANGLE_RAD` and offsets within :data:`COPLANAR_OFFSET_M`.
"""

from __future__ import annotations

import math

import numpy as np
import trimesh
from numpy.typing import NDArray
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from planner.faces.regions import fit_planes

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: ``mesh.face_attributes`` key: per triangle, the B-rep plane it lies on, ``-1`` for none.
BREP_PLANE = "brep_plane"
#: Two neighbouring B-rep planes closer in angle than this are one plane, rad.
COPLANAR_ANGLE_RAD = 1e-6
#: ... and in offset along their normal than this, metres.
COPLANAR_OFFSET_M = 1e-7


def brep_plane_labels(mesh: trimesh.Trimesh) -> IntArray | None:
    """``(F,)`` the B-rep plane of each triangle (``-1`` for none), or ``None`` for a mesh that
    does not come from CAD (or whose labels no longer match its triangles)."""
    attrs = getattr(mesh, "face_attributes", None) or {}
    labels = attrs.get(BREP_PLANE)
    if labels is None:
        return None
    labels = np.asarray(labels)
    if labels.shape != (len(mesh.faces),) or labels.dtype.kind not in "iu":
        return None
    return labels.astype(np.int64)


def brep_regions(
    tris: FloatArray,
    area: FloatArray,
    normals: FloatArray,
    adjacency: IntArray,
    planes: IntArray,
) -> IntArray:
    """``(F,)`` region label of each triangle from its B-rep plane, ``-1`` off every plane.

    Args:
        tris: ``(F, 3, 3)`` triangles, metres (any fixed origin).
        area: ``(F,)`` their areas, m^2 (zero-area triangles get ``-1``).
        normals: ``(F, 3)`` their unit normals.
        adjacency: ``(A, 2)`` pairs of triangles sharing an edge.
        planes: ``(F,)`` the B-rep plane of each triangle, ``-1`` for none.

    Returns:
        Labels ``0..R-1``, one per plane after joining neighbouring coplanar B-rep planes.
    """
    labels = np.where(area > 0, planes, -1)
    if labels.max(initial=-1) < 0:
        return np.full(len(labels), -1, dtype=np.int64)
    used, labels[labels >= 0] = np.unique(labels[labels >= 0], return_inverse=True)
    k = len(used)
    n, d, _, _ = fit_planes(tris, area, normals, labels)
    a, b = labels[adjacency[:, 0]], labels[adjacency[:, 1]]
    cross = (a >= 0) & (b >= 0) & (a != b)
    pairs = np.unique(np.sort(np.stack([a[cross], b[cross]], axis=1), axis=1), axis=0)
    same = np.einsum("ki,ki->k", n[pairs[:, 0]], n[pairs[:, 1]]) >= math.cos(COPLANAR_ANGLE_RAD)
    same &= np.abs(d[pairs[:, 0]] - d[pairs[:, 1]]) <= COPLANAR_OFFSET_M
    join = pairs[same]
    graph = coo_matrix((np.ones(len(join)), (join[:, 0], join[:, 1])), shape=(k, k))
    _, group = connected_components(graph, directed=False)
    out = np.full(len(labels), -1, dtype=np.int64)
    out[labels >= 0] = group[labels[labels >= 0]]
    return out
