"""Pure edits of the cell of a plan: poses of the work object, the robot base and fixtures,
snapping the part onto a fixture's top face, and a new work-object frame (3 points).

Humans see millimetres and Tait-Bryan z-y'-x'' angles in degrees (``calib/frames.py``); the
plan keeps metres and ``quat_wxyz``. Every function returns a new :class:`calib.plan.file.Plan`;
the UI makes it the session's in one undoable step (:meth:`webui.app.WobjcalApp.replace_source`).
"""

from __future__ import annotations

import dataclasses

import msgspec
import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray

from calib.errors import InputError
from calib.frames import (
    check_transform,
    invert_transform,
    make_transform,
    matrix_from_tait_bryan_zyx,
    tait_bryan_zyx_from_matrix,
    transform_points,
)
from calib.plan.cell import Pose
from calib.plan.file import Plan
from calib.plan.reframe import plan_in_frame
from calib.user_frame import probe_point_in
from webui.plan_adapter import with_source
from webui.plan_doc import UiPlan

#: What the cell panel can move: the work object, the robot base, or ``fixture:<name>``.
WORK_OBJECT = "work object"
ROBOT_BASE = "robot base"
FIXTURE_PREFIX = "fixture: "


def movable(plan: Plan) -> tuple[str, ...]:
    """The things of the plan's cell that can be moved, as the panel lists them."""
    return (WORK_OBJECT, ROBOT_BASE, *(FIXTURE_PREFIX + f.name for f in plan.cell.fixtures))


def pose_of(plan: Plan, target: str) -> NDArray[np.float64]:
    """``(4, 4)`` world pose of ``target`` (see :func:`movable`).

    Raises:
        InputError: no such thing in the cell (the message lists what there is).
    """
    if target == WORK_OBJECT:
        return plan.work_object.T_world_wobj.matrix()
    if target == ROBOT_BASE:
        return plan.cell.robot.T_world_base.matrix()
    for f in plan.cell.fixtures:
        if target == FIXTURE_PREFIX + f.name:
            return f.T_world_fixture.matrix()
    raise InputError(f"nothing called {target!r} to move; the cell has {list(movable(plan))}")


def with_pose(plan: Plan, target: str, T_world: ArrayLike) -> Plan:
    """``plan`` with ``target`` at the world pose ``T_world`` (4x4, metres).

    Raises:
        InputError: no such thing, or not a rigid transform (the message says which).
    """
    pose_of(plan, target)  # names the problem when there is no such thing
    pose = Pose.from_matrix(T_world)
    if target == WORK_OBJECT:
        wobj = msgspec.structs.replace(plan.work_object, T_world_wobj=pose)
        return msgspec.structs.replace(plan, work_object=wobj)
    if target == ROBOT_BASE:
        robot = msgspec.structs.replace(plan.cell.robot, T_world_base=pose)
        return msgspec.structs.replace(plan, cell=msgspec.structs.replace(plan.cell, robot=robot))
    fixtures = [
        msgspec.structs.replace(f, T_world_fixture=pose) if target == FIXTURE_PREFIX + f.name else f
        for f in plan.cell.fixtures
    ]
    return msgspec.structs.replace(plan, cell=msgspec.structs.replace(plan.cell, fixtures=fixtures))


def fields_of(T: ArrayLike) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """Position (mm) and z-y'-x'' angles (deg) of a 4x4 pose, rounded to 1e-6 for display."""
    T_arr = np.asarray(T, dtype=np.float64)
    p = np.round(T_arr[:3, 3] * 1000.0, 6)
    a = np.round(np.degrees(tait_bryan_zyx_from_matrix(T_arr[:3, :3])), 6)
    return (float(p[0]), float(p[1]), float(p[2])), (float(a[0]), float(a[1]), float(a[2]))


def pose_from_fields(position_mm: ArrayLike, zyx_deg: ArrayLike) -> NDArray[np.float64]:
    """The 4x4 pose of a position (mm) and z-y'-x'' angles (deg).

    Raises:
        InputError: a value is not a finite number.
    """
    p = np.asarray(position_mm, dtype=np.float64).reshape(3)
    a = np.asarray(zyx_deg, dtype=np.float64).reshape(3)
    if not (np.all(np.isfinite(p)) and np.all(np.isfinite(a))):
        raise InputError(f"pose: position and angles must be finite, got {p} mm, {a} deg")
    R = matrix_from_tait_bryan_zyx(*np.radians(a))
    return make_transform(R, p / 1000.0)


def snapped_onto(
    plan: Plan, part: trimesh.Trimesh, fixture: str, fixture_mesh: trimesh.Trimesh
) -> NDArray[np.float64]:
    """The work object's world pose resting on the top face of ``fixture``: its lowest point
    on the fixture's highest, its footprint centred over the fixture's; orientation kept.

    Args:
        plan: the plan (the part's current pose, the fixture's pose).
        part: the work-object mesh in its wobj frame, metres.
        fixture: the fixture's name.
        fixture_mesh: the fixture's mesh in its own frame, metres.

    Raises:
        InputError: no such fixture.
    """
    T_fix = pose_of(plan, FIXTURE_PREFIX + fixture)
    T = plan.work_object.T_world_wobj.matrix()
    verts = transform_points(T, part.vertices)
    top = transform_points(T_fix, fixture_mesh.vertices)
    shift = np.zeros(3)
    centre = 0.5 * (verts.min(axis=0) + verts.max(axis=0))
    table = 0.5 * (top.min(axis=0) + top.max(axis=0))
    shift[:2] = table[:2] - centre[:2]
    shift[2] = top[:, 2].max() - verts[:, 2].min()
    out = T.copy()
    out[:3, 3] += shift
    return out


def reframed(ui: UiPlan, T_old_new: ArrayLike) -> UiPlan:
    """``ui`` in a new work-object frame ``T_old_new`` (the new frame in the old, 4x4, m):
    its points and its plan re-expressed, the part and the points unmoved in the world
    (:func:`calib.plan.reframe.plan_in_frame`).

    Raises:
        InputError: no plan is loaded, or ``T_old_new`` is not a rigid transform.
    """
    if not isinstance(ui.source, Plan):
        raise InputError("load a plan first: there is no work object to give a frame")
    T_new_old = invert_transform(check_transform(T_old_new, "T_old_new"))
    points = tuple(
        dataclasses.replace(p, probe=probe_point_in(T_new_old, p.probe)) for p in ui.points
    )
    return with_source(dataclasses.replace(ui, points=points), plan_in_frame(ui.source, T_old_new))
