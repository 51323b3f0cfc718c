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
import json
from pathlib import Path, PurePosixPath
from typing import Any, Final, Literal, get_args

import msgspec
import numpy as np
from numpy.typing import ArrayLike

from calib.atomic_io import write_text_atomic
from calib.errors import PlanError
from calib.limits import MAX_PLAN_POINTS, MAX_VIAS_PER_POINT
from calib.models import SENSOR_KINDS, ProximitySensor
from calib.plan.base import (
    BUILTIN_PREFIX,
    PLAN_NAME_PATTERN,
    POINT_ID_PATTERN,
    MeshUnits,
    PlanName,
    PointId,
    check_pattern,
    file_sha256,
    resolve_ref,
)
from calib.plan.cell import (
    CellSpec,
    FixtureSpec,
    Pose,
    RobotSpec,
    ToolSpec,
    WorkObjectSpec,
)
from calib.plan.json_io import (
    canonical_json,
    check_schema_tag,
    convert_strict,
    parse_json_text,
    read_text_file,
    unsigned_zeros,
)
from calib.plan.models import ValidationSpec
from calib.plan.report_spec import COMPONENTS
from calib.plan.vias import ViaPoint, check_via_counts
from calib.probing import ProbePoint, SearchSpec
from calib.procedures import METHODS, ProcedureSettings, method_of, procedure_kind
from calib.procedures.base import RolePoint
from calib.reading import MAX_MESH_BYTES, check_regular_file
from calib.structs import (
    UNIT_TOL,
    Strict,
    Vec3,
    check_coordinates,
    check_length,
    check_positive,
    check_search_lengths,
    check_unit,
)

__all__ = [
    "BUILTIN_PREFIX",
    "PLAN_SCHEMA",
    "SUPPORTED_PLAN_SCHEMAS",
    "CellSpec",
    "FixtureSpec",
    "Plan",
    "PlanError",
    "PlanPoint",
    "Pose",
    "RobotSpec",
    "Search",
    "ToolSpec",
    "ValidationSpec",
    "ViaPoint",
    "WorkObjectSpec",
    "check_plan_files",
    "file_sha256",
    "load_plan",
    "plan_digest",
    "plan_from_json",
    "plan_to_json",
    "resolve_ref",
    "save_plan",
]

PLAN_SCHEMA: Final = "wobjcal.plan/1"
SUPPORTED_PLAN_SCHEMAS = (PLAN_SCHEMA,)
#: Why a plan's points and a point's vias are bounded (:mod:`calib.limits`).
POINTS_WHY = (
    "a calibration uses 6 to a few dozen; check holds ~0.15 MB a point and compares points "
    "pairwise, so 10,000 points took 6.8 GB"
)
VIAS_WHY = "a path needs 1 to 3; each is checked in the cell"


class Search(Strict, frozen=True, kw_only=True):
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
        check_positive(self.start_offset_m, "start_offset_m")
        check_positive(self.overtravel_m, "overtravel_m")
        check_search_lengths(self.start_offset_m, self.overtravel_m)
        check_positive(self.speed_m_s, "speed_m_s")
        if self.kind == "edge" and self.edge_direction is None:
            raise PlanError("edge_direction: required for an edge search")
        if self.kind == "approach" and self.edge_direction is not None:
            raise PlanError("edge_direction: must be null for an approach search")
        check_unit(self.edge_direction, "edge_direction")


class PlanPoint(Strict, frozen=True, kw_only=True):
    """A probe point; the plan-file form of :class:`calib.probing.ProbePoint`.

    Attributes:
        id: unique name, e.g. ``"A"``.
        role: the point's role in the procedure (see :mod:`calib.procedures`).
        position_m: ``(3,)`` nominal surface (or edge) point, wobj frame, metres.
        normal: ``(3,)`` unit outward normal of the face, wobj frame.
        search: how the point is searched for.
        edge_normal: ``(3,)`` unit normal of the face whose end an edge search finds, or ``None``.
        vias: the joint configurations the robot passes, in order, on its way from the previous
            point to this one (:mod:`calib.plan.vias`); left out of the file when there are
            none (:attr:`via_points` reads both).
    """

    id: PointId
    role: str
    position_m: Vec3
    normal: Vec3
    search: Search = Search()
    edge_normal: Vec3 | None = None
    vias: list[ViaPoint] | msgspec.UnsetType = msgspec.UNSET

    @property
    def via_points(self) -> tuple[ViaPoint, ...]:
        """The point's vias in order (``()`` when the file has none)."""
        return () if isinstance(self.vias, msgspec.UnsetType) else tuple(self.vias)

    def with_vias(self, vias: list[ViaPoint] | tuple[ViaPoint, ...]) -> PlanPoint:
        """This point with ``vias`` (none: the field is left out of the file, as before vias)."""
        return msgspec.structs.replace(self, vias=list(vias) if vias else msgspec.UNSET)

    def __post_init__(self) -> None:
        check_pattern(self.id, POINT_ID_PATTERN, "id", "a point id")
        check_length(self.via_points, "vias", MAX_VIAS_PER_POINT, "vias", VIAS_WHY)
        check_coordinates(self.position_m, "position_m")
        check_unit(self.normal, "normal")
        check_unit(self.edge_normal, "edge_normal")
        if self.search.edge_direction is not None:
            dot = float(np.dot(self.search.edge_direction, self.normal))
            if abs(dot) > UNIT_TOL:
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
    def from_probe_point(
        cls,
        point: ProbePoint,
        role: str,
        speed_m_s: float = 0.010,
        vias: tuple[ViaPoint, ...] = (),
    ) -> PlanPoint:
        """The plan form of ``point`` with its ``role`` and ``vias`` (numbers converted to plain
        floats)."""

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
            vias=list(vias) if vias else msgspec.UNSET,
        )


#: How a plan's searches are sized: ``whole``: each for the whole misplacement (every
#: controller's program runs them); ``steered``: a search an adaptive program commands in its
#: estimate only for what the earlier points leave (:mod:`planner.program.steered_searches`).
SearchSizing = Literal["whole", "steered"]


class Plan(Strict, frozen=True, kw_only=True):
    """A complete measurement plan (file format ``wobjcal.plan/1``).

    ``search_sizing`` (:data:`SearchSizing`) is left out of the file when not set: a plan
    written before it keeps its digest, and reads as ``whole`` (:attr:`steered_searches`).
    """

    schema: Literal["wobjcal.plan/1"] = PLAN_SCHEMA
    name: PlanName = ""
    description: str = ""
    cell: CellSpec = CellSpec()
    work_object: WorkObjectSpec = WorkObjectSpec()
    points: list[PlanPoint] = []  # noqa: RUF012 (msgspec copies empty defaults)
    procedure: ProcedureSettings
    validation: ValidationSpec = ValidationSpec()
    search_sizing: SearchSizing | msgspec.UnsetType = msgspec.UNSET

    @property
    def steered_searches(self) -> bool:
        """The searches are sized for an adaptive program (``search_sizing: "steered"``)."""
        return self.search_sizing == "steered"

    def __post_init__(self) -> None:
        check_length(self.points, "points", MAX_PLAN_POINTS, "points", POINTS_WHY)
        check_pattern(self.name, PLAN_NAME_PATTERN, "name", "a plan name")
        seen: dict[str, int] = {}
        for i, p in enumerate(self.points):
            if p.id in seen:
                raise PlanError(
                    f"points[{i}].id: duplicate id {p.id!r} (also points[{seen[p.id]}])"
                )
            seen[p.id] = i
        check_via_counts([(p.id, p.via_points) for p in self.points])
        names = [f.name for f in self.cell.fixtures]
        if len(set(names)) != len(names):
            raise PlanError(f"cell.fixtures: duplicate fixture names in {names}")
        msg = procedure_kind(self.procedure).role_problem([p.role for p in self.points], False)
        if msg:
            raise PlanError(msg)

    @property
    def method(self) -> str:
        """The procedure's method: ``hultman2013``, ``three_two_one`` or ``best_fit``."""
        return method_of(self.procedure)

    def fixed_points(self) -> str:
        """Why no point can be added to this plan (``suggest --add`` grows a plan into a best
        fit of all its points): what of its procedure a best fit would drop, or ``""`` when
        nothing would (a 3-2-1 plan's six points are a best fit's too)."""
        if getattr(self.procedure, "xoffset", None) is None:
            return ""
        return (
            f"the plan's {self.method} procedure takes exactly its own points and runs the "
            "x-offset run after them, which a best fit of more points would not: measure those "
            "points again if the calibrated frame is in doubt (calibrate's screen fits every "
            "point measured)"
        )

    def require_complete(self) -> None:
        """Raise :class:`PlanError` unless the points have all roles the procedure needs."""
        msg = procedure_kind(self.procedure).role_problem([p.role for p in self.points], True)
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

    def role_points(self) -> list[RolePoint]:
        """Every point with its role, in plan order (what the procedures take)."""
        return [RolePoint(p.role, p.to_probe_point()) for p in self.points]


_CHOICES = {
    "units": get_args(MeshUnits),
    "method": METHODS,
    "search.kind": ("approach", "edge"),
    "sensor.kind": SENSOR_KINDS,
    "components": COMPONENTS,
    "search_sizing": get_args(SearchSizing),
}


def _with_legacy_defaults(raw: Any) -> Any:
    """``raw`` with what older plan files leave out filled in.

    A plan written before the touch probe existed has a ``validation.sensor`` without
    ``kind``: it is the proximity sensor (the only sensor there was).
    """
    validation = raw.get("validation") if isinstance(raw, dict) else None
    if not isinstance(validation, dict):
        return raw
    sensor = validation.get("sensor")
    if isinstance(sensor, dict) and "kind" not in sensor:
        validation["sensor"] = {"kind": ProximitySensor.KIND, **sensor}
    return raw


def plan_from_json(text: str, source: str = "plan") -> Plan:
    """Parse and validate plan JSON text (no file checks); errors name ``source`` and the path.

    A ``validation.sensor`` without ``kind`` (a plan from before the touch probe) loads as the
    proximity sensor.
    """
    raw = parse_json_text(text, PlanError, source)
    check_schema_tag(raw, SUPPORTED_PLAN_SCHEMAS, PlanError, source)
    return convert_strict(_with_legacy_defaults(raw), Plan, PlanError, source, _CHOICES)


def plan_to_json(plan: Plan) -> str:
    """The canonical JSON text of ``plan`` (sorted keys, indent 2, trailing newline)."""
    return canonical_json(plan)


def _file_ref(ref: object) -> bool:
    return isinstance(ref, str) and not ref.startswith("builtin:")


def plan_digest(plan: Plan) -> str:
    """The plan's digest: the first 16 hex digits of the sha256 of its canonical JSON, with
    every ``-0.0`` taken as ``0.0`` (the same plan gives the same digest whatever wrote it).

    Where the plan's files lie does not count: the robot's and the tool's files count by
    their names (a robot file decides the controller's base frame: another robot is another
    plan), the meshes not at all (their ``sha256`` fields pin their contents when given; a
    ZIP renames a fixture's mesh whose name another has), ``builtin:`` references as they
    are, the robot's package path not at all. So a plan moved to another folder or downloaded
    with its files in a ZIP (:mod:`calib.plan.bundle`: its paths rewritten) is the same plan,
    and calibrates the results of the program exported before. (Before 2026-11-29 the paths
    counted: a program exported then from a plan with file references carries another digest;
    export it again.)

    Program headers carry it and ``wobjcal calibrate`` compares it with the plan it is given,
    so results measured with another plan's program are named, not used.
    """
    data = msgspec.to_builtins(plan)
    cell = data.get("cell", {})
    named = [(cell.get("robot", {}), "urdf"), (cell.get("tool", {}), "name")]
    meshes = [(f, "mesh") for f in cell.get("fixtures", [])]
    meshes.append((data.get("work_object", {}), "mesh"))
    for holder, key in named:
        if _file_ref(ref := holder.get(key)):
            holder[key] = PurePosixPath(str(ref).replace("\\", "/")).name
    for holder, key in meshes:
        if _file_ref(holder.get(key)):
            holder[key] = "file"
    cell.get("robot", {}).pop("package_path", None)
    text = json.dumps(
        unsigned_zeros(data),
        sort_keys=True,
        separators=(",", ":"),
        ensure_ascii=False,
        allow_nan=False,
    )
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


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
        if path.is_dir():
            raise PlanError(f"{source}: {where}.mesh: {path} is a directory, not a mesh file")
        if not path.exists():
            raise PlanError(f"{source}: {where}.mesh: file not found: {path}")
        try:
            check_regular_file(path, MAX_MESH_BYTES, "mesh file", PlanError)
        except PlanError as exc:
            raise PlanError(f"{source}: {where}.mesh: {exc}") from None
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
    text = read_text_file(p, PlanError, "plan file")
    plan = plan_from_json(text, source=str(p))
    if check_files:
        check_plan_files(plan, p.parent, source=str(p))
    return plan


def save_plan(plan: Plan, path: str | Path) -> Path:
    """Write ``plan`` atomically as canonical JSON; return the path."""
    return write_text_atomic(path, plan_to_json(plan))
