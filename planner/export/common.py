"""What every robot-program exporter needs, independent of the robot language.

An :class:`ExportJob` holds the nominal work object, the sensor tool and, per probe point, the
sensor-TCP pose at the start and at the end of its search, all in the wobj frame (metres), with
the IK branch's ABB configuration when known. The exporters (``rapid``, ``krl``, ``urscript``)
only format it. :func:`build_job` makes a job from a plan, the tool's TCP and (optionally) the
orientations and configurations chosen by ``wobjcal check``.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.frames import check_transform, make_transform
from calib.plan import Plan
from calib.probing import SearchCommand

FloatArray = NDArray[np.float64]
#: ABB ``confdata`` (cf1, cf4, cf6, cfx).
ConfData = tuple[int, int, int, int]


@dataclass(frozen=True)
class TargetPair:
    """The search of one probe point, as the robot program runs it.

    Attributes:
        point_id: the plan's point id, e.g. ``"A"``.
        role: the point's role in the procedure.
        kind: ``"approach"`` or ``"edge"``.
        T_wobj_start: ``(4, 4)`` sensor-TCP pose at the start of the search, wobj frame, m.
        T_wobj_end: ``(4, 4)`` sensor-TCP pose at the end of the search travel, wobj frame, m.
        speed_m_s: search speed, m/s.
        confdata: ABB configuration (cf1, cf4, cf6, cfx) of the IK branch, or ``None``.
    """

    point_id: str
    role: str
    kind: str
    T_wobj_start: FloatArray
    T_wobj_end: FloatArray
    speed_m_s: float
    confdata: ConfData | None = None

    @property
    def length_m(self) -> float:
        """Search travel, metres."""
        return float(np.linalg.norm(self.T_wobj_end[:3, 3] - self.T_wobj_start[:3, 3]))


@dataclass(frozen=True)
class ToolData:
    """The robot-held sensor tool.

    Attributes:
        T_flange_tcp: ``(4, 4)`` pose of the sensor TCP in the flange frame, m.
        mass_kg: tool mass, kg.
        cog_m: ``(3,)`` centre of gravity in the flange frame, m.
    """

    T_flange_tcp: FloatArray
    mass_kg: float = 5.0
    cog_m: tuple[float, float, float] = (0.0, 0.0, 0.1)


@dataclass(frozen=True)
class ExportJob:
    """Everything an exporter writes.

    Attributes:
        name: identifier-safe program/module name, e.g. ``"WobjcalStatorSectionAh"``.
        plan_name: the plan's name (for comments).
        method: the plan's procedure.
        T_base_wobj: ``(4, 4)`` nominal work-object frame in the robot base frame, m.
        tool: the sensor tool.
        targets: one :class:`TargetPair` per point, in plan order.
        sensor_input: name of the sensor's digital input (RAPID signal, KRL/UR input number).
    """

    name: str
    plan_name: str
    method: str
    T_base_wobj: FloatArray
    tool: ToolData
    targets: tuple[TargetPair, ...]
    sensor_input: str = "diSensor"


def identifier(text: str, prefix: str = "p") -> str:
    """A robot-language identifier made of ``text``: letters, digits and ``_`` only."""
    ident = re.sub(r"\W", "_", text)
    if not ident or not ident[0].isalpha():
        ident = prefix + ident
    return ident


def module_name(plan_name: str) -> str:
    """``"stator_section_ah"`` -> ``"WobjcalStatorSectionAh"`` (max 32 characters)."""
    words = re.split(r"[^A-Za-z0-9]+", plan_name)
    return ("Wobjcal" + "".join(w[:1].upper() + w[1:] for w in words if w))[:32]


def default_sensor_rotation(
    normal: ArrayLike, edge_direction: ArrayLike | None = None
) -> FloatArray:
    """Sensor orientation in the wobj frame when no check chose one.

    The sensor +z looks into the surface (``-normal``); its +x is the edge direction for an edge
    search, else the wobj axis least aligned with the normal (z, then y) made perpendicular.
    """
    z = -np.asarray(normal, dtype=float)
    z /= np.linalg.norm(z)
    if edge_direction is not None:
        ref = np.asarray(edge_direction, dtype=float)
    else:
        ref = np.array([0.0, 0.0, 1.0]) if abs(z[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = ref - (ref @ z) * z
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.column_stack([x, y, z])


def build_job(
    plan: Plan,
    T_base_wobj: ArrayLike,
    tool: ToolData,
    rotations_wobj: Mapping[str, ArrayLike] | None = None,
    confdata: Mapping[str, ConfData] | None = None,
    sensor_input: str = "diSensor",
) -> ExportJob:
    """The export job of ``plan``.

    Args:
        plan: the plan.
        T_base_wobj: ``(4, 4)`` nominal work object in the robot base frame.
        tool: the sensor tool.
        rotations_wobj: ``{id: (3, 3)}`` sensor-TCP orientation in the wobj frame per point (from
            the check); missing points get :func:`default_sensor_rotation`.
        confdata: ``{id: (cf1, cf4, cf6, cfx)}`` per point (from the check), or ``None``.
        sensor_input: name of the sensor input.
    """
    T = check_transform(T_base_wobj, "T_base_wobj")
    rotations = rotations_wobj or {}
    confs = confdata or {}
    targets = []
    for p in plan.points:
        cmd = SearchCommand.from_point(p.to_probe_point(), np.eye(4))
        R = rotations.get(p.id)
        if R is None:
            R = default_sensor_rotation(p.normal, p.search.edge_direction)
        R = np.asarray(R, dtype=float)
        end = cmd.start_m + cmd.length_m * cmd.direction
        targets.append(
            TargetPair(
                point_id=p.id,
                role=p.role,
                kind=p.search.kind,
                T_wobj_start=make_transform(R, cmd.start_m),
                T_wobj_end=make_transform(R, end),
                speed_m_s=p.search.speed_m_s,
                confdata=confs.get(p.id),
            )
        )
    return ExportJob(
        name=module_name(plan.name or "plan"),
        plan_name=plan.name,
        method=plan.method,
        T_base_wobj=T,
        tool=tool,
        targets=tuple(targets),
        sensor_input=sensor_input,
    )


def fmt(x: float, decimals: int = 4) -> str:
    """A number for program text: fixed decimals, no ``-0``, trailing zeros trimmed."""
    s = f"{x:.{decimals}f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s
