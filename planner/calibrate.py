"""Calibration of a plan from measured points, with any of the three methods.

:func:`calibrate_plan` computes ``T_base_wobj``: ``hultman2013`` replays the paper's A-H
procedure with a probe that returns the recorded points (retakes of C and D as ``C2``/``D2``),
``three_two_one`` uses the plan's 3-2-1 roles (or picks them from the faces when the plan was
made for another method, :func:`assign_three_two_one`), ``best_fit`` fits every measured point
to its face(s). Pure numpy and ``calib``: no simulator.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from calib.errors import InputError
from calib.estimators.best_fit import best_fit
from calib.estimators.three_two_one import ThreeTwoOneLayout, three_two_one
from calib.frames import invert_transform, transform_points
from calib.paper.stator_procedure import (
    StatorSettings,
    probe_from_measurements,
    run_stator_procedure,
)
from calib.plan.file import Plan, PlanError, PlanPoint
from calib.plan.measurements import Measurements
from calib.plan.procedures import (
    METHODS,
    THREE_TWO_ONE_ROLES,
    BestFit,
    Hultman2013,
)
from planner.plan_cell import T_base_world, hultman_points, nominal_T_base_wobj

FloatArray = NDArray[np.float64]


def _faces(p: PlanPoint) -> list[tuple[float, ...]]:
    """The faces a point can stand for: ``(nx, ny, nz, offset)`` rounded, own face first."""
    faces = [(*p.normal, float(np.dot(p.normal, p.position_m)))]
    if p.edge_normal is not None:
        faces.append((*p.edge_normal, float(np.dot(p.edge_normal, p.position_m))))
    return [tuple(round(v, 6) for v in f) for f in faces]


def assign_three_two_one(plan: Plan) -> dict[str, list[PlanPoint]]:
    """3-2-1 roles of the plan's points: the plan's own, else picked from the faces.

    Picking: the primary face is the one most points lie on (three spanning the largest
    triangle); the secondary is the face, not parallel to it, with the most other points (the
    two farthest apart); the tertiary is a remaining point on a third face.
    """
    if plan.method == "three_two_one":
        plan.require_complete()
        return {r: [p for p in plan.points if p.role == r] for r in THREE_TWO_ONE_ROLES}
    groups: dict[tuple[float, ...], list[PlanPoint]] = {}
    for p in plan.points:
        for f in _faces(p):
            groups.setdefault(f, []).append(p)
    ranked = sorted(groups.items(), key=lambda kv: -len(kv[1]))
    primary_face, primary_pts = ranked[0]
    if len(primary_pts) < 3:
        raise PlanError("three_two_one: no face with 3 points for the primary role")
    plain = [p for p in primary_pts if p.search.kind == "approach"]
    if len(plain) >= 3:  # keep edge points free: they also stand for the face whose end they find
        primary_pts = plain
    best, area = primary_pts[:3], -1.0
    for i, a in enumerate(primary_pts):
        for j in range(i + 1, len(primary_pts)):
            for b in primary_pts[j + 1 :]:
                c = primary_pts[j]
                s = float(
                    np.linalg.norm(
                        np.cross(
                            np.subtract(c.position_m, a.position_m),
                            np.subtract(b.position_m, a.position_m),
                        )
                    )
                )
                if s > area:
                    best, area = [a, c, b], s
    used = {p.id for p in best}
    chosen: dict[str, list[PlanPoint]] = {"primary": best}
    normals = [np.array(primary_face[:3])]
    for role, need in (("secondary", 2), ("tertiary", 1)):
        for face, pts in ranked:
            n = np.array(face[:3])
            if any(abs(float(n @ m)) > math.cos(math.radians(2.0)) for m in normals):
                continue
            free = [p for p in pts if p.id not in used]
            if len(free) >= need:
                if need == 2:
                    pairs: list[tuple[PlanPoint, PlanPoint]] = [
                        (a, b) for i, a in enumerate(free) for b in free[i + 1 :]
                    ]

                    def apart(ab: tuple[PlanPoint, PlanPoint]) -> float:
                        return float(
                            np.linalg.norm(np.subtract(ab[0].position_m, ab[1].position_m))
                        )

                    far = max(pairs, key=apart)
                    pick = [far[0], far[1]]
                else:
                    pick = free[:1]
                chosen[role] = pick
                used |= {p.id for p in pick}
                normals.append(n)
                break
        else:
            raise PlanError(f"three_two_one: no face for the {role} role among the plan's points")
    return chosen


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
        method: ``hultman2013``, ``three_two_one`` or ``best_fit``; default: the plan's.

    Raises:
        InputError: unknown method, a measured id the plan does not have, missing
            measurements, a layout the method cannot use.
        ProbeFailedError: the A-H replay needs a point that was not measured.
    """
    method = method or plan.method
    if method not in METHODS:
        raise InputError(f"method must be one of {list(METHODS)}, got {method!r}")
    known = {p.id for p in plan.points}
    unknown = sorted(set(measurements.points) - known)
    if unknown:
        raise InputError(
            f"measurements: points {unknown} are not in the plan (its points: {sorted(known)})"
        )
    T_nom = nominal_T_base_wobj(plan)
    T_bw = T_base_world(plan)
    measured = {pid: measurements.sequence_m(pid, T_bw) for pid in measurements.points}

    def first(pid: str) -> FloatArray:
        if pid not in measured:
            measurements.sequence_m(pid, T_bw)  # raises naming the point and any failure
        return measured[pid][0]

    if method == "hultman2013":
        by_role = hultman_points(plan)
        role_to_id = {p.role: p.id for p in plan.points}
        table = {role: first(pid) for role, pid in role_to_id.items()}
        for role in ("C", "D"):
            pid = role_to_id[role]
            if pid in measured:
                seq = measured[pid]
                table[f"{role}2"] = seq[1] if len(seq) > 1 else seq[0]
        settings = plan.procedure if isinstance(plan.procedure, Hultman2013) else Hultman2013()
        result = run_stator_procedure(
            by_role,
            T_nom,
            probe_from_measurements(table),
            StatorSettings(
                beta1_rad=settings.beta1_rad,
                p3_height_m=settings.p3_height_m,
                retake_c_d=settings.retake_c_d,
                edge_start_from_measured=settings.edge_start_from_measured,
                edge_start_offset_m=settings.edge_start_offset_m,
                edge_event_offset_m=settings.edge_event_offset_m or 0.0,
            ),
        )
        T, used = result.T_base_wobj, tuple(role_to_id[r] for r in by_role)
    elif method == "three_two_one":
        roles = assign_three_two_one(plan)
        ordered = roles["primary"] + roles["secondary"] + roles["tertiary"]
        primary, secondary, tertiary = (
            [p.to_probe_point() for p in roles[r]] for r in ("primary", "secondary", "tertiary")
        )
        layout = ThreeTwoOneLayout.from_points(primary, secondary, tertiary)
        q = np.array([first(p.id) for p in ordered])
        T, used = three_two_one(layout, q, T_nom).T_base_wobj, tuple(p.id for p in ordered)
    else:
        pts = [p for p in plan.points if p.id in measured]
        settings_bf = plan.procedure if isinstance(plan.procedure, BestFit) else BestFit()
        res = best_fit(
            [p.to_probe_point() for p in pts],
            np.array([first(p.id) for p in pts]),
            T_nom,
            max_iterations=settings_bf.max_iterations,
            tol=settings_bf.tol,
        )
        T, used = res.T_base_wobj, tuple(p.id for p in pts)
    residuals, edge_res = point_residuals(plan, T, {pid: s[0] for pid, s in measured.items()})
    skipped = tuple(p.id for p in plan.points if p.id not in measured)
    return CalibrationOutput(method, T, T_nom, residuals, edge_res, used, skipped)


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
