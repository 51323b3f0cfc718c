"""The report's rows of a plan: frame rows, points of interest, regions, the x-offset rows.

:func:`report_rows` turns the plan's ``validation.report`` (:class:`calib.plan.report_spec.
ReportSpec`) into :class:`planner.sim.rows.RowSpec` s on the work object's mesh:

- points of interest as given, or by default the surface point farthest from the WOCS origin
  (the paper's epsilon is the slot hole farthest from it: there rotation errors weigh most);
- regions: ``"part"`` samples the whole surface (area-weighted, fixed seed), ``"face"`` the
  planar face through a point, ``"slot_holes"`` the slot-hole targets of a built-in stator
  within the robot's reach (the paper's "stator side"; targets at x = 0, as the robot is sent
  to them from the calibrated frame);
- with an x-offset run, the slot targets' x error with and without the x-offset matrix.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import trimesh
from numpy.typing import NDArray

from calib.errors import PlanError
from calib.plan.report_spec import PointOfInterest, RegionSpec, ReportSpec
from planner.faces.detection import find_planar_faces
from planner.parts.stator import StatorGeometry
from planner.sim.rows import RowSpec, frame_rows
from planner.sim.xoffset import XOffsetSetup

FloatArray = NDArray[np.float64]

#: Seed of the surface samples of regions (the same points in every run).
REGION_SEED = 7
#: Row keys of the x-offset rows (slot targets' x error without and with the matrix).
XOFFSET_KEYS = ("x_slots", "x_slots_xoffset")


def _label(components: str, what: str) -> str:
    if len(components) == 1:
        return f"{components} error {what}"
    if components == "xyz":
        return f"xyz error {what}"
    return f"{components}-plane error {what}"


def farthest_point(mesh: trimesh.Trimesh) -> FloatArray:
    """``(3,)`` the vertex of the part farthest from the WOCS origin, wobj, metres."""
    v = np.asarray(mesh.vertices, dtype=np.float64)
    return v[int(np.argmax(np.einsum("ij,ij->i", v, v)))].copy()


def default_points_of_interest(mesh: trimesh.Trimesh) -> list[PointOfInterest]:
    """The surface point farthest from the origin, as the report's point of interest."""
    p = farthest_point(mesh)
    mm = ", ".join(f"{c * 1e3:.0f}" for c in p)
    return [
        PointOfInterest(
            name="farthest",
            position_m=(float(p[0]), float(p[1]), float(p[2])),
            components="xyz",
            label=f"xyz error at the farthest point ({mm}) mm",
        )
    ]


def surface_samples(
    mesh: trimesh.Trimesh, n: int, triangles: NDArray[np.int64] | None = None
) -> FloatArray:
    """``(n, 3)`` area-weighted points on ``mesh`` (or on the given triangles), fixed seed."""
    tri = np.arange(len(mesh.faces)) if triangles is None else np.asarray(triangles)
    area = np.asarray(mesh.area_faces, dtype=np.float64)[tri]
    rng = np.random.default_rng(REGION_SEED)
    pick = tri[rng.choice(len(tri), size=n, p=area / area.sum())]
    uv = rng.uniform(size=(n, 2))
    flip = uv.sum(axis=1) > 1.0
    uv[flip] = 1.0 - uv[flip]
    t = np.asarray(mesh.triangles, dtype=np.float64)[pick]
    return t[:, 0] + uv[:, :1] * (t[:, 1] - t[:, 0]) + uv[:, 1:] * (t[:, 2] - t[:, 0])


def region_points(
    region: RegionSpec, mesh: trimesh.Trimesh, geometry: StatorGeometry | None
) -> FloatArray:
    """``(M, 3)`` the wobj points of a region.

    Raises:
        PlanError: ``"slot_holes"`` on a part that is not a built-in stator, or a face point
            that lies on no planar face.
    """
    if region.points == "slot_holes":
        if geometry is None:
            raise PlanError(
                f"validation.report.regions: {region.name!r} uses the slot holes, which only a "
                "built-in stator work object has"
            )
        return geometry.slot_centres_m() * np.array([0.0, 1.0, 1.0])
    if region.points == "face":
        faces = find_planar_faces(mesh)
        fid = int(faces.face_at(np.asarray([region.face_point_m], dtype=np.float64))[0])
        if fid < 0:
            raise PlanError(
                f"validation.report.regions: {region.name!r}: face_point_m "
                f"{list(region.face_point_m or ())} lies on no planar face of the work object"
            )
        return surface_samples(mesh, region.max_points, np.flatnonzero(faces.face_id == fid))
    return surface_samples(mesh, region.max_points)


def poi_rows(spec: ReportSpec, mesh: trimesh.Trimesh) -> list[RowSpec]:
    """The rows of the points of interest (default: the surface point farthest from the
    origin), in the plan's order; the layout quality and the report share them."""
    pois: Sequence[PointOfInterest] = (
        spec.points_of_interest
        if spec.points_of_interest is not None
        else default_points_of_interest(mesh)
    )
    return [
        RowSpec(
            key=f"{poi.components}_{poi.name}",
            label=poi.label or _label(poi.components, f"at {poi.name}"),
            unit="mm",
            levels_percent=poi.levels_percent or spec.levels_percent,
            points_wobj=np.asarray([poi.position_m], dtype=np.float64),
            components=poi.components,
        )
        for poi in pois
    ]


def report_rows(
    spec: ReportSpec,
    mesh: trimesh.Trimesh,
    geometry: StatorGeometry | None = None,
    xoffset: XOffsetSetup | None = None,
) -> list[RowSpec]:
    """The rows of a plan's report, in order: frame, points of interest, regions, x-offset."""
    levels = spec.levels_percent
    rows = frame_rows(levels) + poi_rows(spec, mesh)
    regions = spec.regions if spec.regions is not None else [RegionSpec(name="part")]
    for region in regions:
        rows.append(
            RowSpec(
                key=f"{region.components}_{region.name}",
                label=region.label or _label(region.components, f"over {region.name}"),
                unit="mm",
                levels_percent=region.levels_percent or levels,
                points_wobj=region_points(region, mesh, geometry),
                components=region.components,
            )
        )
    if xoffset is not None:
        targets = xoffset.targets_wobj.reshape(-1, 3)
        bulge = xoffset.holes_wobj.reshape(-1, 3) - targets
        labels = (
            "slot-hole target x error, targets at x = 0",
            "slot-hole target x error, x from the x-offset matrix (eq. 13-14)",
        )
        for key, label, offset in zip(XOFFSET_KEYS, labels, (bulge, None), strict=True):
            # without the matrix: the frame's error at the target minus the true hole's x
            # (the bulge); with it, the trials return the target errors themselves
            rows.append(
                RowSpec(
                    key=key,
                    label=label,
                    unit="mm",
                    levels_percent=levels,
                    points_wobj=targets,
                    components="x",
                    offset_m=offset,
                )
            )
    return rows
