"""A CAD part as a triangle mesh in metres, its unit from the file, cached by the file's hash.

:func:`load_cad_mesh` reads a STEP/IGES file (:mod:`planner.cad.occt_read`), takes the chosen
body or bodies, triangulates them (:mod:`planner.cad.tessellate`) and scales them to metres by
the file's declared unit. Each triangle keeps, in ``mesh.face_attributes[BREP_PLANE]``, the
index of the B-rep plane it lies on (``-1`` on a curved face), which
:func:`planner.faces.detection.find_planar_faces` uses instead of clustering triangles.

The unit (:func:`cad_units`): the plan's ``units`` must be ``auto`` or the file's own unit; a
contradiction is an error naming both. A STEP file that declares no length unit is refused
unless the plan names one (then that unit, stated by the user, is used: never a guess).

The triangulation is cached on disk (:mod:`planner.cell.disk_cache`, kind ``cad_mesh``) under
the file's SHA-256, the body chosen, the plan's units, the tolerances and the version of the
OpenCASCADE bindings (:func:`mesher_version`): a second load of the
same file skips OpenCASCADE (and its import). The cache is optional: when it cannot be written
the command only runs slower.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib.metadata
import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from calib.units import AUTO, METRES_PER_UNIT
from planner.cad.occt_read import ALL_BODIES, MODEL_UNIT_M, choose_bodies, read_cad_file
from planner.cad.tessellate import (
    ANGULAR_DEFLECTION_RAD,
    LINEAR_DEFLECTION_MM,
    PLANE_TOL_MM,
    tessellate,
)
from planner.errors import MeshError
from planner.faces.array_cache import ArrayCache as ArrayCache
from planner.faces.brep import BREP_PLANE

log = logging.getLogger(__name__)

#: The disk cache kind of CAD triangulations, and the version of what it stores.
CACHE_KIND = "cad_mesh"
CACHE_VERSION = 1


@dataclass(frozen=True)
class CadInfo:
    """What reading a CAD part found.

    Attributes:
        fmt: ``"step"`` or ``"iges"``.
        file_unit: the length unit the file declares (canonical name such as ``"in"``, or
            the file's spelling of another unit), ``None`` when it declares none.
        unit: the unit the part was read in (``file_unit``, or the plan's for a file
            without one).
        body: the name of the body the part is, or ``"all"``.
        bodies: the names of all the file's bodies.
        n_brep_faces: B-rep faces triangulated.
        n_planes: how many of them are planes.
        linear_mm: chord tolerance of the triangulation, mm.
        angular_rad: angular deflection of the triangulation, rad.
        untriangulated: B-rep faces OpenCASCADE could not triangulate.
        cached: the triangulation came from the disk cache.
    """

    fmt: str
    file_unit: str | None
    unit: str
    body: str
    bodies: tuple[str, ...]
    n_brep_faces: int
    n_planes: int
    linear_mm: float
    angular_rad: float
    untriangulated: int
    cached: bool

    @property
    def note(self) -> str:
        """The unit and body in words, e.g. ``"STEP in 'in' (declared in the file), body
        'box_base' of 10"``."""
        how = "declared in the file" if self.file_unit else "the file declares none: as given"
        of = ""
        if self.body == ALL_BODIES:
            of = f", all {len(self.bodies)} bodies as one rigid part"
        elif len(self.bodies) > 1:
            of = f", body {self.body!r} of {len(self.bodies)}"
        return f"{self.fmt.upper()} in {self.unit!r} ({how}){of}"


def cad_units(declared: str | None, given: str, source: str) -> tuple[str, float]:
    """The unit a CAD part is read in, and the factor its transferred numbers (millimetres,
    or the file's bare numbers when it declares no unit) take to become millimetres.

    Args:
        declared: the file's unit (:attr:`planner.cad.occt_read.CadFile.unit`).
        given: the plan's canonical ``units`` (``"auto"`` or a name of
            :data:`calib.units.METRES_PER_UNIT`).
        source: the file, for messages.

    Raises:
        MeshError: the plan's units contradict the file's (naming both), or the file declares
            none and the plan says ``auto``.
    """
    if declared is None:
        if given == AUTO:
            raise MeshError(
                f"{source}: the STEP file declares no length unit (no LENGTH_UNIT in its "
                "representation context), so its size is unknown; set work_object.units to the "
                "unit it was modelled in (m, mm, cm or in)"
            )
        return given, METRES_PER_UNIT[given] / MODEL_UNIT_M
    if given not in (AUTO, declared):
        raise MeshError(
            f"{source}: work_object.units is {given!r} but the file declares its length unit "
            f"as {declared!r}; set units to 'auto' or {declared!r}"
            + ("" if declared in METRES_PER_UNIT else " ('auto': wobjcal has no such name)")
        )
    return declared, 1.0


def mesher_version() -> str:
    """The installed OpenCASCADE bindings' version (``cadquery-ocp-novtk`` or
    ``cadquery-ocp``), read from the package metadata without importing OCP; ``"unknown"``
    when neither is installed. Another OpenCASCADE meshes differently, so it is in the key."""
    for dist in ("cadquery-ocp-novtk", "cadquery-ocp"):
        with contextlib.suppress(importlib.metadata.PackageNotFoundError):
            return f"{dist}=={importlib.metadata.version(dist)}"
    return "unknown"


def _key(
    digest: str, body: str | int | None, units: str, linear_mm: float, angular_rad: float
) -> str:
    """The cache key: everything the stored arrays depend on besides the code
    (:data:`CACHE_VERSION`): the file's content, the body, the units, the tolerances, the plane
    test's tolerance and the OpenCASCADE that meshed it."""
    sel = "none" if body is None else f"{type(body).__name__}:{body}"
    text = (
        f"{digest} {sel} {units} {linear_mm!r} {angular_rad!r} {PLANE_TOL_MM!r} {mesher_version()}"
    )
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:40]


def _strings(values: tuple[str, ...]) -> np.ndarray:
    return np.array(values, dtype=str) if values else np.zeros(0, dtype="<U1")


def load_cad_mesh(
    path: Path,
    body: str | int | None = None,
    units: str = AUTO,
    linear_mm: float = LINEAR_DEFLECTION_MM,
    angular_rad: float = ANGULAR_DEFLECTION_RAD,
    cache: ArrayCache | None = None,
) -> tuple[trimesh.Trimesh, CadInfo]:
    """Read a STEP/IGES part as a triangle mesh in the file's frame, metres.

    Args:
        path: the ``.step``/``.stp``/``.iges``/``.igs`` file.
        body: which body (name, 0-based index, or ``"all"``); ``None``: the file must hold one.
        units: the plan's canonical ``units`` (``"auto"`` or a name); see :func:`cad_units`.
        linear_mm: chord tolerance of the triangulation, mm.
        angular_rad: angular deflection of the triangulation, rad.
        cache: where the triangulation is kept by the file's hash (``None``: not kept).

    Returns:
        The mesh (unprocessed: faces do not share vertices yet; ``face_attributes[BREP_PLANE]``
        set) and what was read.

    Raises:
        MeshError: the file cannot be read, holds no solid, several bodies and no choice, or
            its unit is missing or contradicts ``units``; each message names the file.
    """
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    key = _key(digest, body, units, linear_mm, angular_rad)
    stored = None if cache is None else cache.load_arrays(CACHE_KIND, key, CACHE_VERSION)
    cached = stored is not None
    if stored is None:
        cad = read_cad_file(path)
        chosen, name = choose_bodies(cad, body)
        _, factor = cad_units(cad.unit, units, str(path))  # refuse before meshing
        try:  # the chord tolerance in true millimetres, also for a file without a unit
            tess = tessellate([b.shape for b in chosen], linear_mm / factor, angular_rad)
        except MeshError as exc:
            raise MeshError(f"{path}: {exc}") from None
        stored = {
            "vertices_mm": tess.vertices_mm,
            "faces": tess.faces,
            "brep_face": tess.brep_face,
            "planar": tess.planar,
            "untriangulated": np.array(tess.untriangulated),
            "unit_names": _strings(cad.unit_names),
            "bodies": _strings(tuple(b.name for b in cad.bodies)),
            "fmt": np.array(cad.fmt),
            "name": np.array(ALL_BODIES if body == ALL_BODIES else name),
            "file_unit": np.array(cad.unit or ""),
        }
        if cache is not None:
            cache.save_arrays(CACHE_KIND, key, CACHE_VERSION, stored)
    file_unit = str(stored["file_unit"]) or None
    unit, factor = cad_units(file_unit, units, str(path))
    planar = np.asarray(stored["planar"], dtype=bool)
    owner = np.asarray(stored["brep_face"], dtype=np.int64)
    vertices = np.asarray(stored["vertices_mm"], dtype=np.float64) * (factor * MODEL_UNIT_M)
    mesh = trimesh.Trimesh(vertices, np.asarray(stored["faces"], np.int64), process=False)
    mesh.face_attributes[BREP_PLANE] = np.where(planar[owner], owner, -1)
    info = CadInfo(
        fmt=str(stored["fmt"]),
        file_unit=file_unit,
        unit=unit,
        body=str(stored["name"]),
        bodies=tuple(str(b) for b in stored["bodies"]),
        n_brep_faces=len(planar),
        n_planes=int(planar.sum()),
        linear_mm=linear_mm,
        angular_rad=angular_rad,
        untriangulated=int(stored["untriangulated"]),
        cached=cached,
    )
    log.info("%s: %s, %d triangles", path, info.note, len(mesh.faces))
    return mesh, info
