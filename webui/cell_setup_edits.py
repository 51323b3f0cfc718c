"""Pure edits of what the cell holds (issue 22, item 1): the tool and its TCP, the sensor and the
points' search speed, and fixtures added (box, cylinder, mesh) or deleted.

Humans see millimetres, mm/s and degrees; the plan keeps metres, m/s and ``quat_wxyz``. Each
function returns a new :class:`calib.plan.file.Plan` (or :class:`webui.plan_doc.UiPlan` when the
points change too); the UI makes it the session's in one undoable, autosaved step, after which
every point is checked again (:meth:`webui.app.WobjcalApp.replace_source` for the cell, a
session update for the sensor). Poses of fixtures already in the cell: :mod:`webui.cell_edits`.
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass

import msgspec
import numpy as np
from numpy.typing import ArrayLike

from calib.errors import InputError, PlanError
from calib.limits import MAX_FIXTURES
from calib.models import SENSOR_KINDS, ProximitySensor, TouchProbe
from calib.plan.cell import FixtureSpec, Pose
from calib.plan.file import Plan
from calib.registry import unknown_name
from calib.units import MESH_UNITS
from planner.cell.scene import FLANGE, Tool
from webui.cell_edits import pose_from_fields
from webui.plan_adapter import with_source
from webui.plan_doc import UiPlan

#: The fixture shapes the cell panel adds from numbers (a mesh comes as an upload).
FIXTURE_SHAPES: tuple[str, ...] = ("box", "cylinder")
_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_ .:+()/-]{0,63}$")


# ---- fixtures ------------------------------------------------------------------------------
def fixture_names(plan: Plan) -> tuple[str, ...]:
    """The names of the plan's fixtures, in plan order."""
    return tuple(f.name for f in plan.cell.fixtures)


def free_fixture_name(plan: Plan, stem: str) -> str:
    """``stem`` when no fixture has that name, else ``stem_2``, ``stem_3``, ..."""
    names = set(fixture_names(plan))
    if stem not in names:
        return stem
    k = 2
    while f"{stem}_{k}" in names:
        k += 1
    return f"{stem}_{k}"


def check_fixture_name(plan: Plan, name: str) -> str:
    """``name`` stripped, when it is a usable new fixture name.

    Raises:
        InputError: empty, odd characters, or a fixture of the plan has it (the message lists
            the fixtures).
    """
    name = name.strip()
    if not _NAME.match(name):
        raise InputError(
            f"fixture name {name!r}: 1 to 64 letters, digits, spaces and _ . : + ( ) / -, "
            "starting with a letter, digit or _"
        )
    if name in fixture_names(plan):
        raise InputError(
            f"a fixture named {name!r} is in the cell already (fixtures: "
            f"{', '.join(fixture_names(plan))}); choose another name or delete it first"
        )
    return name


def _mm(values: ArrayLike, n: int, what: str) -> tuple[float, ...]:
    """``n`` lengths in mm, each finite and > 0, as metres."""
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    if v.shape != (n,) or not np.all(np.isfinite(v)) or np.any(v <= 0.0):
        raise InputError(f"{what}: must be {n} lengths > 0 mm, got {v.tolist()}")
    return tuple(float(x) / 1000.0 for x in v)


def _spec(plan: Plan, name: str, position_mm: ArrayLike, **shape: object) -> FixtureSpec:
    """A fixture spec at ``position_mm`` (world, mm, axes of the world), its name checked."""
    name = check_fixture_name(plan, name)
    pose = Pose.from_matrix(pose_from_fields(position_mm, (0.0, 0.0, 0.0)))
    try:
        return FixtureSpec(name=name, T_world_fixture=pose, **shape)  # type: ignore[arg-type]
    except PlanError as exc:
        raise InputError(f"fixture {name!r}: {exc}") from None


def box_fixture(plan: Plan, name: str, size_mm: ArrayLike, position_mm: ArrayLike) -> FixtureSpec:
    """A box fixture of edge lengths ``size_mm`` (x, y, z; mm) centred at ``position_mm``
    (world, mm), its edges along the world axes.

    Raises:
        InputError: a size that is not > 0, a bad position, or a name in use.
    """
    size = _mm(size_mm, 3, "box size")
    return _spec(plan, name, position_mm, box_size_m=size)


def cylinder_fixture(
    plan: Plan, name: str, radius_mm: float, length_mm: float, position_mm: ArrayLike
) -> FixtureSpec:
    """A cylinder fixture of ``radius_mm`` and ``length_mm`` (mm) about the world's z axis,
    centred at ``position_mm`` (world, mm).

    Raises:
        InputError: a radius or length that is not > 0, a bad position, or a name in use.
    """
    for value, what in ((radius_mm, "cylinder radius"), (length_mm, "cylinder length")):
        if not (math.isfinite(value) and value > 0.0):
            raise InputError(f"{what}: must be > 0 mm, got {value}")
    r, h = _mm((radius_mm, length_mm), 2, "cylinder radius and length")
    return _spec(plan, name, position_mm, cylinder_m=(r, h))


def mesh_fixture(
    plan: Plan, name: str, mesh: str, units: str, sha256: str, position_mm: ArrayLike
) -> FixtureSpec:
    """A mesh fixture: the file ``mesh`` (its digest ``sha256``) in ``units``, its frame at
    ``position_mm`` (world, mm).

    Raises:
        InputError: unknown units, a bad position, or a name in use.
    """
    if units not in MESH_UNITS:
        raise InputError(f"mesh units: must be one of {', '.join(MESH_UNITS)}, got {units!r}")
    return _spec(plan, name, position_mm, mesh=mesh, units=units, sha256=sha256)


def with_fixture(plan: Plan, fixture: FixtureSpec) -> Plan:
    """``plan`` with ``fixture`` added to its cell.

    Raises:
        InputError: a fixture of that name exists, or the cell holds the most it may.
    """
    check_fixture_name(plan, fixture.name)
    if len(plan.cell.fixtures) >= MAX_FIXTURES:
        raise InputError(f"the cell holds {MAX_FIXTURES} fixtures, the most it may")
    fixtures = [*plan.cell.fixtures, fixture]
    return msgspec.structs.replace(plan, cell=msgspec.structs.replace(plan.cell, fixtures=fixtures))


def without_fixture(plan: Plan, name: str) -> Plan:
    """``plan`` without the fixture ``name``.

    Raises:
        InputError: no such fixture (the message lists the fixtures).
    """
    if name not in fixture_names(plan):
        have = ", ".join(fixture_names(plan)) or "none"
        raise InputError(f"no fixture {name!r} to delete (fixtures: {have})")
    fixtures = [f for f in plan.cell.fixtures if f.name != name]
    return msgspec.structs.replace(plan, cell=msgspec.structs.replace(plan.cell, fixtures=fixtures))


# ---- the tool ------------------------------------------------------------------------------
def tcp_choice(tool: Tool, current: str) -> str:
    """The TCP to probe with on ``tool``: ``current`` when the tool has it, else the tool's
    sensor TCP, else its first TCP, else the flange."""
    if current in tool.tcp_names:
        return current
    if tool.sensor_tcp is not None:
        return tool.sensor_tcp
    return next((t for t in sorted(tool.tcps)), FLANGE)


def with_tool(plan: Plan, tool_ref: str, tcp: str) -> Plan:
    """``plan`` with the tool ``tool_ref`` (``builtin:NAME`` or a file) probing with TCP
    ``tcp``; the tool's mount on the flange (``T_flange_tool``) is kept."""
    if not tool_ref or not tcp:
        raise InputError(f"tool: give a tool and a TCP, got {tool_ref!r} and {tcp!r}")
    tool = msgspec.structs.replace(plan.cell.tool, name=tool_ref, tcp=tcp)
    return msgspec.structs.replace(plan, cell=msgspec.structs.replace(plan.cell, tool=tool))


# ---- the sensor ----------------------------------------------------------------------------
@dataclass(frozen=True)
class SensorFields:
    """The sensor's numbers as the cell panel shows them.

    Attributes:
        kind: ``"proximity"`` or ``"touch"`` (:data:`calib.models.SENSOR_KINDS`).
        diameter_mm: the proximity sensor's face diameter, or the touch probe's ball, mm.
        range_mm: the proximity sensor's detection range (nominal sensing distance), mm; a
            touch probe has none (it touches: 0 shown, not used).
        noise_mm: 1-sigma scatter of the switching (proximity) or trigger (touch) point, mm.
        speed_mm_s: the search speed of the points, mm/s (``None``: each point keeps its own).
    """

    kind: str
    diameter_mm: float
    range_mm: float
    noise_mm: float
    speed_mm_s: float | None = None


def sensor_fields(ui: UiPlan) -> SensorFields:
    """The fields of ``ui``'s sensor; the speed is the first point's (10 mm/s without points).

    Raises:
        InputError: no plan is loaded.
    """
    if not isinstance(ui.source, Plan):
        raise InputError("load a plan first: there is no sensor to set up")
    sensor = ui.source.validation.sensor
    speed = 1000.0 * (ui.points[0].speed_m_s if ui.points else 0.010)
    if isinstance(sensor, TouchProbe):
        return SensorFields(
            "touch", 1000.0 * sensor.tip_diameter_m, 0.0,
            1000.0 * sensor.trigger_repeatability_sigma_m, speed,
        )  # fmt: skip
    return SensorFields(
        "proximity", 1000.0 * sensor.face_diameter_m, 1000.0 * sensor.sensing_distance_m,
        1000.0 * sensor.repeatability_sigma_m, speed,
    )  # fmt: skip


#: The largest sensor number the Sensor fields take (a typo of x100 is refused, not exported):
#: face or ball diameter 100 mm, detection range 50 mm, noise 5 mm, search speed 250 mm/s.
SENSOR_LIMITS = {
    "diameter": 100.0,
    "ball diameter": 100.0,
    "detection range": 50.0,
    "noise 1 sigma": 5.0,
    "search speed": 250.0,
}


def _number(value: float, what: str, allow_zero: bool) -> float:
    """``value`` checked: finite, positive (or zero) and at most its :data:`SENSOR_LIMITS`
    entry (``what`` is ``"<name> (<unit>)"``)."""
    if not math.isfinite(value) or value < 0.0 or (value == 0.0 and not allow_zero):
        raise InputError(f"{what}: must be {'>= 0' if allow_zero else '> 0'}, got {value}")
    most = SENSOR_LIMITS.get(what.split(" (")[0])
    if most is not None and value > most:
        unit = what.split(" (")[-1].rstrip(")") if " (" in what else ""
        raise InputError(f"{what}: at most {most:g} {unit}, got {value:g} (a typo?)")
    return float(value)


def with_sensor(ui: UiPlan, fields: SensorFields) -> UiPlan:
    """``ui`` with the sensor of ``fields`` (its other settings kept when the kind stays, the
    kind's defaults when it changes) and, unless ``fields.speed_mm_s`` is ``None``, every
    point searching at that speed.

    Raises:
        InputError: no plan, an unknown kind, or a number out of range (the message names the
            field in mm or mm/s).
    """
    if not isinstance(ui.source, Plan):
        raise InputError("load a plan first: there is no sensor to set up")
    if fields.kind not in SENSOR_KINDS:
        raise unknown_name(
            "sensor kind (validation.sensor.kind)", fields.kind, SENSOR_KINDS, InputError
        )
    noise = _number(fields.noise_mm, "noise 1 sigma (mm)", allow_zero=True) / 1000.0
    old = ui.source.validation.sensor
    sensor: ProximitySensor | TouchProbe
    if fields.kind == TouchProbe.KIND:
        diameter = _number(fields.diameter_mm, "ball diameter (mm)", allow_zero=False) / 1000.0
        base_t = old if isinstance(old, TouchProbe) else TouchProbe()
        sensor = msgspec.structs.replace(
            base_t, tip_diameter_m=diameter, trigger_repeatability_sigma_m=noise
        )
    else:
        diameter = _number(fields.diameter_mm, "diameter (mm)", allow_zero=True) / 1000.0
        reach = _number(fields.range_mm, "detection range (mm)", allow_zero=False) / 1000.0
        base_p = old if isinstance(old, ProximitySensor) else ProximitySensor()
        sensor = msgspec.structs.replace(
            base_p, face_diameter_m=diameter, sensing_distance_m=reach, repeatability_sigma_m=noise
        )
    validation = msgspec.structs.replace(ui.source.validation, sensor=sensor)
    out = with_source(ui, msgspec.structs.replace(ui.source, validation=validation))
    if fields.speed_mm_s is None:
        return out
    speed = _number(fields.speed_mm_s, "search speed (mm/s)", allow_zero=False) / 1000.0
    points = tuple(dataclasses.replace(p, speed_m_s=speed) for p in out.points)
    return dataclasses.replace(out, points=points)
