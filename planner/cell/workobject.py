"""Work-object meshes: loading any format trimesh reads, units, light repair, PyBullet body.

Units: a name of :data:`calib.units.MESH_UNITS` (``"m"``, ``"mm"``, ``"cm"``, ``"in"``, ``"auto"``)
or an alias of :data:`calib.units.ALIASES` (e.g. ``"inch"``), the same table the plan uses.
The ``auto`` rule: a mesh whose largest bounding-box extent exceeds :data:`AUTO_MM_EXTENT` (20)
is taken as millimetres, with a warning; otherwise as metres. A 20 m work object is implausible
for a robot cell, and a part drawn in mm is rarely smaller than 20 mm.

Repair is light and reported: merge duplicate vertices, drop degenerate faces (zero area, or
smaller than (1e-6 x the largest extent)^2) and duplicate faces
and unreferenced vertices, and, for a watertight mesh only, make the winding consistent with
outward normals. Open meshes (scans) keep their normals and load with a warning.

In PyBullet the work object is a *concave* static body (``GEOM_FORCE_CONCAVE_TRIMESH``, mass 0):
without that flag PyBullet would use the convex hull and fill every hole and slot.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import trimesh
from numpy.typing import NDArray

from calib.errors import InputError
from calib.units import AUTO, METRES_PER_UNIT, canonical_unit
from planner.builtins import builtin_mesh, is_builtin
from planner.cell.bodies import BodyLinks, mesh_collision_shape, static_body
from planner.errors import MeshError

FloatArray = NDArray[np.float64]
log = logging.getLogger(__name__)

#: ``units="auto"``: a larger extent than this (in file units) means millimetres.
AUTO_MM_EXTENT = 20.0


@dataclass(frozen=True)
class RepairReport:
    """What loading did to a mesh.

    Attributes:
        source: file path or name the mesh came from.
        units: the canonical unit used (``"m"``, ``"mm"``, ``"cm"``, ``"in"``).
        units_detected: True when ``units`` came from the ``auto`` rule.
        scale: metres per file unit applied.
        merged_vertices: vertices removed by merging duplicates.
        removed_degenerate_faces: zero-area faces removed.
        removed_duplicate_faces: duplicate faces removed.
        fixed_winding: True when faces were re-wound for consistent outward normals.
        watertight: True when the repaired mesh is closed.
        boundary_edges: number of open (boundary) edges, 0 for a closed mesh.
        n_vertices: vertex count after repair.
        n_faces: face count after repair.
        warnings: human-readable warnings (also logged).
    """

    source: str
    units: str
    units_detected: bool
    scale: float
    merged_vertices: int
    removed_degenerate_faces: int
    removed_duplicate_faces: int
    fixed_winding: bool
    watertight: bool
    boundary_edges: int
    n_vertices: int
    n_faces: int
    warnings: tuple[str, ...] = ()


@dataclass(frozen=True)
class WorkObject:
    """A work-object mesh in its own frame (wobj), metres.

    Attributes:
        name: a short name, e.g. the file stem.
        mesh: the repaired mesh, wobj frame, metres.
        report: what loading and repair did.
    """

    name: str
    mesh: trimesh.Trimesh = field(repr=False)
    report: RepairReport

    def create_body(self, client: int, T_world_wobj: FloatArray) -> BodyLinks:
        """Add the mesh to PyBullet ``client`` as a concave static body at ``T_world_wobj``."""
        shape = mesh_collision_shape(client, self.mesh, concave=True, source=self.report.source)
        return static_body(client, shape, T_world_wobj, self.name)


def _read(source: str | Path | trimesh.Trimesh) -> tuple[trimesh.Trimesh, str]:
    if isinstance(source, trimesh.Trimesh):
        meta = source.metadata or {}
        return source.copy(), str(meta.get("name") or "work object")
    if is_builtin(source):
        return builtin_mesh(str(source)), str(source)
    path = Path(source)
    if not path.is_file():
        raise MeshError(f"mesh file not found: {path}")
    try:
        mesh = trimesh.load(str(path), force="mesh", process=False)
    except Exception as exc:  # trimesh raises many types for unreadable files
        raise MeshError(f"cannot read mesh file {path}: {exc}") from None
    if not isinstance(mesh, trimesh.Trimesh):
        raise MeshError(f"mesh file {path} holds no triangle mesh (got {type(mesh).__name__})")
    return mesh, str(path)


def load_work_object(
    source: str | Path | trimesh.Trimesh, units: str = "auto", name: str | None = None
) -> WorkObject:
    """Load, scale and lightly repair a work-object mesh.

    Args:
        source: a mesh file (STL, OBJ, PLY, GLB, ... anything trimesh reads), a
            ``trimesh.Trimesh``, or ``"builtin:<name>"`` (see :mod:`planner.builtins`).
        units: a unit of :mod:`calib.units` (``"m"``, ``"mm"``, ``"cm"``, ``"in"``, an alias
            such as ``"inch"``) or ``"auto"`` (see the module docstring).
        name: a short name; default the file stem.

    Raises:
        MeshError: missing or unreadable file, empty mesh, NaN/infinite vertices, bad units;
            the message names the file.
    """
    mesh, src = _read(source)
    try:
        units = canonical_unit(units, f"units for {src}")
    except InputError as exc:
        raise MeshError(str(exc)) from None
    if len(mesh.faces) == 0 or len(mesh.vertices) == 0:
        raise MeshError(f"mesh {src} is empty (no faces)")
    if not np.all(np.isfinite(mesh.vertices)):
        raise MeshError(f"mesh {src} holds NaN or infinite vertex coordinates")
    warnings: list[str] = []
    detected = units == AUTO
    if detected:
        extent = float(np.max(mesh.extents))
        units = "mm" if extent > AUTO_MM_EXTENT else "m"
        if units == "mm":
            warnings.append(
                f"{src}: largest extent {extent:.4g} > {AUTO_MM_EXTENT:g}, taken as millimetres "
                f"(pass units='m' or 'in' if wrong)"
            )
    n_v, n_f = len(mesh.vertices), len(mesh.faces)
    mesh.merge_vertices()
    merged = n_v - len(mesh.vertices)
    # zero-area faces, and slivers smaller than (1 ppm of the extent)^2
    tiny = (1e-6 * float(np.max(mesh.extents))) ** 2
    keep = mesh.nondegenerate_faces() & (mesh.area_faces > tiny)
    degenerate = int((~keep).sum())
    mesh.update_faces(keep)
    n_after = len(mesh.faces)
    mesh.update_faces(mesh.unique_faces())
    duplicates = n_after - len(mesh.faces)
    mesh.remove_unreferenced_vertices()
    if len(mesh.faces) == 0:
        raise MeshError(f"mesh {src} has no usable faces ({n_f} faces were all degenerate)")
    fixed = False
    if mesh.is_watertight:
        before = mesh.faces.copy()
        trimesh.repair.fix_normals(mesh)
        fixed = before.shape != mesh.faces.shape or not np.array_equal(before, mesh.faces)
    boundary = len(trimesh.grouping.group_rows(mesh.edges_sorted, require_count=1))
    if boundary:
        warnings.append(f"{src}: open mesh with {boundary} boundary edges; normals kept as given")
    scale = METRES_PER_UNIT[units]
    mesh.apply_scale(scale)
    for w in warnings:
        log.warning(w)
    report = RepairReport(
        source=src,
        units=units,
        units_detected=detected,
        scale=scale,
        merged_vertices=merged,
        removed_degenerate_faces=degenerate,
        removed_duplicate_faces=duplicates,
        fixed_winding=fixed,
        watertight=bool(mesh.is_watertight),
        boundary_edges=boundary,
        n_vertices=len(mesh.vertices),
        n_faces=len(mesh.faces),
        warnings=tuple(warnings),
    )
    stem = src.split(":", 1)[1] if is_builtin(src) else Path(src).stem or src
    return WorkObject(name=name or stem, mesh=mesh, report=report)
