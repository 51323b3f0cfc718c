"""The sensor's round footprint on a mesh: samples in a plane, and ray tests onto a planar face.

A proximity sensor's face (18 mm diameter for the paper's sensor; the plan's sensor says) must
lie wholly over one planar face. The footprint is sampled at its centre, on its rim and on a ring
at half the radius; a ray cast down the face normal from just above each sample tells whether the
sample lies on the face (a hole lets the ray through, an edge or a step makes it miss or hit
another face).

Used by detection (:mod:`planner.faces.detection`: does a region hold the footprint anywhere?) and
by the per-point checks (:mod:`planner.faces.checks`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import trimesh
from numpy.typing import NDArray

from calib.models.proximity import ProximitySensor

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Default footprint radius: the default sensor's (:class:`calib.models.ProximitySensor`), m.
#: Callers with a plan pass ``plan.validation.sensor.footprint_radius_m``.
DEFAULT_FOOTPRINT_RADIUS_M = ProximitySensor().footprint_radius_m
#: Footprint samples: this many on the rim, half as many at half the radius, and the centre.
N_RIM_SAMPLES = 12
#: Footprint rays start this far above the face's plane, m.
RAY_LIFT_M = 0.002
#: Candidate footprint centres per region: its largest triangles, and as many spread over it.
_N_CANDIDATES = 16


def footprint_offsets(radius_m: float) -> FloatArray:
    """``(S, 2)`` in-plane sample offsets: the centre, the rim and a ring at half the radius."""
    rim = np.linspace(0.0, 2 * math.pi, N_RIM_SAMPLES, endpoint=False)
    inner = np.linspace(0.0, 2 * math.pi, N_RIM_SAMPLES // 2, endpoint=False) + math.pi / 6
    ang = np.concatenate([rim, inner])
    r = np.concatenate([np.full(len(rim), radius_m), np.full(len(inner), radius_m / 2)])
    offs = np.stack([r * np.cos(ang), r * np.sin(ang)], axis=1)
    return np.vstack([np.zeros((1, 2)), offs])


def plane_basis(n: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Two unit vectors ``(K, 3)`` spanning the planes with normals ``n (K, 3)``."""
    helper = np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    u = np.cross(n, helper)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    return u, np.cross(n, u)


def footprint_hits(
    mesh: trimesh.Trimesh,
    face_id: IntArray,
    centres: FloatArray,
    normals: FloatArray,
    ids: IntArray,
    radius_m: float,
    tol_m: float,
) -> NDArray[np.bool_]:
    """``(K, S)``: footprint sample ``s`` around centre ``k`` lies on face ``ids[k]``.

    The samples lie in the plane through ``centres[k]`` with unit normal ``normals[k]``. From
    :data:`RAY_LIFT_M` above each, a ray is cast down the normal: the sample is on the face when
    the first hit is a triangle of that face within ``tol_m`` of the plane (a hole lets the ray
    through, an edge or a step makes it miss or hit another face).
    """
    offs = footprint_offsets(radius_m)
    u, v = plane_basis(normals)
    S = centres[:, None, :] + offs[None, :, :1] * u[:, None, :] + offs[None, :, 1:] * v[:, None, :]
    dirs = np.repeat(-normals, len(offs), axis=0)
    origins = S.reshape(-1, 3) - RAY_LIFT_M * dirs
    tri, ray, loc = mesh.ray.intersects_id(
        origins, dirs, multiple_hits=False, return_locations=True
    )
    good = np.zeros(len(origins), dtype=bool)
    t = np.einsum("ki,ki->k", np.asarray(loc) - origins[ray], dirs[ray])
    flat_ids = np.repeat(ids, len(offs))
    good[ray] = (face_id[tri] == flat_ids[ray]) & (np.abs(t - RAY_LIFT_M) <= tol_m)
    return good.reshape(len(centres), len(offs))


def holds_footprint(
    mesh: trimesh.Trimesh,
    labels: IntArray,
    regions: IntArray,
    n: FloatArray,
    d: FloatArray,
    radius_m: float,
    tol_m: float,
) -> NDArray[np.bool_]:
    """Whether each region has a spot where the whole sensor footprint lies on it.

    Tries the centroids of the region's largest triangles and of triangles spread over it;
    where none holds it, a point of the region's outline (its triangles projected onto the
    plane, holes included) with room for the disc to spare, then the centre of the largest
    circle inside that outline: the spot with the most room. So the answer does not depend on
    how the mesh is triangulated (a 20 mm strip meshed as two long triangles has no centroid
    on its centre line). Every spot is confirmed by :func:`footprint_hits` (rays).
    """
    if len(regions) == 0:
        return np.zeros(0, dtype=bool)
    area = np.asarray(mesh.area_faces)
    centres, ids = [], []
    tris: dict[int, IntArray] = {}
    order = np.argsort(labels, kind="stable")
    starts = np.searchsorted(labels[order], regions, side="left")
    ends = np.searchsorted(labels[order], regions, side="right")
    for r, lo, hi in zip(regions, starts, ends, strict=True):
        tri = order[lo:hi]
        tris[int(r)] = tri
        big = tri[np.argsort(-area[tri], kind="stable")[:_N_CANDIDATES]]
        spread = tri[np.linspace(0, len(tri) - 1, min(len(tri), _N_CANDIDATES)).astype(int)]
        pick = np.unique(np.concatenate([big, spread]))
        c = np.asarray(mesh.triangles_center[pick])
        centres.append(c - (c @ n[r] - d[r])[:, None] * n[r])
        ids.append(np.full(len(pick), r))
    at, region = np.vstack(centres), np.concatenate(ids)
    hits = footprint_hits(mesh, labels, at, n[region], region, radius_m, tol_m)
    ok = np.all(hits, axis=1)
    out = np.array([bool(np.any(ok[region == r])) for r in regions], dtype=bool)
    for k in np.flatnonzero(~out):
        r = int(regions[k])
        if _too_narrow(mesh, tris[r], n[r], radius_m):
            continue
        outline, B = _outline(mesh, tris[r], n[r])
        for find in (_spot_with_room, _roomiest_spot):
            uv = find(outline, radius_m)
            if uv is None:
                continue
            spot = B @ uv + float(d[r]) * np.asarray(n[r], dtype=np.float64)
            hit = footprint_hits(
                mesh, labels, spot[None], n[r][None], np.array([r]), radius_m, tol_m
            )
            if np.all(hit):
                out[k] = True
                break
    return out


def _too_narrow(mesh: trimesh.Trimesh, tri: IntArray, n: FloatArray, radius_m: float) -> bool:
    """No footprint can lie wholly on the region of the triangles ``tri``: its outline is
    narrower, along one of two in-plane axes, than the rim samples span in every direction
    (``2 r cos(pi / N)``: the samples are :data:`N_RIM_SAMPLES` apart around the rim, so some
    lie within ``pi / N`` of any direction and its opposite). A necessary condition, cheap,
    that spares the inscribed circle of the many small regions of a curved or finely meshed
    part."""
    u, v = plane_basis(np.asarray(n, dtype=np.float64)[None])
    pts = np.asarray(mesh.vertices, dtype=np.float64)[np.asarray(mesh.faces)[tri].ravel()]
    need = 2.0 * radius_m * math.cos(math.pi / N_RIM_SAMPLES) - 1e-9
    return bool(np.ptp(pts @ u[0]) < need or np.ptp(pts @ v[0]) < need)


def _outline(mesh: trimesh.Trimesh, tri: IntArray, n: FloatArray) -> tuple[Any, FloatArray]:
    """The outline of the region of the triangles ``tri`` (holes included) in the plane basis
    ``B`` (``(3, 2)``, :func:`calib.estimators.steering.plane_basis` of ``n``), and ``B``."""
    import shapely

    from calib.estimators.steering import plane_basis

    B = np.asarray(plane_basis(n), dtype=np.float64)  # (3, 2)
    uv = np.asarray(mesh.triangles[tri], dtype=np.float64) @ B  # (T, 3, 2)
    return shapely.union_all(shapely.polygons(uv)).buffer(1e-7), B


def _spot_with_room(outline: Any, radius_m: float) -> FloatArray | None:
    """``(2,)`` a point of ``outline`` at least ``1.02 radius_m`` from its boundary (a point of
    the outline shrunk by that much); ``None`` when there is none. About a hundredth of the
    cost of :func:`_roomiest_spot`, which a disc that fits with room to spare does not need
    (a sliver-meshed face of a small footprint: the stator at 1 mm took 18 ms a face)."""
    import shapely

    inner = outline.buffer(-1.02 * radius_m)
    if inner.is_empty:
        return None
    return np.asarray(shapely.get_coordinates(inner.representative_point())[0], dtype=np.float64)


def _roomiest_spot(outline: Any, radius_m: float) -> FloatArray | None:
    """``(2,)`` the centre of the largest circle inside ``outline`` (plane coordinates, m);
    ``None`` when the outline is empty."""
    import shapely

    if outline.is_empty:
        return None
    line = shapely.maximum_inscribed_circle(outline, tolerance=radius_m * 0.02)
    return np.asarray(shapely.get_coordinates(line)[0], dtype=np.float64)
