"""Planar faces of a work-object mesh: detection, and the results the probe-point checks use.

A proximity sensor measures a plane: the paper's method (and every point-to-plane fit) assumes
each probe point lies on a planar face of the work object, with the sensor's round face (18 mm
diameter for the paper's sensor) wholly over that face. This module finds those faces;
:mod:`planner.faces.checks` checks probe points against them, so a point on a curved or noisy scan,
or one whose footprint hangs over a hole or an edge, is reported instead of silently using a mesh
triangle's normal.

Detection (:func:`find_planar_faces`; region fits in :mod:`planner.faces.regions`, footprint ray
tests in :mod:`planner.faces.footprint`), all vectorized:

1. triangles joined across edges whose dihedral angle is at most ``angle_tol_rad`` form
   candidate regions (exact CAD facets, and smooth scanned patches);
2. each region's plane is fitted by area-weighted least squares (exact second moments of the
   triangles); triangles whose normal leaves the plane normal by more than ``angle_tol_rad`` or
   with a vertex farther than ``max_deviation_m`` from the plane are peeled off, the rest is split
   into connected parts again, and this repeats until nothing changes (a few rounds);
   A mesh triangulated from CAD (STEP/IGES) skips steps 1 and 2: its regions are its exact
   B-rep planes (:mod:`planner.faces.brep`), curved B-rep faces are in none;
3. a region is a *planar face* when its area is at least ``min_area_m2`` (default: the sensor
   footprint, pi x 9 mm^2) and its area-weighted RMS distance from its plane is at most
   ``flatness_tol_m``.

Default tolerances, and why: ``angle_tol_rad`` 3 deg, ``flatness_tol_m`` 0.1 mm RMS and
``max_deviation_m`` 0.5 mm. The stator's tightening bolts bulge its side face by up to 0.3 mm
(RMS about 0.055 mm over the face), and the paper still measures that face as one plane; the
stricter 0.05 mm RMS would reject it. A raw scan with sub-millimetre noise fails on RMS.

Results are cached by a hash of the mesh's vertices and faces and the tolerances, so the UI and
the command line detect once per mesh; given a disk store, the footprint test (most of the time)
is also kept across commands (:mod:`planner.faces.footprint_cache`).
"""

from __future__ import annotations

import hashlib
import math
import threading
from collections import OrderedDict
from dataclasses import dataclass, field, replace

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_points
from calib.tolerances import FACE_ANGLE_TOL_RAD, FACE_FLATNESS_RMS_M, FACE_MAX_DEVIATION_M
from planner.errors import MeshError
from planner.faces.array_cache import ArrayCache
from planner.faces.brep import brep_plane_labels, brep_regions
from planner.faces.footprint import DEFAULT_FOOTPRINT_RADIUS_M
from planner.faces.footprint import N_RIM_SAMPLES as N_RIM_SAMPLES
from planner.faces.footprint import RAY_LIFT_M as RAY_LIFT_M
from planner.faces.footprint_cache import holds_footprint_cached
from planner.faces.regions import RegionStats as RegionStats
from planner.faces.regions import fit_planes, flat_regions, region_stats

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Default smallest face area: the sensor footprint, m^2.
MIN_AREA_M2 = math.pi * DEFAULT_FOOTPRINT_RADIUS_M**2
#: Default largest angle between triangle normals (and to the fitted plane) in a face, rad
#: (the one table of tolerances, :mod:`calib.tolerances`).
ANGLE_TOL_RAD = FACE_ANGLE_TOL_RAD
#: Default largest RMS distance of a face from its fitted plane, m.
FLATNESS_TOL_M = FACE_FLATNESS_RMS_M
#: Default largest distance of any vertex of a face from its fitted plane, m.
MAX_DEVIATION_M = FACE_MAX_DEVIATION_M
_CACHE_SIZE = 8


class NoPlanarFaceError(MeshError):
    """A work-object mesh has no planar face a probe point could lie on (numbers in the message)."""


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
        region_of: ``(F,)`` flat region of each triangle (planar face or not), ``-1`` for none.
        region_area_m2: ``(R,)`` area of each flat region, m^2.
        region_rms_m: ``(R,)`` RMS distance of each flat region from its plane, metres.
        region_holds: ``(R,)`` the region holds the sensor footprint somewhere (tested only
            for regions large and flat enough).
    """

    name: str
    mesh: trimesh.Trimesh = field(repr=False)
    face_id: IntArray = field(repr=False)
    faces: tuple[RegionStats, ...]
    largest_region: RegionStats | None
    min_area_m2: float
    flatness_tol_m: float
    max_deviation_m: float
    region_of: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64), repr=False)
    region_area_m2: FloatArray = field(default_factory=lambda: np.zeros(0), repr=False)
    region_rms_m: FloatArray = field(default_factory=lambda: np.zeros(0), repr=False)
    region_holds: NDArray[np.bool_] = field(
        default_factory=lambda: np.zeros(0, dtype=bool), repr=False
    )

    def why_not_at(self, triangle: int, footprint_radius_m: float) -> str:
        """Why the triangle ``triangle`` is on no planar face, in words with the numbers."""
        r = int(self.region_of[triangle]) if len(self.region_of) else -1
        if r < 0:
            return "not on a planar face (curved or noisy there: no flat region)"
        area, rms = float(self.region_area_m2[r]), float(self.region_rms_m[r])
        d_mm = 2e3 * footprint_radius_m
        if area < self.min_area_m2:
            return (
                f"on a flat face of {area * 1e6:.1f} mm^2, too small for the {d_mm:.0f} mm "
                f"sensor (its face covers {self.min_area_m2 * 1e6:.0f} mm^2)"
            )
        if rms > self.flatness_tol_m:
            return (
                f"on a flat region too rough to be a planar face (RMS {rms * 1e3:.3f} mm, "
                f"limit {self.flatness_tol_m * 1e3:.3f} mm)"
            )
        if not bool(self.region_holds[r]):
            return (
                f"on a flat face of {area * 1e6:.1f} mm^2 too narrow for the {d_mm:.0f} mm sensor "
                "(no spot of it holds the sensor face)"
            )
        return "not on a planar face"

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


# ---- detection ------------------------------------------------------------------------------
def _detect(
    mesh: trimesh.Trimesh,
    name: str,
    min_area_m2: float,
    angle_tol_rad: float,
    flatness_tol_m: float,
    max_deviation_m: float,
    footprint_radius_m: float,
    digest: str = "",
    cache: ArrayCache | None = None,
) -> PlanarFaces:
    nf = len(mesh.faces)
    shift = np.asarray(mesh.bounds, dtype=np.float64).mean(axis=0)  # less round-off in moments
    tris = np.asarray(mesh.triangles, dtype=np.float64) - shift
    area = np.asarray(mesh.area_faces, dtype=np.float64)
    normals = np.asarray(mesh.face_normals, dtype=np.float64)
    adj = np.asarray(mesh.face_adjacency, dtype=np.int64).reshape(-1, 2)
    planes = brep_plane_labels(mesh)
    if planes is None:
        edges = adj[np.asarray(mesh.face_adjacency_angles) <= angle_tol_rad]
        labels = flat_regions(tris, area, normals, edges, angle_tol_rad, max_deviation_m)
    else:  # a CAD part: its B-rep planes are the regions (planner.faces.brep)
        labels = brep_regions(tris, area, normals, adj, planes)
    face_id = np.full(nf, -1, dtype=np.int64)
    if labels.max(initial=-1) < 0:
        return PlanarFaces(
            name, mesh, face_id, (), None, min_area_m2, flatness_tol_m, max_deviation_m
        )
    n, d, area_r, rms = fit_planes(tris, area, normals, labels)
    d = d + n @ shift  # back to the mesh frame
    cnt = np.bincount(labels[labels >= 0], minlength=len(area_r))
    cand = np.flatnonzero((area_r >= min_area_m2) & (rms <= flatness_tol_m))
    holds = np.zeros(len(area_r), dtype=bool)
    holds[cand] = holds_footprint_cached(
        mesh, digest, labels, cand, n, d, footprint_radius_m, max_deviation_m, cache
    )
    good = np.flatnonzero(holds)
    good = good[np.argsort(-area_r[good], kind="stable")]
    remap = np.full(len(area_r), -1, dtype=np.int64)
    remap[good] = np.arange(len(good))
    face_id[labels >= 0] = remap[labels[labels >= 0]]
    faces = tuple(region_stats(n, d, area_r, rms, cnt, holds, int(i)) for i in good)
    largest = region_stats(n, d, area_r, rms, cnt, holds, int(np.argmax(area_r)))
    return PlanarFaces(
        name,
        mesh,
        face_id,
        faces,
        largest,
        min_area_m2,
        flatness_tol_m,
        max_deviation_m,
        region_of=labels,
        region_area_m2=np.asarray(area_r, dtype=np.float64),
        region_rms_m=np.asarray(rms, dtype=np.float64),
        region_holds=holds,
    )


_cache: OrderedDict[tuple[object, ...], PlanarFaces] = OrderedDict()
_cache_lock = threading.Lock()


def mesh_digest(mesh: trimesh.Trimesh) -> str:
    """A content hash (sha1) of a mesh's vertices and faces (and B-rep planes, if any)."""
    h = hashlib.sha1(np.ascontiguousarray(mesh.vertices, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(mesh.faces, dtype=np.int64).tobytes())
    planes = brep_plane_labels(mesh)
    if planes is not None:  # a CAD part's B-rep planes decide its faces
        h.update(b"brep" + np.ascontiguousarray(planes).tobytes())
    return h.hexdigest()


def find_planar_faces(
    mesh: trimesh.Trimesh,
    *,
    min_area_m2: float = MIN_AREA_M2,
    angle_tol_rad: float = ANGLE_TOL_RAD,
    flatness_tol_m: float = FLATNESS_TOL_M,
    max_deviation_m: float = MAX_DEVIATION_M,
    footprint_radius_m: float = DEFAULT_FOOTPRINT_RADIUS_M,
    name: str | None = None,
    cache: ArrayCache | None = None,
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
        cache: a disk store for the footprint test, most of the detection's time
            (:mod:`planner.faces.footprint_cache`; the jobs pass
            :mod:`planner.cell.disk_cache`); ``None``: only this process's memory.

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
    digest = mesh_digest(mesh)
    key = (digest, *tols.values())  # the name is for messages only
    with _cache_lock:
        hit = _cache.get(key)
        if hit is not None:
            _cache.move_to_end(key)
            return hit if hit.name == label else replace(hit, name=label)
    found = _detect(mesh, label, **tols, digest=digest, cache=cache)
    with _cache_lock:
        _cache[key] = found
        while len(_cache) > _CACHE_SIZE:
            _cache.popitem(last=False)
    return found
