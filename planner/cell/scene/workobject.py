"""Work-object meshes: loading any format trimesh reads, units, light repair, PyBullet body.

Units: a name of :data:`calib.units.MESH_UNITS` (``"m"``, ``"mm"``, ``"cm"``, ``"in"``, ``"auto"``)
or an alias of :data:`calib.units.ALIASES` (e.g. ``"inch"``), the same table the plan uses.
The ``auto`` rule (:func:`auto_units`) weighs the file's own unit hints and the cell's scale:

1. a unit the file names (the loader's ``units``, a token of the STL header or the file name
   such as ``_mm`` or ``inch``) is taken when it gives a plausible part;
2. otherwise each unit is tried in the order m, mm, in, cm and the first that gives a plausible
   part is taken: largest extent at least :data:`MIN_PART_M` (10 mm, about the sensor face)
   and at most twice the robot's reach (a part the robot can work on from one side to the
   other; the reach is the cell's :class:`planner.robot.reach.ReachModel`, or
   :data:`DEFAULT_REACH_M` without a cell);
3. when no unit does, metres, with a warning.

Loading always says, in :attr:`RepairReport.units_note` and the log, the unit it used (and why,
for ``auto``) and the part's resulting size; a part given in explicit units that comes out
larger than twice the reach or smaller than 10 mm gets a warning naming the unit that would fit.

Repair is light and reported: merge duplicate vertices, drop degenerate faces (zero area, or
smaller than (1e-6 x the largest extent)^2) and duplicate faces
and unreferenced vertices, and, for a watertight mesh only, make the winding consistent with
outward normals. Open meshes (scans) keep their normals and load with a warning.

A CAD file (STEP, IGES: :mod:`planner.cad`) is not guessed at: its unit is the one the file
declares (``units`` must be ``auto`` or agree), one body is chosen (``body``), and its triangles
keep the B-rep plane they lie on, which planar-face detection uses (:mod:`planner.faces.brep`).

In PyBullet the work object is a *concave* static body (``GEOM_FORCE_CONCAVE_TRIMESH``, mass 0):
without that flag PyBullet would use the convex hull and fill every hole and slot.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import trimesh
from numpy.typing import NDArray

from calib.errors import InputError
from calib.limits import MAX_CAD_FILE_BYTES, MAX_CELL_TRIANGLES, MAX_MESH_TRIANGLES, MiB
from calib.reading import MAX_MESH_BYTES, check_regular_file
from calib.units import AUTO, METRES_PER_UNIT, canonical_unit
from planner.builtins import builtin_mesh, is_builtin
from planner.cad.occt_read import is_cad_path
from planner.cell.scene.bodies import BodyLinks, mesh_collision_shape, static_body
from planner.cell.scene.mesh_units import (
    DEFAULT_REACH_M,
    auto_units,
    implausible_units_warning,
    unit_hint,
)
from planner.errors import MeshError

if TYPE_CHECKING:
    from planner.cad.part import CadInfo

FloatArray = NDArray[np.float64]
log = logging.getLogger(__name__)


@dataclass(frozen=True)
class RepairReport:
    """What loading did to a mesh.

    Attributes:
        source: file path or name the mesh came from.
        units: the canonical unit used (``"m"``, ``"mm"``, ``"cm"``, ``"in"``).
        units_detected: True when ``units`` came from the ``auto`` rule.
        scale: metres per file unit applied.
        extents_m: ``(3,)`` the part's bounding-box size after scaling, metres.
        units_note: the unit used, why (for ``auto``) and the part's size, in words.
        merged_vertices: vertices removed by merging duplicates.
        removed_degenerate_faces: zero-area faces removed.
        removed_duplicate_faces: duplicate faces removed.
        fixed_winding: True when faces were re-wound for consistent outward normals.
        watertight: True when the repaired mesh is closed.
        boundary_edges: number of open (boundary) edges, 0 for a closed mesh.
        n_vertices: vertex count after repair.
        n_faces: face count after repair.
        warnings: human-readable warnings (also logged).
        units_declared: the unit is the one a CAD file declares (not the plan's, not guessed).
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
    extents_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    units_note: str = ""
    units_declared: bool = False

    @property
    def size_text(self) -> str:
        """The part's size and units in words, e.g. ``"0.203 x 0.305 x 0.013 m (file in mm)"``."""
        dims = " x ".join(f"{v:.3g}" for v in self.extents_m)
        how = (
            "declared in the file"
            if self.units_declared
            else "detected"
            if self.units_detected
            else "given"
        )
        return f"{dims} m (file units {self.units!r}, {how})"


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


def _too_many(path: object, n: int, limit: int = MAX_MESH_TRIANGLES) -> MeshError:
    which = (
        f"wobjcal takes at most {limit:,}"
        if limit >= MAX_MESH_TRIANGLES
        else f"the cell's other meshes leave {limit:,} of the {MAX_CELL_TRIANGLES:,} a cell takes"
    )
    return MeshError(
        f"{path}: {n:,} triangles; {which} (validate holds about 2.6 kB a triangle: 500,000 "
        "are 1.6 GB of the 2 GB a command stays within): decimate it first (e.g. MeshLab's "
        "quadric edge collapse)"
    )


def stl_triangle_count(path: Path, size: int) -> int | None:
    """The triangle count of a binary STL from its header, ``None`` for an ASCII STL.

    Raises:
        MeshError: a binary STL whose size does not match its header (truncated, corrupt).
    """
    with path.open("rb") as handle:
        head = handle.read(84)
    if len(head) < 84:
        if head.lstrip().lower().startswith(b"solid"):
            return None
        raise MeshError(f"{path}: {size} bytes is too short for an STL file (corrupt?)")
    n = int.from_bytes(head[80:84], "little")
    if size == 84 + 50 * n:
        return n
    if head.lstrip().lower().startswith(b"solid"):
        return None  # ASCII (a binary STL may also start with "solid": then the size matches)
    raise MeshError(
        f"{path}: corrupt binary STL: its header says {n:,} triangles ({84 + 50 * n:,} bytes), "
        f"the file has {size:,} bytes"
    )


def _read(
    source: str | Path | trimesh.Trimesh,
    limit: int = MAX_MESH_TRIANGLES,
    units: str = AUTO,
    body: str | int | None = None,
) -> tuple[trimesh.Trimesh, str, CadInfo | None]:
    if isinstance(source, trimesh.Trimesh):
        meta = source.metadata or {}
        if len(source.faces) > limit:
            raise _too_many(meta.get("name") or "work object", len(source.faces), limit)
        return source.copy(), str(meta.get("name") or "work object"), None
    if is_builtin(source):
        return builtin_mesh(str(source)), str(source), None
    path = Path(source)
    try:
        size = check_regular_file(path, MAX_MESH_BYTES, "mesh file", MeshError)
    except FileNotFoundError:
        raise MeshError(f"mesh file not found: {path}") from None
    if is_cad_path(path):  # STEP/IGES: planner.cad, in metres and the file's own unit
        from planner.cad.part import load_cad_mesh

        if size > MAX_CAD_FILE_BYTES:
            raise MeshError(
                f"{path}: {size / MiB:,.1f} MiB, at most {MAX_CAD_FILE_BYTES // MiB} MiB for a "
                "CAD file (OpenCASCADE holds its model in memory, ~12 times the file; a "
                "machined part's STEP is a few MB: export the one part, or simplify it)"
            )

        from planner.cell import disk_cache

        part, cad = load_cad_mesh(path, body=body, units=units, cache=disk_cache)
        if len(part.faces) > limit:
            raise _too_many(path, len(part.faces), limit)
        return part, str(path), cad
    with path.open("rb") as handle:
        if handle.read(64).lstrip().upper().startswith(b"ISO-10303-21"):
            raise MeshError(
                f"{path}: a STEP file (it starts with 'ISO-10303-21;') named {path.suffix!r}: "
                "rename it .step (or .stp) to read it as CAD"
            )
    if body is not None:
        raise MeshError(
            f"work_object.body {body!r}: {path} is a mesh file, which has no bodies to choose "
            "from (body is for STEP/IGES files)"
        )
    if path.suffix.lower() == ".stl":
        n = stl_triangle_count(path, size)
        if n is not None and n > limit:
            raise _too_many(path, n, limit)  # before a byte of geometry is parsed
    try:
        mesh = trimesh.load(str(path), force="mesh", process=False)
    except Exception as exc:  # trimesh raises many types for unreadable files
        raise MeshError(f"cannot read mesh file {path}: {exc}") from None
    if not isinstance(mesh, trimesh.Trimesh):
        raise MeshError(f"mesh file {path} holds no triangle mesh (got {type(mesh).__name__})")
    if len(mesh.faces) == 0 and size > 0:
        if path.suffix.lower() == ".stl" and (cut := _ascii_stl_cut_short(path)):
            raise MeshError(f"mesh file {path}: {cut}")
        raise MeshError(
            f"mesh file {path}: no triangle could be read from its {size:,} bytes (corrupt, or "
            f"not a {path.suffix.lstrip('.').upper() or 'mesh'} file)"
        )
    if len(mesh.faces) > limit:
        raise _too_many(path, len(mesh.faces), limit)
    return mesh, str(path), None


def _ascii_stl_cut_short(path: Path) -> str:
    """Why an ASCII STL that gave no triangle is cut short (``""``: it does not look so): it
    starts with ``solid`` and holds facets, but its last line is not ``endsolid`` (a file cut
    in a copy or an upload; the reader then refuses the whole file)."""
    with path.open("rb") as handle:
        if not handle.read(256).lstrip().lower().startswith(b"solid"):
            return ""
        handle.seek(0)
        text = handle.read().decode("ascii", errors="replace")
    facets = text.count("endfacet")
    lines = text.rstrip().splitlines()
    if facets == 0 or (lines and lines[-1].strip().lower().startswith("endsolid")):
        return ""
    return (
        f"an ASCII STL cut short: {facets:,} whole facets, then it ends without its "
        f"'endsolid' line (last line {lines[-1].strip()[:40]!r}); the file is incomplete: "
        "copy or export it again"
    )


def load_work_object(
    source: str | Path | trimesh.Trimesh,
    units: str = "auto",
    name: str | None = None,
    reach_m: float | None = None,
    max_triangles: int = MAX_MESH_TRIANGLES,
    body: str | int | None = None,
) -> WorkObject:
    """Load, scale and lightly repair a work-object mesh.

    Args:
        source: a mesh file (STL, OBJ, PLY, GLB, ... anything trimesh reads), a CAD file
            (STEP ``.step``/``.stp``, IGES ``.iges``/``.igs``: :mod:`planner.cad`), a
            ``trimesh.Trimesh``, or ``"builtin:<name>"`` (see :mod:`planner.builtins`).
        units: a unit of :mod:`calib.units` (``"m"``, ``"mm"``, ``"cm"``, ``"in"``, an alias
            such as ``"inch"``) or ``"auto"`` (see the module docstring). A CAD file declares
            its own: ``units`` must then be ``"auto"`` or that unit
            (:func:`planner.cad.part.cad_units`).
        name: a short name; default the file stem.
        reach_m: the robot's reach, m, for ``auto`` and the size warning; default
            :data:`DEFAULT_REACH_M`.
        max_triangles: refuse a mesh of more triangles (before its geometry is parsed when
            it is a binary STL); default :data:`calib.limits.MAX_MESH_TRIANGLES`.
        body: for a STEP/IGES file, the body to load: its name, its 0-based index or
            ``"all"`` (the bodies as one rigid part); ``None``: the file must hold one body.
            Must be ``None`` for a mesh file.

    Raises:
        MeshError: missing or unreadable file, empty mesh, NaN/infinite vertices, bad units;
            the message names the file.
    """
    try:
        units = canonical_unit(units, f"units for {source}")
    except InputError as exc:
        raise MeshError(str(exc)) from None
    mesh, src, cad = _read(source, max_triangles, units, body)
    if len(mesh.faces) == 0 or len(mesh.vertices) == 0:
        raise MeshError(f"mesh {src} is empty (no faces)")
    if not np.all(np.isfinite(mesh.vertices)):
        raise MeshError(f"mesh {src} holds NaN or infinite vertex coordinates")
    warnings: list[str] = []
    reach = DEFAULT_REACH_M if reach_m is None else float(reach_m)
    extent = float(np.max(mesh.extents))
    detected = units == AUTO and cad is None
    if cad is not None:  # the file declares its unit (planner.cad.part.cad_units)
        units, note = cad.unit, cad.note
    elif detected:
        units, why = auto_units(extent, unit_hint(mesh, src), reach)
        note = f"units 'auto' read as {units!r}: {why}"
    else:
        note = f"units {units!r} as given"
        warning = implausible_units_warning(src, extent, units, reach)
        if warning:
            warnings.append(warning)
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
    if cad is None:
        scale = METRES_PER_UNIT[units]
        mesh.apply_scale(scale)
    else:  # already in metres; the scale the file's unit stands for
        scale = METRES_PER_UNIT.get(units, float("nan"))
    ext = tuple(float(v) for v in mesh.extents)
    dims = " x ".join(f"{v:.3g}" for v in ext)
    note = f"{src}: {note}; the part is {dims} m"
    if detected or cad is not None:  # a unit wobjcal did not get from the plan: said
        warnings.insert(0, note)
    else:
        log.info(note)
    for w in warnings:
        log.warning(w)
    report = RepairReport(
        source=src,
        units=units,
        units_detected=detected,
        units_declared=cad is not None and cad.file_unit is not None,
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
        extents_m=(ext[0], ext[1], ext[2]),
        units_note=note,
    )
    stem = src.split(":", 1)[1] if is_builtin(src) else Path(src).stem or src
    return WorkObject(name=name or stem, mesh=mesh, report=report)
