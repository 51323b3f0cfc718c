"""Uploading a part: its size in each unit before it is accepted, and the plan's points that
no longer lie on the new surface (listed, then dropped or projected onto it).

:class:`PendingPart` holds an uploaded mesh until the user accepts it: the mesh is read once
(raw file coordinates) and :meth:`PendingPart.describe` gives its size in the chosen units,
including what ``auto`` would pick (:func:`planner.cell.scene.load_work_object`, the
loader every plan uses). :func:`off_surface` lists the points farther than
:data:`OFF_SURFACE_M` from a mesh; :func:`project_points` and :func:`drop_points` are the two
fixes, each a pure edit of the UI plan. A new part starts with its file's own frame as the
work-object frame unless the user keeps the earlier one (:func:`frame_note` says which).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from calib.units import AUTO, metres_per_unit
from planner.cad.occt_read import is_cad_path
from planner.cell.scene import load_work_object
from webui import plan_doc
from webui.plan_doc import UiPlan
from webui.surface import SurfacePicker

#: A point farther than this from the new surface no longer lies on it, m (the plan check's
#: own distance limit).
OFF_SURFACE_M = 1.0e-3


@dataclass(frozen=True)
class PendingPart:
    """An uploaded mesh waiting for the user's choice of units.

    Attributes:
        name: the file's name as the user uploaded it.
        path: where the upload is kept.
        digest: its SHA-256.
        raw_extents: ``(3,)`` the mesh's extents in file units (numbers as in the file); for
            a CAD file, metres.
        cad_unit: for a CAD file (STEP/IGES), the length unit it declares (the units the
            user picks do not apply); ``None`` for a mesh file.
    """

    name: str
    path: Path
    digest: str
    raw_extents: tuple[float, float, float]
    cad_unit: str | None = None

    @classmethod
    def read(cls, name: str, path: Path, digest: str) -> PendingPart:
        """Read the kept upload once (raises ``MeshError`` naming ``name`` when unreadable,
        or when a CAD file holds several bodies: the plan's ``work_object.body`` chooses)."""
        cad = is_cad_path(path)
        wobj = load_work_object(path, units=AUTO if cad else "m", name=Path(name).stem)
        e = np.asarray(wobj.mesh.extents, dtype=np.float64)
        unit = wobj.report.units if cad else None
        return cls(name, path, digest, (float(e[0]), float(e[1]), float(e[2])), unit)

    @property
    def units(self) -> str | None:
        """The plan's ``units`` for this part when the file fixes them (``"auto"`` for a CAD
        file), ``None`` when the user's choice applies."""
        return None if self.cad_unit is None else AUTO

    def size_m(self, units: str) -> np.ndarray:
        """``(3,)`` the part's size in metres if its file is in ``units`` (not ``auto``; a CAD
        file's own unit whatever ``units``)."""
        if self.cad_unit is not None:
            return np.asarray(self.raw_extents)
        return np.asarray(self.raw_extents) * metres_per_unit(units)

    def auto_units(self, reach_m: float | None) -> str:
        """The unit ``auto`` picks for this file (the loader's rule)."""
        return load_work_object(self.path, units=AUTO, reach_m=reach_m).report.units

    def describe(self, units: str, reach_m: float | None = None) -> str:
        """E.g. ``plate.stl in mm: 300.0 x 200.0 x 20.0 mm``; ``auto`` names its pick; a CAD
        file names the unit it declares."""
        if self.cad_unit is not None:
            size = " x ".join(f"{v * 1e3:.1f}" for v in self.size_m(AUTO))
            return f"{self.name} in {self.cad_unit} (declared in the file): {size} mm"
        picked = self.auto_units(reach_m) if units == AUTO else units
        size = " x ".join(f"{v * 1e3:.1f}" for v in self.size_m(picked))
        how = f"auto picks {picked}" if units == AUTO else f"in {units}"
        return f"{self.name} {how}: {size} mm"


def off_surface(plan: UiPlan, mesh: trimesh.Trimesh) -> dict[str, float]:
    """``{point id: distance to the surface, m}`` of the points not on ``mesh`` (wobj frame)."""
    if not plan.points:
        return {}
    pts = np.array([p.probe.position_m for p in plan.points], dtype=np.float64)
    _, dist, _ = trimesh.proximity.closest_point(mesh, pts)
    return {p.id: float(d) for p, d in zip(plan.points, dist, strict=True) if d > OFF_SURFACE_M}


def project_points(plan: UiPlan, picker: SurfacePicker, ids: list[str]) -> UiPlan:
    """``plan`` with the points ``ids`` moved to the nearest surface point (and its normal)."""
    for pid in ids:
        hit = picker.project(plan.get(pid).probe.position_m)
        plan = plan_doc.place_point(plan, pid, hit.position_wobj, hit.normal_wobj)
    return plan


def drop_points(plan: UiPlan, ids: list[str]) -> UiPlan:
    """``plan`` without the points ``ids``."""
    for pid in ids:
        plan = plan_doc.delete_point(plan, pid)
    return plan


def frame_note(had_frame: bool, kept: bool) -> str:
    """What became of the earlier part's 3-point frame (``work_object.T_wobj_mesh``)."""
    if not had_frame:
        return ""
    if kept:
        return "; the earlier part's work-object frame (T_wobj_mesh) is kept"
    return (
        "; its work-object frame is the file's own (T_wobj_mesh identity): the earlier "
        "part's 3-point frame was not kept (tick Keep work-object frame to keep it)"
    )
