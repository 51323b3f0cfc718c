"""The measurement plan ``wobjcal.plan/1``: typed, strict, versioned JSON.

A plan holds everything needed to check, validate, export and evaluate one work-object
calibration: the cell (robot, tool and probing TCP, fixtures), the work object and its nominal
pose, the probe points, the procedure and its settings, and the error models used for validation.
The file format is described in ``docs/plan_format.md``; the JSON Schema generated from these
types is checked in at ``assets/schema/wobjcal.plan-1.schema.json``.

Conventions: metres and radians (field names end in ``_m``, ``_rad``, ``_m_s``), poses as
``{"position_m": [x, y, z], "quat_wxyz": [w, x, y, z]}`` meaning ``T_parent_child``. Paths to
files (URDF, meshes) are relative to the plan file, or ``builtin:NAME``. This module is pure:
msgspec and numpy only, no simulator.
"""

from __future__ import annotations

import hashlib
import math
import re
from pathlib import Path
from typing import Final, Literal, get_args

import msgspec
import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.atomic_io import write_text_atomic
from calib.errors import InputError
from calib.frames import (
    check_transform,
    make_transform,
    matrix_from_quat_wxyz,
    quat_wxyz_from_matrix,
)
from calib.plan_json import canonical_json, check_schema_tag, convert_strict, parse_json_text
from calib.plan_procedures import METHODS, Procedure, check_roles, method_of
from calib.probing import ProbePoint, SearchSpec

PLAN_SCHEMA: Final = "wobjcal.plan/1"
SUPPORTED_PLAN_SCHEMAS = (PLAN_SCHEMA,)
BUILTIN_PREFIX = "builtin:"
MeshUnits = Literal["m", "mm", "cm", "in", "auto"]
Vec3 = tuple[float, float, float]
_UNIT_TOL = 1e-6
_SHA256_RE = re.compile(r"^[0-9a-f]{64}$")


class PlanError(InputError):
    """A plan file or plan object is malformed; the message names the file and JSON path."""


class _Strict(msgspec.Struct, frozen=True, forbid_unknown_fields=True, kw_only=True):
    """Base of the plan structs: immutable, unknown fields rejected."""


def _check_finite(values: tuple[float, ...] | None, field: str) -> None:
    if values is not None and not all(math.isfinite(v) for v in values):
        raise PlanError(f"{field}: must hold finite numbers, got {list(values)}")


def _check_unit(values: tuple[float, ...] | None, field: str) -> None:
    if values is None:
        return
    _check_finite(values, field)
    norm = math.sqrt(sum(v * v for v in values))
    if abs(norm - 1.0) > _UNIT_TOL:
        raise PlanError(f"{field}: must be a unit vector, got length {norm:.6g}")


def _check_positive(value: float, field: str, allow_zero: bool = False) -> None:
    if not math.isfinite(value) or value < 0 or (value == 0 and not allow_zero):
        raise PlanError(f"{field}: must be {'>= 0' if allow_zero else '> 0'}, got {value}")


def _check_sha256(value: str | None, ref: str, field: str) -> None:
    if value is None:
        return
    if ref.startswith(BUILTIN_PREFIX):
        raise PlanError(f"{field}: must be null for a built-in ({ref!r})")
    if not _SHA256_RE.match(value):
        raise PlanError(f"{field}: must be 64 lowercase hex digits, got {value!r}")


class Pose(_Strict, frozen=True, kw_only=True):
    """A rigid transform ``T_parent_child``.

    Attributes:
        position_m: ``(3,)`` origin of the child frame in the parent frame, metres.
        quat_wxyz: ``(4,)`` unit quaternion (w, x, y, z) of the child's rotation in the parent.
    """

    position_m: Vec3 = (0.0, 0.0, 0.0)
    quat_wxyz: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        _check_finite(self.position_m, "position_m")
        _check_unit(self.quat_wxyz, "quat_wxyz")

    def matrix(self) -> NDArray[np.float64]:
        """The 4x4 transform ``T_parent_child``."""
        return make_transform(matrix_from_quat_wxyz(self.quat_wxyz), self.position_m)

    @classmethod
    def from_matrix(cls, T: ArrayLike) -> Pose:
        """The pose of a 4x4 rigid transform (quaternion with ``w >= 0``)."""
        T_arr = check_transform(T, "T")
        q = quat_wxyz_from_matrix(T_arr[:3, :3])
        p = T_arr[:3, 3]
        return cls(
            position_m=(float(p[0]), float(p[1]), float(p[2])),
            quat_wxyz=(float(q[0]), float(q[1]), float(q[2]), float(q[3])),
        )


class RobotSpec(_Strict, frozen=True, kw_only=True):
    """The robot: ``urdf`` is a path relative to the plan or ``builtin:irb4400``.

    Attributes:
        urdf: URDF file or built-in name.
        T_world_base: pose of the robot base in the cell (world) frame.
        base_link: URDF base link (``None``: the URDF's root).
        tip_link: URDF flange link (``None``: ``tool0`` or the single leaf).
    """

    urdf: str = "builtin:irb4400"
    T_world_base: Pose = Pose()
    base_link: str | None = None
    tip_link: str | None = None


class ToolSpec(_Strict, frozen=True, kw_only=True):
    """The robot-held tool: ``name`` is a URDF path or ``builtin:cable_feeder``; ``tcp`` is the
    probing TCP (the proximity sensor at its sensing distance)."""

    name: str = "builtin:cable_feeder"
    tcp: str = "sensor"


class FixtureSpec(_Strict, frozen=True, kw_only=True):
    """A fixed obstacle (table, fixture) for collision checks: a mesh or a box.

    Attributes:
        name: unique fixture name.
        mesh: mesh file (relative to the plan) or ``builtin:NAME``; ``None`` for a box.
        box_size_m: ``(3,)`` edge lengths of a box centred on its frame, m; ``None`` for a mesh.
        units: length unit of the mesh file.
        sha256: hex digest of the mesh file, checked on load (``None``: not checked).
        T_world_fixture: pose of the mesh (or box centre) frame in the world frame.
    """

    name: str
    mesh: str | None = None
    box_size_m: Vec3 | None = None
    units: MeshUnits = "m"
    sha256: str | None = None
    T_world_fixture: Pose = Pose()

    def __post_init__(self) -> None:
        if (self.mesh is None) == (self.box_size_m is None):
            raise PlanError("mesh: give exactly one of mesh and box_size_m")
        if self.box_size_m is not None:
            if not all(math.isfinite(v) and v > 0 for v in self.box_size_m):
                raise PlanError(f"box_size_m: must be 3 lengths > 0, got {list(self.box_size_m)}")
            if self.sha256 is not None:
                raise PlanError("sha256: must be null for a box")
        else:
            _check_sha256(self.sha256, self.mesh or "", "sha256")


class CellSpec(_Strict, frozen=True, kw_only=True):
    """Robot, tool and fixtures of the cell."""

    robot: RobotSpec = RobotSpec()
    tool: ToolSpec = ToolSpec()
    fixtures: list[FixtureSpec] = []


class WorkObjectSpec(_Strict, frozen=True, kw_only=True):
    """The work object: its mesh, the mesh unit, the file digest and its nominal pose.

    Attributes:
        mesh: mesh file (relative to the plan) or ``builtin:stator_section``.
        units: length unit of the mesh file (``auto`` lets the loader guess).
        sha256: hex digest of the mesh file; a mismatch on load is an error naming the file.
        T_world_wobj: nominal pose of the work-object frame (WOCS) in the world frame.
    """

    mesh: str = "builtin:stator_section"
    units: MeshUnits = "m"
    sha256: str | None = None
    T_world_wobj: Pose = Pose()

    def __post_init__(self) -> None:
        _check_sha256(self.sha256, self.mesh, "sha256")


class Search(_Strict, frozen=True, kw_only=True):
    """How a point is searched for; see :class:`calib.probing.SearchSpec`.

    Attributes:
        kind: ``approach`` (along ``-normal``) or ``edge`` (along ``edge_direction``).
        start_offset_m: start distance before the nominal point, metres.
        overtravel_m: allowed travel past the nominal point, metres.
        edge_direction: ``(3,)`` unit direction of an edge search, wobj frame; ``None`` otherwise.
        speed_m_s: search speed for the exported robot programs, m/s.
    """

    kind: Literal["approach", "edge"] = "approach"
    start_offset_m: float = 0.030
    overtravel_m: float = 0.020
    edge_direction: Vec3 | None = None
    speed_m_s: float = 0.010

    def __post_init__(self) -> None:
        _check_positive(self.start_offset_m, "start_offset_m")
        _check_positive(self.overtravel_m, "overtravel_m")
        _check_positive(self.speed_m_s, "speed_m_s")
        if self.kind == "edge" and self.edge_direction is None:
            raise PlanError("edge_direction: required for an edge search")
        if self.kind == "approach" and self.edge_direction is not None:
            raise PlanError("edge_direction: must be null for an approach search")
        _check_unit(self.edge_direction, "edge_direction")


class PlanPoint(_Strict, frozen=True, kw_only=True):
    """A probe point; the plan-file form of :class:`calib.probing.ProbePoint`.

    Attributes:
        id: unique name, e.g. ``"A"``.
        role: the point's role in the procedure (see ``calib.plan_procedures``).
        position_m: ``(3,)`` nominal surface (or edge) point, wobj frame, metres.
        normal: ``(3,)`` unit outward normal of the face, wobj frame.
        search: how the point is searched for.
        edge_normal: ``(3,)`` unit normal of the face whose end an edge search finds, or ``None``.
    """

    id: str
    role: str
    position_m: Vec3
    normal: Vec3
    search: Search = Search()
    edge_normal: Vec3 | None = None

    def __post_init__(self) -> None:
        if not self.id or not self.id.strip():
            raise PlanError("id: must be a non-empty string")
        _check_finite(self.position_m, "position_m")
        _check_unit(self.normal, "normal")
        _check_unit(self.edge_normal, "edge_normal")
        if self.search.edge_direction is not None:
            dot = float(np.dot(self.search.edge_direction, self.normal))
            if abs(dot) > _UNIT_TOL:
                raise PlanError(
                    f"search.edge_direction: must be perpendicular to normal, got dot = {dot:.3g}"
                )

    def to_probe_point(self) -> ProbePoint:
        """The :class:`ProbePoint` used by procedures and the cell."""
        s = self.search
        return ProbePoint(
            id=self.id,
            position_m=self.position_m,
            normal=self.normal,
            search=SearchSpec(
                kind=s.kind,
                start_offset_m=s.start_offset_m,
                overtravel_m=s.overtravel_m,
                edge_direction=s.edge_direction,
            ),
            edge_normal=self.edge_normal,
        )

    @classmethod
    def from_probe_point(cls, point: ProbePoint, role: str, speed_m_s: float = 0.010) -> PlanPoint:
        """The plan form of ``point`` with its ``role`` (numbers converted to plain floats)."""

        def vec(v: ArrayLike | None) -> Vec3 | None:
            if v is None:
                return None
            a = np.asarray(v, dtype=float)
            return (float(a[0]), float(a[1]), float(a[2]))

        s = point.search
        return cls(
            id=point.id,
            role=role,
            position_m=vec(point.position_m),  # type: ignore[arg-type]
            normal=vec(point.normal),  # type: ignore[arg-type]
            search=Search(
                kind=s.kind,
                start_offset_m=float(s.start_offset_m),
                overtravel_m=float(s.overtravel_m),
                edge_direction=vec(s.edge_direction),
                speed_m_s=speed_m_s,
            ),
            edge_normal=vec(point.edge_normal),
        )


class SensorModel(_Strict, frozen=True, kw_only=True):
    """The proximity sensor, for validation (``planner.sensor.ProximitySensor``).

    Attributes:
        face_diameter_m: diameter of the active face, m.
        sensing_distance_m: nominal sensing distance on a flat steel target, m.
        decay_length_m: length over which the damping signal falls by ``e``, m.
        hysteresis_fraction: switch-off distance exceeds switch-on by this part of the distance.
        repeatability_sigma_m: 1-sigma jitter of the switching distance, m.
        n_rays: rays over the face for switching decisions.
        n_scan_rays: rays for the coarse scan of an edge search.
    """

    face_diameter_m: float = 0.018
    sensing_distance_m: float = 0.008
    decay_length_m: float = 0.003
    hysteresis_fraction: float = 0.10
    repeatability_sigma_m: float = 0.00004
    n_rays: int = 256
    n_scan_rays: int = 37

    def __post_init__(self) -> None:
        _check_positive(self.face_diameter_m, "face_diameter_m", allow_zero=True)
        _check_positive(self.sensing_distance_m, "sensing_distance_m")
        _check_positive(self.decay_length_m, "decay_length_m")
        _check_positive(self.hysteresis_fraction, "hysteresis_fraction", allow_zero=True)
        _check_positive(self.repeatability_sigma_m, "repeatability_sigma_m", allow_zero=True)
        _check_positive(self.n_rays, "n_rays")
        _check_positive(self.n_scan_rays, "n_scan_rays")


class RobotErrorModel(_Strict, frozen=True, kw_only=True):
    """Robot positioning errors, for validation (``planner.error_models.RobotErrorModel``).

    Attributes:
        repeatability_sigma_m: 1-sigma per-axis TCP scatter of each search, m.
        accuracy_amplitude_m: RMS per axis of the smooth absolute-accuracy field, m (0: off).
        accuracy_wavelength_m: typical wavelength of the accuracy field, m.
        accuracy_terms: number of sine terms of the field.
    """

    repeatability_sigma_m: float = 0.00002
    accuracy_amplitude_m: float = 0.0
    accuracy_wavelength_m: float = 1.0
    accuracy_terms: int = 6

    def __post_init__(self) -> None:
        _check_positive(self.repeatability_sigma_m, "repeatability_sigma_m", allow_zero=True)
        _check_positive(self.accuracy_amplitude_m, "accuracy_amplitude_m", allow_zero=True)
        _check_positive(self.accuracy_wavelength_m, "accuracy_wavelength_m")
        _check_positive(self.accuracy_terms, "accuracy_terms")


class Misplacement(_Strict, frozen=True, kw_only=True):
    """How far the real part may lie from its nominal pose (uniform, for validation).

    Attributes:
        max_translation_m: largest translation, m (paper: 20 mm).
        max_angle_rad: largest rotation, rad (paper: 3 deg).
    """

    max_translation_m: float = 0.020
    max_angle_rad: float = math.radians(3.0)

    def __post_init__(self) -> None:
        _check_positive(self.max_translation_m, "max_translation_m", allow_zero=True)
        _check_positive(self.max_angle_rad, "max_angle_rad", allow_zero=True)


class ValidationSpec(_Strict, frozen=True, kw_only=True):
    """Monte Carlo validation settings.

    Attributes:
        sensor: the sensor model.
        robot_error: the robot error model.
        misplacement: misplacement tolerance of the part.
        trials: number of simulated calibrations.
        seed: seed of the ``numpy.random.Generator``.
    """

    sensor: SensorModel = SensorModel()
    robot_error: RobotErrorModel = RobotErrorModel()
    misplacement: Misplacement = Misplacement()
    trials: int = 400
    seed: int = 20131023

    def __post_init__(self) -> None:
        if self.trials < 2:
            raise PlanError(f"trials: must be >= 2, got {self.trials}")


class Plan(_Strict, frozen=True, kw_only=True):
    """A complete measurement plan (file format ``wobjcal.plan/1``)."""

    schema: Literal["wobjcal.plan/1"] = PLAN_SCHEMA
    name: str = ""
    description: str = ""
    cell: CellSpec = CellSpec()
    work_object: WorkObjectSpec = WorkObjectSpec()
    points: list[PlanPoint] = []
    procedure: Procedure
    validation: ValidationSpec = ValidationSpec()

    def __post_init__(self) -> None:
        seen: dict[str, int] = {}
        for i, p in enumerate(self.points):
            if p.id in seen:
                raise PlanError(
                    f"points[{i}].id: duplicate id {p.id!r} (also points[{seen[p.id]}])"
                )
            seen[p.id] = i
        names = [f.name for f in self.cell.fixtures]
        if len(set(names)) != len(names):
            raise PlanError(f"cell.fixtures: duplicate fixture names in {names}")
        msg = check_roles(self.procedure, [p.role for p in self.points], complete=False)
        if msg:
            raise PlanError(msg)

    @property
    def method(self) -> str:
        """The procedure's method: ``hultman2013``, ``three_two_one`` or ``best_fit``."""
        return method_of(self.procedure)

    def require_complete(self) -> None:
        """Raise :class:`PlanError` unless the points have all roles the procedure needs."""
        msg = check_roles(self.procedure, [p.role for p in self.points], complete=True)
        if msg:
            raise PlanError(msg)

    def point(self, point_id: str) -> PlanPoint:
        """The point named ``point_id``; the error lists the valid ids."""
        for p in self.points:
            if p.id == point_id:
                return p
        raise PlanError(f"no point {point_id!r} in the plan (ids: {[p.id for p in self.points]})")

    def probe_points(self) -> dict[str, ProbePoint]:
        """All points as :class:`ProbePoint`, by id, in plan order."""
        return {p.id: p.to_probe_point() for p in self.points}

    def roles(self) -> dict[str, str]:
        """Role of each point, by id."""
        return {p.id: p.role for p in self.points}


def file_sha256(path: str | Path) -> str:
    """Hex SHA-256 digest of a file's bytes."""
    digest = hashlib.sha256()
    with Path(path).open("rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def resolve_ref(ref: str, plan_dir: str | Path) -> str | Path:
    """A file reference of the plan: ``builtin:NAME`` unchanged, else a path under ``plan_dir``."""
    if ref.startswith(BUILTIN_PREFIX):
        return ref
    path = Path(ref)
    return path if path.is_absolute() else Path(plan_dir) / path


_CHOICES = {
    "units": get_args(MeshUnits),
    "method": METHODS,
    "kind": ("approach", "edge"),
}


def plan_from_json(text: str, source: str = "plan") -> Plan:
    """Parse and validate plan JSON text (no file checks); errors name ``source`` and the path."""
    raw = parse_json_text(text, PlanError, source)
    check_schema_tag(raw, SUPPORTED_PLAN_SCHEMAS, PlanError, source)
    return convert_strict(raw, Plan, PlanError, source, _CHOICES)


def plan_to_json(plan: Plan) -> str:
    """The canonical JSON text of ``plan`` (sorted keys, indent 2, trailing newline)."""
    return canonical_json(plan)


def check_plan_files(plan: Plan, plan_dir: str | Path, source: str = "plan") -> None:
    """Check that referenced files exist and match their ``sha256``; errors name the file."""
    refs = [("work_object", plan.work_object.mesh, plan.work_object.sha256)]
    refs += [
        (f"cell.fixtures[{i}]", f.mesh, f.sha256)
        for i, f in enumerate(plan.cell.fixtures)
        if f.mesh is not None
    ]
    for where, ref, sha in refs:
        path = resolve_ref(ref, plan_dir)
        if isinstance(path, str):
            continue
        if not path.is_file():
            raise PlanError(f"{source}: {where}.mesh: file not found: {path}")
        if sha is not None and file_sha256(path) != sha:
            raise PlanError(
                f"{source}: {where}.sha256: {path} has digest {file_sha256(path)}, "
                f"the plan says {sha} (the file changed since the plan was made)"
            )


def load_plan(path: str | Path, check_files: bool = True) -> Plan:
    """Read a plan file strictly.

    Args:
        path: the plan JSON file.
        check_files: also check referenced mesh files and their sha256 digests.

    Raises:
        PlanError: malformed JSON, unsupported schema, wrong field, or a file mismatch; the
            message names the file and the JSON path.
        OSError: the file cannot be read.
    """
    p = Path(path)
    text = p.read_text(encoding="utf-8")
    plan = plan_from_json(text, source=str(p))
    if check_files:
        check_plan_files(plan, p.parent, source=str(p))
    return plan


def save_plan(plan: Plan, path: str | Path) -> Path:
    """Write ``plan`` atomically as canonical JSON; return the path."""
    return write_text_atomic(path, plan_to_json(plan))
