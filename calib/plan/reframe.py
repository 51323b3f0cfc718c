"""A plan re-expressed in a new work-object frame, nothing moved in the world.

A 3-point user frame (:func:`calib.user_frame.three_point_frame`) taught on the part gives
``T_old_new``, the new work-object frame in the old one. :func:`plan_in_frame` turns every
wobj-frame quantity of the plan into the new frame and moves the frame's cell pose so that the
part, the points and the report's points stay where they are in the world:

- ``T_world_wobj_new = T_world_wobj_old @ T_old_new``;
- ``T_wobj_mesh_new = inv(T_old_new) @ T_wobj_mesh_old`` (the mesh file is unchanged);
- points (position, normal, edge direction, edge normal), points of interest and the report's
  face points: ``p_new = inv(T_old_new) @ p_old``;
- via points keep their joint values (the robot moves as before); their informative TCP pose
  is re-expressed.

The misplacement bound (a ball and an angle) and the procedure's settings do not depend on
the frame's orientation and are kept.
"""

from __future__ import annotations

import msgspec
import numpy as np
from numpy.typing import ArrayLike

from calib.frames import check_transform, invert_transform, transform_points
from calib.plan.cell import Pose
from calib.plan.file import Plan, PlanPoint
from calib.plan.report_spec import ReportSpec
from calib.plan.vias import ViaPoint
from calib.user_frame import probe_point_in

__all__ = ["plan_in_frame"]

replace = msgspec.structs.replace


def _vec(T: np.ndarray, v: ArrayLike) -> tuple[float, float, float]:
    p = transform_points(T, v)
    return (float(p[0]), float(p[1]), float(p[2]))


def _report_in(T_new_old: np.ndarray, report: ReportSpec) -> ReportSpec:
    pois = report.points_of_interest
    if pois is not None:
        pois = [replace(p, position_m=_vec(T_new_old, p.position_m)) for p in pois]
    regions = report.regions
    if regions is not None:
        regions = [
            r
            if r.face_point_m is None
            else replace(r, face_point_m=_vec(T_new_old, r.face_point_m))
            for r in regions
        ]
    return replace(report, points_of_interest=pois, regions=regions)


def _via_in(T_new_old: np.ndarray, via: ViaPoint) -> ViaPoint:
    """A via in the new frame: the same joint values (the part has not moved, so neither does
    the robot); its informative TCP pose re-expressed."""
    if via.tcp_wobj is None:
        return via
    return replace(via, tcp_wobj=Pose.from_matrix(T_new_old @ via.tcp_wobj.matrix()))


def plan_in_frame(plan: Plan, T_old_new: ArrayLike) -> Plan:
    """``plan`` with its work-object frame replaced by ``T_old_new`` (the new frame in the old
    one, 4x4, metres); see the module docstring.

    Raises:
        InputError: ``T_old_new`` is not a rigid transform.
    """
    T = check_transform(T_old_new, "T_old_new")
    T_new_old = invert_transform(T)
    wo = plan.work_object
    work_object = replace(
        wo,
        T_world_wobj=Pose.from_matrix(wo.T_world_wobj.matrix() @ T),
        T_wobj_mesh=Pose.from_matrix(T_new_old @ wo.mesh_matrix()),
    )
    points = [
        PlanPoint.from_probe_point(
            probe_point_in(T_new_old, p.to_probe_point()),
            p.role,
            p.search.speed_m_s,
            tuple(_via_in(T_new_old, v) for v in p.via_points),
        )
        for p in plan.points
    ]
    validation = replace(plan.validation, report=_report_in(T_new_old, plan.validation.report))
    return replace(plan, work_object=work_object, points=points, validation=validation)
