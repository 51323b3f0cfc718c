"""Planar faces of a work-object mesh, and whether probe points and sensor footprints lie on one.

A proximity sensor measures a plane: the paper's method (and every point-to-plane fit) assumes
each probe point lies on a planar face of the work object, with the sensor's round face (18 mm
diameter for the paper's sensor) wholly over that face. This module finds those faces and checks
probe points against them, so a point on a curved or noisy scan, or one whose footprint hangs
over a hole or an edge, is reported instead of silently using a mesh triangle's normal.

Detection (:func:`find_planar_faces`), all vectorized:

1. triangles joined across edges whose dihedral angle is at most ``angle_tol_rad`` form
   candidate regions (exact CAD facets, and smooth scanned patches);
2. each region's plane is fitted by area-weighted least squares (exact second moments of the
   triangles); triangles whose normal leaves the plane normal by more than ``angle_tol_rad`` or
   with a vertex farther than ``max_deviation_m`` from the plane are peeled off, the rest is split
   into connected parts again, and this repeats until nothing changes (a few rounds);
3. a region is a *planar face* when its area is at least ``min_area_m2`` (default: the sensor
   footprint, pi x 9 mm^2) and its area-weighted RMS distance from its plane is at most
   ``flatness_tol_m``.

Default tolerances, and why: ``angle_tol_rad`` 3 deg, ``flatness_tol_m`` 0.1 mm RMS and
``max_deviation_m`` 0.5 mm. The stator's tightening bolts bulge its side face by up to 0.3 mm
(RMS about 0.055 mm over the face), and the paper still measures that face as one plane; the
stricter 0.05 mm RMS would reject it. A raw scan with sub-millimetre noise fails on RMS.

Results are cached by a hash of the mesh's vertices and faces and the tolerances, so the UI and
the command line detect once per mesh. Per-point checks use ``trimesh.proximity.closest_point``.
"""

from __future__ import annotations

import hashlib
import math
import threading
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from calib.errors import ShapeError
from calib.probing import ProbePoint
from calib.validation import check_points
from planner.errors import MeshError

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Sensor face diameter of the paper's proximity sensor, metres.
SENSOR_DIAMETER_M = 0.018
#: Default smallest face area: the sensor footprint, m^2.
MIN_AREA_M2 = math.pi * (SENSOR_DIAMETER_M / 2) ** 2
#: Default largest angle between triangle normals (and to the fitted plane) in a face, rad.
ANGLE_TOL_RAD = math.radians(3.0)
#: Default largest RMS distance of a face from its fitted plane, m.
FLATNESS_TOL_M = 1.0e-4
#: Default largest distance of any vertex of a face from its fitted plane, m.
MAX_DEVIATION_M = 5.0e-4
#: Default largest angle between a plan normal and its face's normal, rad.
MAX_NORMAL_ANGLE_RAD = math.radians(5.0)
#: Footprint samples: this many on the rim, half as many at half the radius, and the centre.
N_RIM_SAMPLES = 12
_MAX_ROUNDS = 6
_CACHE_SIZE = 8
#: Footprint rays start this far above the face's plane, m.
RAY_LIFT_M = 0.002
_N_CANDIDATES = 16


class NoPlanarFaceError(MeshError):
    """A work-object mesh has no planar face a probe point could lie on (numbers in the message)."""


@dataclass(frozen=True)
class RegionStats:
    """One flat region (planar face or not).

    Attributes:
        normal: ``(3,)`` unit outward plane normal (area-weighted mean of its triangle normals'
            side), mesh frame.
        offset_m: plane offset ``d`` in ``normal . x = d``, metres.
        area_m2: region area, m^2.
        rms_m: area-weighted RMS distance of the region's surface from its plane, metres.
        n_triangles: triangles in the region.
        holds_footprint: some spot of the region holds the whole sensor footprint (only tested
            for regions large and flat enough; ``False`` for the others).
    """

    normal: FloatArray
    offset_m: float
    area_m2: float
    rms_m: float
    n_triangles: int
    holds_footprint: bool = True


@dataclass(frozen=True)
class PlanarFaces:
    """The planar faces of one mesh.

    Attributes:
        name: the mesh's name (for messages).
        mesh: the mesh searched, its own frame, metres.
        face_id: ``(F,)`` int, planar-face id of each triangle, ``-1`` for none.
        faces: per planar face (index = id): plane, area and flatness, largest area first.
        largest_region: the largest flat region found, planar face or not (``None`` for a mesh
            without any region); names the numbers when there is no planar face.
        min_area_m2: the area a planar face needed, m^2.
        flatness_tol_m: the largest RMS a planar face could have, metres.
        max_deviation_m: the largest vertex distance from the plane within a face, metres.
    """

    name: str
    mesh: trimesh.Trimesh = field(repr=False)
    face_id: IntArray = field(repr=False)
    faces: tuple[RegionStats, ...]
    largest_region: RegionStats | None
    min_area_m2: float
    flatness_tol_m: float
    max_deviation_m: float

    @property
    def normals(self) -> FloatArray:
        """``(K, 3)`` unit outward normals of the planar faces."""
        return np.array([f.normal for f in self.faces], dtype=np.float64).reshape(-1, 3)

    def face_at(self, points: ArrayLike) -> IntArray:
        """``(N,)`` planar-face id of the triangle nearest each point ``(N, 3)``, or ``-1``."""
        pts = check_points(points, "points")
        if len(pts) == 0:
            return np.zeros(0, dtype=np.int64)
        _, _, tri = trimesh.proximity.closest_point(self.mesh, pts)
        return self.face_id[np.asarray(tri, dtype=np.int64)]

    def _why_not(self, region: RegionStats) -> str:
        """Why ``region`` is not a planar face, in words."""
        why = []
        if region.rms_m > self.flatness_tol_m:
            why.append("too rough")
        if region.area_m2 < self.min_area_m2:
            why.append("too small")
        if not why and not region.holds_footprint:
            why.append("no spot of it holds the sensor face")
        return " and ".join(why) or "a planar face"

    def require_any(self) -> None:
        """Raise :class:`NoPlanarFaceError` (with the numbers) when there is no planar face."""
        if self.faces:
            return
        need = (
            f"a planar face needs area >= {self.min_area_m2 * 1e6:.0f} mm^2 and RMS <= "
            f"{self.flatness_tol_m * 1e3:.3f} mm"
        )
        big = self.largest_region
        if big is None:
            found = "no flat region at all"
        else:
            found = (
                f"largest flat region {big.area_m2 * 1e6:.1f} mm^2 "
                f"({big.n_triangles} triangles), RMS {big.rms_m * 1e3:.3f} mm"
                + f", {self._why_not(big)}"
            )
        raise NoPlanarFaceError(f"{self.name}: no planar face: {found}; {need}")


@dataclass(frozen=True)
class FaceCheck:
    """Whether one probe point lies on a planar face with the sensor footprint on it.

    Attributes:
        face_id: planar face of the triangle nearest the point, ``-1`` for none.
        distance_m: distance from the point to the mesh surface, metres.
        footprint_on_face: every footprint sample lies on the same face (no hole or edge).
        normal_angle_rad: angle between the plan normal and the face normal, rad (``nan``
            without a face).
        face_normal: ``(3,)`` the face's unit outward normal, mesh frame (zeros without a face).
        ok: the point passes every test.
        reason: why not (``""`` when ok), e.g. ``"footprint over a hole/edge: ..."``.
    """

    face_id: int
    distance_m: float
    footprint_on_face: bool
    normal_angle_rad: float
    face_normal: FloatArray = field(repr=False)
    ok: bool
    reason: str


# ---- detection ------------------------------------------------------------------------------
def _components(n: int, edges: IntArray, active: NDArray[np.bool_]) -> IntArray:
    """Connected components of the active triangles over ``edges``; ``-1`` for inactive ones."""
    keep = active[edges[:, 0]] & active[edges[:, 1]]
    e = edges[keep]
    graph = coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    labels = labels.astype(np.int64)
    labels[~active] = -1
    _, labels[active] = np.unique(labels[active], return_inverse=True)
    return labels


def _fit_planes(
    tris: FloatArray, area: FloatArray, normals: FloatArray, labels: IntArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Area-weighted least-squares planes of every label: normals, offsets, areas, RMS."""
    k = int(labels.max()) + 1 if labels.size and labels.max() >= 0 else 0
    m = labels >= 0
    lab, a, t = labels[m], area[m], tris[m]
    g = t.mean(axis=1)
    # exact second moment of a triangle: A/12 (sum v v^T + 9 g g^T)
    second = (a / 12.0)[:, None, None] * (
        np.einsum("fvi,fvj->fij", t, t) + 9.0 * np.einsum("fi,fj->fij", g, g)
    )
    A = np.bincount(lab, weights=a, minlength=k)
    S1 = np.stack([np.bincount(lab, weights=a * g[:, i], minlength=k) for i in range(3)], 1)
    S2 = np.stack(
        [np.bincount(lab, weights=second[:, i // 3, i % 3], minlength=k) for i in range(9)], 1
    ).reshape(k, 3, 3)
    Nsum = np.stack(
        [np.bincount(lab, weights=a * normals[m][:, i], minlength=k) for i in range(3)], 1
    )
    c = S1 / A[:, None]
    cov = S2 / A[:, None, None] - np.einsum("ki,kj->kij", c, c)
    w, v = np.linalg.eigh(cov)
    n = v[:, :, 0]
    n = np.where((np.einsum("ki,ki->k", n, Nsum) < 0)[:, None], -n, n)
    d = np.einsum("ki,ki->k", n, c)
    rms = np.sqrt(np.clip(w[:, 0], 0.0, None))
    return n.astype(np.float64), d.astype(np.float64), A.astype(np.float64), rms


def _stats(
    n: FloatArray,
    d: FloatArray,
    area: FloatArray,
    rms: FloatArray,
    cnt: IntArray,
    holds: NDArray[np.bool_],
    i: int,
) -> RegionStats:
    return RegionStats(
        n[i].copy(), float(d[i]), float(area[i]), float(rms[i]), int(cnt[i]), bool(holds[i])
    )


def _detect(
    mesh: trimesh.Trimesh,
    name: str,
    min_area_m2: float,
    angle_tol_rad: float,
    flatness_tol_m: float,
    max_deviation_m: float,
    footprint_radius_m: float,
) -> PlanarFaces:
    nf = len(mesh.faces)
    shift = np.asarray(mesh.bounds, dtype=np.float64).mean(axis=0)  # less round-off in moments
    tris = np.asarray(mesh.triangles, dtype=np.float64) - shift
    area = np.asarray(mesh.area_faces, dtype=np.float64)
    normals = np.asarray(mesh.face_normals, dtype=np.float64)
    adj = np.asarray(mesh.face_adjacency, dtype=np.int64).reshape(-1, 2)
    edges = adj[np.asarray(mesh.face_adjacency_angles) <= angle_tol_rad]
    active = area > 0
    cos_tol = math.cos(angle_tol_rad)
    labels = _components(nf, edges, active)
    for _ in range(_MAX_ROUNDS):
        if labels.max(initial=-1) < 0:
            break
        n, d, _, _ = _fit_planes(tris, area, normals, labels)
        m = labels >= 0
        pn, pd = n[labels[m]], d[labels[m]]
        dev = np.abs(np.einsum("fvi,fi->fv", tris[m], pn) - pd[:, None]).max(axis=1)
        bad = (np.einsum("fi,fi->f", normals[m], pn) < cos_tol) | (dev > max_deviation_m)
        if not bad.any():
            break
        idx = np.flatnonzero(m)[bad]
        active[idx] = False
        labels = _components(nf, edges, active)
    face_id = np.full(nf, -1, dtype=np.int64)
    if labels.max(initial=-1) < 0:
        return PlanarFaces(
            name, mesh, face_id, (), None, min_area_m2, flatness_tol_m, max_deviation_m
        )
    n, d, area_r, rms = _fit_planes(tris, area, normals, labels)
    d = d + n @ shift  # back to the mesh frame
    cnt = np.bincount(labels[labels >= 0], minlength=len(area_r))
    cand = np.flatnonzero((area_r >= min_area_m2) & (rms <= flatness_tol_m))
    holds = np.zeros(len(area_r), dtype=bool)
    holds[cand] = _holds_footprint(mesh, labels, cand, n, d, footprint_radius_m, max_deviation_m)
    good = np.flatnonzero(holds)
    good = good[np.argsort(-area_r[good], kind="stable")]
    remap = np.full(len(area_r), -1, dtype=np.int64)
    remap[good] = np.arange(len(good))
    face_id[labels >= 0] = remap[labels[labels >= 0]]
    faces = tuple(_stats(n, d, area_r, rms, cnt, holds, int(i)) for i in good)
    largest = _stats(n, d, area_r, rms, cnt, holds, int(np.argmax(area_r)))
    return PlanarFaces(
        name, mesh, face_id, faces, largest, min_area_m2, flatness_tol_m, max_deviation_m
    )


def _holds_footprint(
    mesh: trimesh.Trimesh,
    labels: IntArray,
    regions: IntArray,
    n: FloatArray,
    d: FloatArray,
    radius_m: float,
    tol_m: float,
) -> NDArray[np.bool_]:
    """Whether each region has a spot where the whole sensor footprint lies on it.

    Tries the centroids of the region's largest triangles and of triangles spread over it.
    """
    if len(regions) == 0:
        return np.zeros(0, dtype=bool)
    area = np.asarray(mesh.area_faces)
    centres, ids = [], []
    order = np.argsort(labels, kind="stable")
    starts = np.searchsorted(labels[order], regions, side="left")
    ends = np.searchsorted(labels[order], regions, side="right")
    for r, lo, hi in zip(regions, starts, ends, strict=True):
        tri = order[lo:hi]
        big = tri[np.argsort(-area[tri], kind="stable")[:_N_CANDIDATES]]
        spread = tri[np.linspace(0, len(tri) - 1, min(len(tri), _N_CANDIDATES)).astype(int)]
        pick = np.unique(np.concatenate([big, spread]))
        c = np.asarray(mesh.triangles_center[pick])
        centres.append(c - (c @ n[r] - d[r])[:, None] * n[r])
        ids.append(np.full(len(pick), r))
    at, region = np.vstack(centres), np.concatenate(ids)
    hits = _footprint_hits(mesh, labels, at, n[region], region, radius_m, tol_m)
    ok = np.all(hits, axis=1)
    return np.array([bool(np.any(ok[region == r])) for r in regions], dtype=bool)


_cache: OrderedDict[tuple[object, ...], PlanarFaces] = OrderedDict()
_cache_lock = threading.Lock()


def mesh_digest(mesh: trimesh.Trimesh) -> str:
    """A content hash (sha1) of a mesh's vertices and faces."""
    h = hashlib.sha1(np.ascontiguousarray(mesh.vertices, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(mesh.faces, dtype=np.int64).tobytes())
    return h.hexdigest()


def find_planar_faces(
    mesh: trimesh.Trimesh,
    *,
    min_area_m2: float = MIN_AREA_M2,
    angle_tol_rad: float = ANGLE_TOL_RAD,
    flatness_tol_m: float = FLATNESS_TOL_M,
    max_deviation_m: float = MAX_DEVIATION_M,
    footprint_radius_m: float = SENSOR_DIAMETER_M / 2,
    name: str | None = None,
) -> PlanarFaces:
    """Find the planar faces of a mesh (cached by mesh content and tolerances).

    Args:
        mesh: the work object, metres (its own frame).
        min_area_m2: smallest area of a planar face, m^2; default the 18 mm sensor footprint.
        angle_tol_rad: largest dihedral angle between neighbouring triangles of a face, and
            largest angle of a triangle normal from the face's plane normal, rad.
        flatness_tol_m: largest area-weighted RMS distance of a face from its plane, metres.
        max_deviation_m: largest distance of any vertex of a face from its plane, metres.
        footprint_radius_m: sensor face radius, metres: a face must hold this disc somewhere.
        name: name for messages; default ``mesh.metadata["name"]`` or ``"work object"``.

    Returns:
        The planar faces (possibly none: see :meth:`PlanarFaces.require_any`).

    Raises:
        MeshError: the mesh has no faces, or a tolerance is not positive.
    """
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise MeshError(f"{name or 'work object'}: planar faces need a non-empty triangle mesh")
    tols = {
        "min_area_m2": min_area_m2,
        "angle_tol_rad": angle_tol_rad,
        "flatness_tol_m": flatness_tol_m,
        "max_deviation_m": max_deviation_m,
        "footprint_radius_m": footprint_radius_m,
    }
    for tol_name, val in tols.items():
        if not (math.isfinite(val) and val > 0):
            raise MeshError(f"{tol_name} must be a positive number, got {val!r}")
    label = name or str((mesh.metadata or {}).get("name") or "work object")
    key = (mesh_digest(mesh), label, *tols.values())
    with _cache_lock:
        hit = _cache.get(key)
        if hit is not None:
            _cache.move_to_end(key)
            return hit
    found = _detect(mesh, label, **tols)
    with _cache_lock:
        _cache[key] = found
        while len(_cache) > _CACHE_SIZE:
            _cache.popitem(last=False)
    return found


# ---- per-point checks -----------------------------------------------------------------------
def _footprint_offsets(radius_m: float) -> FloatArray:
    """``(S, 2)`` in-plane sample offsets: the centre, the rim and a ring at half the radius."""
    rim = np.linspace(0.0, 2 * math.pi, N_RIM_SAMPLES, endpoint=False)
    inner = np.linspace(0.0, 2 * math.pi, N_RIM_SAMPLES // 2, endpoint=False) + math.pi / 6
    ang = np.concatenate([rim, inner])
    r = np.concatenate([np.full(len(rim), radius_m), np.full(len(inner), radius_m / 2)])
    offs = np.stack([r * np.cos(ang), r * np.sin(ang)], axis=1)
    return np.vstack([np.zeros((1, 2)), offs])


def _plane_basis(n: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Two unit vectors ``(K, 3)`` spanning the planes with normals ``n (K, 3)``."""
    helper = np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    u = np.cross(n, helper)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    return u, np.cross(n, u)


def _footprint_hits(
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
    offs = _footprint_offsets(radius_m)
    u, v = _plane_basis(normals)
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


def _surface_under(
    mesh: trimesh.Trimesh, P: FloatArray, unit: FloatArray, max_distance_m: float
) -> tuple[FloatArray, IntArray]:
    """Distance to the surface ``(N,)`` and the triangle ``(N,)`` under each point.

    A ray down the plan normal finds the triangle under a point on the surface (fast); points
    it misses (off the surface, or a wrong normal) fall back to the nearest triangle.
    """
    lift = max_distance_m + RAY_LIFT_M
    origins = P + lift * unit
    tri_hit, ray, loc = mesh.ray.intersects_id(
        origins, -unit, multiple_hits=False, return_locations=True
    )
    dist = np.full(len(P), np.inf)
    tri = np.full(len(P), -1, dtype=np.int64)
    t = np.einsum("ki,ki->k", np.asarray(loc) - origins[ray], -unit[ray])
    close = np.abs(t - lift) <= max_distance_m
    dist[ray[close]], tri[ray[close]] = np.abs(t - lift)[close], tri_hit[close]
    rest = np.flatnonzero(tri < 0)
    if len(rest):
        _, d, t_near = trimesh.proximity.closest_point(mesh, P[rest])
        dist[rest], tri[rest] = d, np.asarray(t_near, dtype=np.int64)
    return dist, tri


def check_probe_faces(
    mesh_or_faces: trimesh.Trimesh | PlanarFaces,
    points: ArrayLike,
    normals: ArrayLike,
    *,
    footprint_radius_m: float = SENSOR_DIAMETER_M / 2,
    max_normal_angle_rad: float = MAX_NORMAL_ANGLE_RAD,
    max_distance_m: float = 1.0e-3,
    name: str | None = None,
) -> list[FaceCheck]:
    """Check that probe points lie on planar faces with the sensor footprint on the same face.

    Args:
        mesh_or_faces: the work-object mesh (faces found with the defaults, cached) or its
            :class:`PlanarFaces`.
        points: ``(N, 3)`` probe points on the surface, mesh frame, metres.
        normals: ``(N, 3)`` the plan's outward normals at the points (need not be unit).
        footprint_radius_m: sensor face radius, metres (the paper's sensor: 9 mm).
        max_normal_angle_rad: largest angle between a plan normal and its face's normal, rad.
        max_distance_m: largest distance of a point from the mesh surface, metres.
        name: the mesh's name in messages (when a mesh is given).

    Returns:
        One :class:`FaceCheck` per point.

    Raises:
        NoPlanarFaceError: the mesh has no planar face at all (a :class:`MeshError`).
        ShapeError, NonFiniteError: malformed ``points`` or ``normals``.
    """
    pf = (
        mesh_or_faces
        if isinstance(mesh_or_faces, PlanarFaces)
        else find_planar_faces(mesh_or_faces, name=name)
    )
    pf.require_any()
    P = check_points(points, "points")
    Nrm = check_points(normals, "normals")
    if Nrm.shape != P.shape:
        raise ShapeError(f"normals must have the shape of points {P.shape}, got {Nrm.shape}")
    if len(P) == 0:
        return []
    unit = Nrm / np.maximum(np.linalg.norm(Nrm, axis=1, keepdims=True), 1e-300)
    dist, tri = _surface_under(pf.mesh, P, unit, max_distance_m)
    fid = pf.face_id[tri]
    on = np.flatnonzero(fid >= 0)
    footprint_ok = np.zeros(len(P), dtype=bool)
    n_off = np.zeros(len(P), dtype=np.int64)
    n_samples = len(_footprint_offsets(footprint_radius_m))
    if len(on):
        n_face = pf.normals[fid[on]]
        d_face = np.array([pf.faces[i].offset_m for i in fid[on]])
        p0 = P[on] - (np.einsum("ki,ki->k", n_face, P[on]) - d_face)[:, None] * n_face
        tol = pf.max_deviation_m + 1e-6
        good = _footprint_hits(pf.mesh, pf.face_id, p0, n_face, fid[on], footprint_radius_m, tol)
        footprint_ok[on] = good.all(axis=1)
        n_off[on] = (~good).sum(axis=1)
    offsets = np.array([face.offset_m for face in pf.faces])
    out = []
    for i in range(len(P)):
        f = int(fid[i])
        fn = pf.faces[f].normal if f >= 0 else np.zeros(3)
        ang = math.acos(float(np.clip(unit[i] @ fn, -1, 1))) if f >= 0 else math.nan
        in_plane = np.flatnonzero(
            (np.abs(pf.normals @ P[i] - offsets) <= pf.max_deviation_m)
            & (pf.normals @ unit[i] >= math.cos(max_normal_angle_rad))
        )
        if dist[i] > max_distance_m and len(in_plane):
            reason = (
                f"footprint over a hole/edge: the point itself lies over a hole or past the "
                f"edge of planar face {in_plane[0]} ({dist[i] * 1e3:.2f} mm from the surface)"
            )
        elif dist[i] > max_distance_m:
            reason = f"point is {dist[i] * 1e3:.2f} mm from the surface"
        elif f < 0:
            reason = "not on a planar face (curved, noisy or too small a flat region there)"
        elif not footprint_ok[i]:
            reason = (
                f"footprint over a hole/edge: {n_off[i]} of {n_samples} points of the "
                f"{footprint_radius_m * 2e3:.0f} mm sensor face leave planar face {f}"
            )
        elif ang > max_normal_angle_rad:
            reason = (
                f"plan normal is {math.degrees(ang):.1f} deg from the face normal "
                f"(limit {math.degrees(max_normal_angle_rad):.1f} deg)"
            )
        else:
            reason = ""
        out.append(
            FaceCheck(f, float(dist[i]), bool(footprint_ok[i]), ang, fn.copy(), not reason, reason)
        )
    return out


def check_plan_faces(
    mesh_or_faces: trimesh.Trimesh | PlanarFaces,
    probes: Sequence[ProbePoint],
    *,
    name: str | None = None,
    **kw: float,
) -> list[FaceCheck]:
    """:func:`check_probe_faces` for plan points (wobj frame), with edge searches handled.

    An edge search's nominal point lies on the edge itself, so its face is checked where the
    search starts: ``start_offset_m`` before the edge, against the search's face normal.

    Args:
        mesh_or_faces: the work-object mesh or its :class:`PlanarFaces`.
        probes: the plan's probe points.
        name: the mesh's name in messages.
        **kw: tolerances passed to :func:`check_probe_faces`.
    """
    P = np.zeros((len(probes), 3))
    N = np.zeros((len(probes), 3))
    for i, p in enumerate(probes):
        P[i], N[i] = p.position_m, p.normal
        if p.search.kind == "edge" and p.search.edge_direction is not None:
            P[i] -= p.search.start_offset_m * np.asarray(p.search.edge_direction)
    checks = check_probe_faces(mesh_or_faces, P, N, name=name, **kw)
    return [
        c
        if c.ok or p.search.kind != "edge"
        else FaceCheck(
            c.face_id,
            c.distance_m,
            c.footprint_on_face,
            c.normal_angle_rad,
            c.face_normal,
            False,
            f"at the edge search's start: {c.reason}",
        )
        for p, c in zip(probes, checks, strict=True)
    ]


def plan_face_reasons(
    mesh: trimesh.Trimesh,
    probes: Sequence[ProbePoint],
    *,
    name: str | None = None,
    raise_if_none: bool = True,
) -> list[str]:
    """Why each plan point fails the planar-face check (``""`` when it passes), for reports.

    Args:
        mesh: the work object, wobj frame, metres.
        probes: the plan's probe points (wobj frame).
        name: the work object's name in messages.
        raise_if_none: raise when the mesh has no planar face; else every point gets that
            message as its reason (for the UI, which shows reasons per point).

    Raises:
        NoPlanarFaceError: the mesh has no planar face and ``raise_if_none`` is true.
    """
    if not probes:
        return []
    try:
        checks = check_plan_faces(mesh, probes, name=name)
    except NoPlanarFaceError as exc:
        if raise_if_none:
            raise
        return [str(exc)] * len(probes)
    return [c.reason for c in checks]
