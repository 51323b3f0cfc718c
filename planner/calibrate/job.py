"""Calibration of a plan from measured points, with any registered procedure.

:func:`calibrate_plan` computes ``T_base_wobj`` with the plan's procedure, or another one named
by ``method``, looked up in :data:`calib.procedures.PROCEDURES`: each procedure's
:meth:`~calib.procedures.base.ProcedureKind.estimate` takes the points with roles and the
measurements (retakes after the first measurement of a point). ``hultman2013`` replays the
paper's A-H procedure on the recorded points, ``three_two_one`` uses the plan's 3-2-1 roles (or
picks them from the faces when the plan was made for another method), ``best_fit`` fits every
measured point to its face(s). Pure numpy and ``calib``: no simulator.

Every result is screened before anyone pastes it into a robot (:func:`trust_problems`):

- gross errors: all measured points are fitted by least squares and each point-to-face residual
  is compared with the noise the plan expects (:func:`expected_sigma_m`: the plan's sensor and
  robot error models and the planar-face flatness); a point beyond ``k_sigma`` is flagged and,
  with redundant points, the point to re-measure is named by leave-one-out
  (:func:`calib.estimators.gross_errors.screen_measurements`); the points whose gross error no
  residual can show (a plain 3-2-1: all six) are named in a note, with how many points to add
  (:func:`calib.estimators.gross_errors.detectability`);
- misplacement: a frame farther from nominal than the plan's misplacement bound
  (``validation.misplacement``) is flagged;
- uncertainty: the frame's 6x6 covariance for that noise, propagated through the method
  (:func:`calib.procedures.uncertainty.propagated_covariance`), and 1 sigma per degree of
  freedom.

A result with problems is not ``trusted``: ``wobjcal calibrate`` then exits 1 without the
lines to paste unless ``--force``, and the UI does not draw the frame as calibrated.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, replace
from typing import Literal

import msgspec
import numpy as np
from numpy.typing import NDArray

from calib.errors import InputError
from calib.estimators.gross_errors import (
    K_SIGMA,
    GrossErrorScreen,
    detectability,
    screen_measurements,
)
from calib.frames import invert_transform, rotvec_from_matrix, transform_points
from calib.plan.file import Plan
from calib.plan.measurements import Measurements
from calib.procedures import PROCEDURES, procedure_kind
from calib.procedures.base import edge_offset_of
from calib.procedures.uncertainty import propagated_covariance
from calib.registry import lookup
from calib.tolerances import FACE_FLATNESS_RMS_M
from planner.plan_cell import T_base_world, nominal_T_base_wobj
from planner.program.build import plan_settings
from planner.program.settings import resolved_settings

FloatArray = NDArray[np.float64]


class MeasuredPoints(Mapping[str, FloatArray]):
    """The measurements of a file as ``{point id: (k, 3)}`` in the robot base frame, metres.

    Looking up a point that was not measured raises the file's own error, which names the point
    and, when the robot reported it, why it failed.

    Args:
        measurements: the measurements file's content.
        T_base_world: ``(4, 4)`` the world frame in the base frame (for world-frame files).
        T_base_controller: ``(4, 4)`` the robot controller's base frame in the base frame
            (:mod:`planner.robot.controller_base`): a ``base``-frame file holds what the
            controller measured, in its own base frame. ``None``: the same frame.
    """

    def __init__(
        self,
        measurements: Measurements,
        T_base_world: FloatArray,
        T_base_controller: FloatArray | None = None,
    ) -> None:
        self._m = measurements
        self._T = T_base_world
        self._T_bc = T_base_controller if measurements.frame == "base" else None
        self._cache: dict[str, FloatArray] = {}

    def __getitem__(self, point_id: str) -> FloatArray:
        if point_id not in self._cache:
            pts = self._m.sequence_m(point_id, self._T)  # raises, named
            if self._T_bc is not None:
                pts = transform_points(self._T_bc, pts)
            self._cache[point_id] = pts
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
        screen: the gross-error screen of the measured points.
        covariance: ``(6, 6)`` covariance of the frame for the expected noise, order
            ``(dx, dy, dz, rx, ry, rz)`` in the calibrated frame's axes (m^2, m rad, rad^2).
        problems: why the frame must not be used as it is (empty when ``trusted``).
        notes: what the user should know that does not stop the result (e.g. no redundancy).
        T_base_controller: ``(4, 4)`` the controller's base frame in the robot base frame
            (identity: the same frame).
    """

    method: str
    T_base_wobj: FloatArray
    T_base_wobj_nominal: FloatArray
    residuals_m: dict[str, float]
    edge_residuals_m: dict[str, float]
    used_ids: tuple[str, ...]
    skipped_ids: tuple[str, ...] = ()
    screen: GrossErrorScreen | None = None
    covariance: FloatArray | None = None
    problems: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    T_base_controller: FloatArray = field(default_factory=lambda: np.eye(4))

    @property
    def T_controller_wobj(self) -> FloatArray:
        """``(4, 4)`` the calibrated work object in the controller's base frame, m: what the
        lines to paste give the controller."""
        return invert_transform(self.T_base_controller) @ self.T_base_wobj

    @property
    def trusted(self) -> bool:
        """No gross error and within the misplacement bound: safe to paste."""
        return not self.problems

    @property
    def sigma_dof(self) -> FloatArray | None:
        """``(6,)`` 1 sigma of ``(x, y, z)`` (m) and of the rotations about ``(x, y, z)`` (rad),
        calibrated frame's axes; ``None`` without a covariance."""
        if self.covariance is None:
            return None
        return np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))


def calibrate_plan(
    plan: Plan,
    measurements: Measurements,
    method: str | None = None,
    k_sigma: float = K_SIGMA,
    T_base_controller: FloatArray | None = None,
) -> CalibrationOutput:
    """Compute ``T_base_wobj`` from measured points and screen it (see the module docstring).

    Args:
        plan: the plan the points were measured with.
        measurements: the measured points (base or world frame, m or mm).
        method: a procedure of :data:`calib.procedures.PROCEDURES`; default: the plan's.
        k_sigma: a residual beyond ``k_sigma`` times the expected noise flags its point.
        T_base_controller: ``(4, 4)`` the controller's base frame in the robot base frame
            (:func:`planner.plan_cell.plan_controller_base`), which ``base``-frame
            measurements are in; ``None``: the robot base frame itself. The result stays in
            the robot base frame (:attr:`CalibrationOutput.T_controller_wobj`: the
            controller's).

    Raises:
        InputError: unknown method, a measured id the plan does not have, missing
            measurements, a layout the method cannot use.
        ProbeFailedError: the A-H replay needs a point that was not measured.
    """
    method = method or plan.method
    lookup(PROCEDURES, method, "procedure (--method)")
    known = {p.id for p in plan.points}
    unknown = sorted(set(measurements.points) - known)
    if unknown:
        raise InputError(
            f"measurements: points {unknown} are not in the plan (its points: {sorted(known)})"
        )
    kind = procedure_kind(method)
    # the program's settings: an unset edge-event offset as the exported program has it (another
    # procedure than the plan's: its defaults, with the same offset)
    settings = (
        plan_settings(plan)
        if kind.method == plan.method
        else resolved_settings(
            msgspec.structs.replace(
                kind.settings_type(),
                edge_event_offset_m=getattr(plan.procedure, "edge_event_offset_m", None),
            ),
            plan.validation.sensor,
        )
    )
    T_nom = nominal_T_base_wobj(plan)
    T_bc = np.eye(4) if T_base_controller is None else np.asarray(T_base_controller, float)
    measured = MeasuredPoints(measurements, T_base_world(plan), T_bc)
    points = plan.role_points()
    run = kind.estimate(points, measured, T_nom, settings)
    first = {pid: measured[pid][0] for pid in measured}
    residuals, edge_res = point_residuals(plan, run.T_base_wobj, first)
    skipped = tuple(p.id for p in plan.points if p.id not in measured)
    sigma = expected_sigma_m(plan)
    # what the program that measured them measured (the plan's procedure's, whatever --method)
    rows = procedure_kind(plan.method).edge_rows
    screen = screen_plan_measurements(plan, first, run.T_base_wobj, sigma, k_sigma, rows)
    sequences = {pid: measured[pid] for pid in measured}
    cov = propagated_covariance(kind, points, sequences, T_nom, settings, sigma)
    problems = [*screen.messages(), *misplacement_problems(plan, run.T_base_wobj, screen)]
    unseen = detectability([p.to_probe_point() for p in plan.points if p.id in first], rows)
    if unseen.unseen and (why := plan.fixed_points()):
        unseen = replace(unseen, fixed=why)
    # which points' gross errors the screen could not see, and how many points would show them
    notes = [unseen.message()] if unseen.unseen else [screen.note] if screen.note else []
    return CalibrationOutput(
        method,
        run.T_base_wobj,
        T_nom,
        residuals,
        edge_res,
        run.used_ids,
        skipped,
        screen,
        cov,
        tuple(problems),
        tuple(notes),
        T_bc,
    )


def expected_sigma_m(plan: Plan) -> float:
    """Noise of one measured point along its face normal that the plan expects, metres.

    The root sum of squares of the sensor's scatter along an approach search (the proximity
    sensor's switching jitter, the touch probe's trigger repeatability), the robot's
    repeatability and absolute-accuracy amplitude (``validation.sensor``,
    ``validation.robot_error``) and the flatness a planar face may have
    (:data:`calib.tolerances.FACE_FLATNESS_RMS_M`: the part itself is not an exact plane where
    the sensor lands).
    """
    v = plan.validation
    parts = (
        v.sensor.search_noise("approach", 0.0).sensor_sigma_m,
        v.robot_error.repeatability_sigma_m,
        v.robot_error.accuracy_amplitude_m,
        FACE_FLATNESS_RMS_M,
    )
    return float(np.sqrt(sum(x * x for x in parts)))


def edge_offset_m(plan: Plan) -> float:
    """How far past the edge the sensor reports an edge, m, as the programs take it."""
    return edge_offset_of(plan_settings(plan))


def screen_plan_measurements(
    plan: Plan,
    measured_m: Mapping[str, FloatArray],
    T_base_wobj: FloatArray,
    sigma_m: float,
    k_sigma: float = K_SIGMA,
    edge_rows: Literal["both", "edge"] = "both",
) -> GrossErrorScreen:
    """Screen the first measurement of every measured point (see the module docstring), an
    edge search's point counting for what the program that took it measured (``edge_rows``:
    the plan's procedure's, :attr:`calib.procedures.base.ProcedureKind.edge_rows`).

    Edge points are moved back by the plan's edge-event offset along their search direction
    (turned into the base frame by ``T_base_wobj``, then by the least-squares fit itself).
    """
    probes = [p.to_probe_point() for p in plan.points if p.id in measured_m]
    offset = edge_offset_m(plan)
    T_nom = nominal_T_base_wobj(plan)

    def corrected(R: FloatArray) -> FloatArray:
        rows = []
        for p in probes:
            q = np.asarray(measured_m[p.id], dtype=np.float64)
            if p.search.kind == "edge" and p.search.edge_direction is not None and offset:
                q = q - offset * (R @ np.asarray(p.search.edge_direction, dtype=np.float64))
            rows.append(q)
        return np.array(rows, dtype=np.float64).reshape(-1, 3)

    def screen_at(R: FloatArray) -> GrossErrorScreen:
        return screen_measurements(probes, corrected(R), T_nom, sigma_m, k_sigma, edge_rows)

    screen = screen_at(T_base_wobj[:3, :3])
    if offset and screen.fit is not None:
        screen = screen_at(screen.fit.T_base_wobj[:3, :3])
    return screen


def misplacement_problems(
    plan: Plan, T_base_wobj: FloatArray, screen: GrossErrorScreen
) -> list[str]:
    """Why the frame lies beyond the plan's misplacement bound (``[]`` when within).

    The part may move by ``validation.misplacement``: a translation of the centroid of the
    probe points and a rotation about it. A frame beyond that (plus the screen's noise limit)
    is a gross error or a part that is not where the cell says.
    """
    if not plan.points:
        return []
    mis = plan.validation.misplacement
    T_nom = nominal_T_base_wobj(plan)
    c = np.mean([p.position_m for p in plan.points], axis=0)
    moved_m = float(np.linalg.norm(transform_points(T_base_wobj, c) - transform_points(T_nom, c)))
    angle = float(np.linalg.norm(rotvec_from_matrix(T_nom[:3, :3].T @ T_base_wobj[:3, :3])))
    positions = np.array([p.position_m for p in plan.points], dtype=np.float64)
    spread = max(float(np.sqrt(np.mean(np.sum((positions - c) ** 2, axis=1)))), 1e-3)
    out = []
    if moved_m > mis.max_translation_m + screen.limit_m:
        out.append(
            f"the calibrated frame moves the centre of the probe points by {moved_m * 1e3:.1f} mm "
            f"from nominal, beyond validation.misplacement.max_translation_m "
            f"({mis.max_translation_m * 1e3:.1f} mm)"
        )
    if angle > mis.max_angle_rad + screen.limit_m / spread:
        out.append(
            f"the calibrated frame is turned {np.degrees(angle):.2f} deg from nominal, beyond "
            f"validation.misplacement.max_angle_rad ({np.degrees(mis.max_angle_rad):.2f} deg)"
        )
    return out


def point_residuals(
    plan: Plan, T_base_wobj: FloatArray, measured_m: Mapping[str, FloatArray]
) -> tuple[dict[str, float], dict[str, float]]:
    """Signed face distances of measured points (base frame) from the part at ``T_base_wobj``;
    edge points moved back by the plan's edge-event offset (:func:`edge_offset_m`)."""
    T_wobj_base = invert_transform(T_base_wobj)
    offset = edge_offset_m(plan)
    res, edge = {}, {}
    for p in plan.points:
        if p.id not in measured_m:
            continue
        q = transform_points(T_wobj_base, measured_m[p.id]) - np.asarray(p.position_m)
        if p.search.edge_direction is not None:
            q = q - offset * np.asarray(p.search.edge_direction)
        res[p.id] = float(np.dot(p.normal, q))
        if p.edge_normal is not None:
            edge[p.id] = float(np.dot(p.edge_normal, q))
    return res, edge
