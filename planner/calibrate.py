"""Calibration of a plan from measured points, with any registered procedure.

:func:`calibrate_plan` computes ``T_base_wobj`` with the plan's procedure, or another one named
by ``method``, looked up in :data:`calib.procedures.PROCEDURES`: each procedure's
:meth:`~calib.procedures.base.ProcedureKind.estimate` takes the points with roles and the
measurements (retakes after the first measurement of a point). ``hultman2013`` replays the
paper's A-H procedure on the recorded points, ``three_two_one`` uses the plan's 3-2-1 roles (or
picks them from the faces when the plan was made for another method), ``best_fit`` fits every
measured point to its face(s). Pure numpy and ``calib``: no simulator.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from calib.errors import InputError
from calib.frames import invert_transform, transform_points
from calib.plan.file import Plan
from calib.plan.measurements import Measurements
from calib.procedures import PROCEDURES, procedure_kind
from planner.plan_cell import T_base_world, nominal_T_base_wobj

FloatArray = NDArray[np.float64]


class MeasuredPoints(Mapping[str, FloatArray]):
    """The measurements of a file as ``{point id: (k, 3)}`` in the robot base frame, metres.

    Looking up a point that was not measured raises the file's own error, which names the point
    and, when the robot reported it, why it failed.

    Args:
        measurements: the measurements file's content.
        T_base_world: ``(4, 4)`` the world frame in the base frame (for world-frame files).
    """

    def __init__(self, measurements: Measurements, T_base_world: FloatArray) -> None:
        self._m = measurements
        self._T = T_base_world
        self._cache: dict[str, FloatArray] = {}

    def __getitem__(self, point_id: str) -> FloatArray:
        if point_id not in self._cache:
            self._cache[point_id] = self._m.sequence_m(point_id, self._T)  # raises, named
        return self._cache[point_id]

    def __iter__(self) -> Iterator[str]:
        return iter(self._m.points)

    def __len__(self) -> int:
        return len(self._m.points)

    def __contains__(self, point_id: object) -> bool:
        return point_id in self._m.points


@dataclass(frozen=True)
class CalibrationOutput:
    """The calibrated work-object frame and how well the measured points fit it.

    Attributes:
        method: the method used.
        T_base_wobj: ``(4, 4)`` calibrated work object in the robot base frame, metres.
        T_base_wobj_nominal: ``(4, 4)`` the plan's nominal work object in the base frame.
        residuals_m: ``{id: r}`` signed distance of each measured point from its face of the
            calibrated part (along the face's outward normal), metres.
        edge_residuals_m: ``{id: r}`` for edge points, the distance from the face whose end
            the search found, metres.
        used_ids: the point ids the method used.
        skipped_ids: plan points without a measurement that the method could do without.
    """

    method: str
    T_base_wobj: FloatArray
    T_base_wobj_nominal: FloatArray
    residuals_m: dict[str, float]
    edge_residuals_m: dict[str, float]
    used_ids: tuple[str, ...]
    skipped_ids: tuple[str, ...] = ()


def calibrate_plan(
    plan: Plan, measurements: Measurements, method: str | None = None
) -> CalibrationOutput:
    """Compute ``T_base_wobj`` from measured points (see the module docstring).

    Args:
        plan: the plan the points were measured with.
        measurements: the measured points (base or world frame, m or mm).
        method: a procedure of :data:`calib.procedures.PROCEDURES`; default: the plan's.

    Raises:
        InputError: unknown method, a measured id the plan does not have, missing
            measurements, a layout the method cannot use.
        ProbeFailedError: the A-H replay needs a point that was not measured.
    """
    method = method or plan.method
    if method not in PROCEDURES:
        raise InputError(f"method must be one of {list(PROCEDURES)}, got {method!r}")
    known = {p.id for p in plan.points}
    unknown = sorted(set(measurements.points) - known)
    if unknown:
        raise InputError(
            f"measurements: points {unknown} are not in the plan (its points: {sorted(known)})"
        )
    kind = procedure_kind(method)
    settings = plan.procedure if kind.method == plan.method else None
    T_nom = nominal_T_base_wobj(plan)
    measured = MeasuredPoints(measurements, T_base_world(plan))
    run = kind.estimate(plan.role_points(), measured, T_nom, settings)
    first = {pid: measured[pid][0] for pid in measured}
    residuals, edge_res = point_residuals(plan, run.T_base_wobj, first)
    skipped = tuple(p.id for p in plan.points if p.id not in measured)
    return CalibrationOutput(
        method, run.T_base_wobj, T_nom, residuals, edge_res, run.used_ids, skipped
    )


def point_residuals(
    plan: Plan, T_base_wobj: FloatArray, measured_m: Mapping[str, FloatArray]
) -> tuple[dict[str, float], dict[str, float]]:
    """Signed face distances of measured points (base frame) from the part at ``T_base_wobj``."""
    T_wobj_base = invert_transform(T_base_wobj)
    res, edge = {}, {}
    for p in plan.points:
        if p.id not in measured_m:
            continue
        q = transform_points(T_wobj_base, measured_m[p.id]) - np.asarray(p.position_m)
        res[p.id] = float(np.dot(p.normal, q))
        if p.edge_normal is not None:
            edge[p.id] = float(np.dot(p.edge_normal, q))
    return res, edge
