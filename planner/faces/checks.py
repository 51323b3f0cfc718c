"""Whether probe points lie on a planar face of the work object, with the sensor footprint on it.

A proximity sensor measures a plane: each probe point must lie on a planar face (found by
:func:`planner.faces.detection.find_planar_faces`) with the sensor's round face wholly over that
face and the plan normal along the face normal. A point on a curved or noisy scan, or one whose
footprint hangs over a hole or an edge, is reported with the reason. Points are located on the
surface by a ray down the plan normal, falling back to ``trimesh.proximity.closest_point``; the
footprint is tested with :mod:`planner.faces.footprint`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_points
from calib.errors import ShapeError
from calib.probing import ProbePoint
from planner.faces.array_cache import ArrayCache
from planner.faces.detection import NoPlanarFaceError, PlanarFaces, find_planar_faces
from planner.faces.footprint import (
    DEFAULT_FOOTPRINT_RADIUS_M,
    RAY_LIFT_M,
    footprint_hits,
    footprint_offsets,
)
from planner.reasons import Reason

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Default largest angle between a plan normal and its face's normal, rad.
MAX_NORMAL_ANGLE_RAD = math.radians(5.0)


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
        cause: why not, a ``footprint`` reason (``None`` when ok), e.g. ``"footprint over a
            hole/edge: ..."``; a point's distance from the surface measures the part
            (``about_part``: a part read in the wrong units shows there).
    """

    face_id: int
    distance_m: float
    footprint_on_face: bool
    normal_angle_rad: float
    face_normal: FloatArray = field(repr=False)
    ok: bool
    cause: Reason | None

    @property
    def reason(self) -> str:
        """The words of :attr:`cause` (``""`` when ok)."""
        return "" if self.cause is None else str(self.cause)


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
    footprint_radius_m: float = DEFAULT_FOOTPRINT_RADIUS_M,
    max_normal_angle_rad: float = MAX_NORMAL_ANGLE_RAD,
    max_distance_m: float = 1.0e-3,
    name: str | None = None,
    cache: ArrayCache | None = None,
) -> list[FaceCheck]:
    """Check that probe points lie on planar faces with the sensor footprint on the same face.

    Args:
        mesh_or_faces: the work-object mesh (faces found with the default tolerances and this
            footprint, cached) or its :class:`PlanarFaces`.
        points: ``(N, 3)`` probe points on the surface, mesh frame, metres.
        normals: ``(N, 3)`` the plan's outward normals at the points (need not be unit).
        footprint_radius_m: sensor face radius, metres (the paper's sensor: 9 mm).
        max_normal_angle_rad: largest angle between a plan normal and its face's normal, rad.
        max_distance_m: largest distance of a point from the mesh surface, metres.
        name: the mesh's name in messages (when a mesh is given).
        cache: the disk store of the faces' footprint test when a mesh is given
            (:func:`find_planar_faces`; the jobs pass :mod:`planner.cell.disk_cache`).

    Returns:
        One :class:`FaceCheck` per point.

    Raises:
        NoPlanarFaceError: the mesh has no planar face at all (a :class:`MeshError`).
        ShapeError, NonFiniteError: malformed ``points`` or ``normals``.
    """
    pf = (
        mesh_or_faces
        if isinstance(mesh_or_faces, PlanarFaces)
        else find_planar_faces(
            mesh_or_faces,
            min_area_m2=math.pi * footprint_radius_m**2,
            footprint_radius_m=footprint_radius_m,
            name=name,
            cache=cache,
        )
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
    n_samples = len(footprint_offsets(footprint_radius_m))
    if len(on):
        n_face = pf.normals[fid[on]]
        d_face = np.array([pf.faces[i].offset_m for i in fid[on]])
        p0 = P[on] - (np.einsum("ki,ki->k", n_face, P[on]) - d_face)[:, None] * n_face
        tol = pf.max_deviation_m + 1e-6
        good = footprint_hits(pf.mesh, pf.face_id, p0, n_face, fid[on], footprint_radius_m, tol)
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
        reason = None
        if dist[i] > max_distance_m and len(in_plane):
            reason = Reason(
                "footprint",
                f"footprint over a hole/edge: the point itself lies over a hole or past the "
                f"edge of planar face {in_plane[0]} ({dist[i] * 1e3:.2f} mm from the surface)",
                about_part=True,
            )
        elif dist[i] > max_distance_m:
            why = f"point is {dist[i] * 1e3:.2f} mm from the surface"
            reason = Reason("footprint", why, about_part=True)
        elif f < 0:
            reason = Reason("footprint", pf.why_not_at(int(tri[i]), footprint_radius_m))
        elif not footprint_ok[i]:
            reason = Reason(
                "footprint",
                f"footprint over a hole/edge: {n_off[i]} of {n_samples} points of the "
                f"{footprint_radius_m * 2e3:.0f} mm sensor face leave planar face {f}",
            )
        elif ang > max_normal_angle_rad:
            reason = Reason(
                "footprint",
                f"plan normal is {math.degrees(ang):.1f} deg from the face normal "
                f"(limit {math.degrees(max_normal_angle_rad):.1f} deg)",
            )
        ok = reason is None
        out.append(FaceCheck(f, float(dist[i]), bool(footprint_ok[i]), ang, fn.copy(), ok, reason))
    return out


def check_plan_faces(
    mesh_or_faces: trimesh.Trimesh | PlanarFaces,
    probes: Sequence[ProbePoint],
    *,
    name: str | None = None,
    cache: ArrayCache | None = None,
    **kw: float,
) -> list[FaceCheck]:
    """:func:`check_probe_faces` for plan points (wobj frame), with edge searches handled.

    An edge search's nominal point lies on the edge itself, so its face is checked where the
    search starts: ``start_offset_m`` before the edge, against the search's face normal.

    Args:
        mesh_or_faces: the work-object mesh or its :class:`PlanarFaces`.
        probes: the plan's probe points.
        name: the mesh's name in messages.
        cache: the disk store of the faces' footprint test (:func:`check_probe_faces`).
        **kw: tolerances passed to :func:`check_probe_faces`.
    """
    P = np.zeros((len(probes), 3))
    N = np.zeros((len(probes), 3))
    for i, p in enumerate(probes):
        P[i], N[i] = p.position_m, p.normal
        if p.search.kind == "edge" and p.search.edge_direction is not None:
            P[i] -= p.search.start_offset_m * np.asarray(p.search.edge_direction)
    checks = check_probe_faces(mesh_or_faces, P, N, name=name, cache=cache, **kw)
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
            c.cause.worded("at the edge search's start: ") if c.cause is not None else None,
        )
        for p, c in zip(probes, checks, strict=True)
    ]


def plan_face_reasons(
    mesh: trimesh.Trimesh,
    probes: Sequence[ProbePoint],
    *,
    name: str | None = None,
    raise_if_none: bool = True,
    footprint_radius_m: float = DEFAULT_FOOTPRINT_RADIUS_M,
    cache: ArrayCache | None = None,
) -> list[Reason | None]:
    """Why each plan point fails the planar-face check (``None`` when it passes): a
    ``footprint`` reason each.

    Args:
        mesh: the work object, wobj frame, metres.
        probes: the plan's probe points (wobj frame).
        name: the work object's name in messages.
        raise_if_none: raise when the mesh has no planar face; else every point gets that
            message as its reason (for the UI, which shows reasons per point; it names the
            part: ``about_part``).
        footprint_radius_m: the plan's sensor footprint radius, metres
            (``plan.validation.sensor.footprint_radius_m``).
        cache: the disk store of the faces' footprint test (:func:`check_probe_faces`).

    Raises:
        NoPlanarFaceError: the mesh has no planar face and ``raise_if_none`` is true.
    """
    if not probes:
        return []
    try:
        checks = check_plan_faces(
            mesh, probes, name=name, footprint_radius_m=footprint_radius_m, cache=cache
        )
    except NoPlanarFaceError as exc:
        if raise_if_none:
            raise
        return [Reason("footprint", str(exc), about_part=True)] * len(probes)
    return [c.cause for c in checks]
