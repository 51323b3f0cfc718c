"""Step-by-step runners of the general methods (3-2-1 and best fit), driven by a probe callback.

A runner never moves anything. For each point it builds
:meth:`calib.probing.SearchCommand.from_point` in the current estimate of ``T_base_wobj`` and
calls the :data:`calib.probing.Probe`; as measurements come in it re-estimates the frame so the
remaining points are commanded where the part really is. The same code drives a simulation
(``planner``) or a real robot.

Between the closed-form steps a runner updates the estimate with the *smallest* motion (rotation
about the layout centroid, scaled by the layout size) that puts the points measured so far on
their faces: after the primary points of a 3-2-1 this fixes the primary plane and leaves the
rest of the estimate alone, as the paper does step by step.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_vector3
from calib.errors import ProbeFailedError, ShapeError
from calib.estimators.best_fit import BestFitResult, best_fit
from calib.estimators.layout import (
    MIN_SCALE_M,
    ConstraintSet,
    constraint_jacobian,
    constraint_set,
    cross_rows,
    small_motion_matrix,
)
from calib.estimators.observability import require_observable
from calib.estimators.three_two_one import ThreeTwoOneLayout, ThreeTwoOneResult, three_two_one
from calib.frames import check_transform
from calib.probing import Probe, ProbePoint, SearchCommand
from calib.procedure_run import EstimateUpdate, ProbeStep, ProcedureRun, measured_by_key

FloatArray = NDArray[np.float64]
#: A motion counts as fixed by a layout when its scaled singular value is above this part of the
#: largest: below it, a measurement's noise moves the estimate by ten thousand times as much
#: (float32 meshes leave "parallel" rows 1e-6 apart; a genuinely weak layout, two points 5 mm
#: apart turning a 100 mm layout, sits at about 0.05).
FIXED_RCOND = 1e-4
logger = logging.getLogger(__name__)
#: The name of an update by the smallest motion that puts the points so far on their faces.
SMALLEST_MOTION = "smallest motion onto the faces measured so far"


def probe_point(
    probe: Probe, point: ProbePoint, T_base_wobj: FloatArray, round_index: int = 0
) -> ProbeStep:
    """Command one search for ``point`` in the estimate ``T_base_wobj`` and check the result.

    Raises:
        ProbeFailedError: the probe reported a failure (its reason is kept).
        ShapeError: the probe returned something that is not a finite ``(3,)`` point.
    """
    command = SearchCommand.from_point(point, T_base_wobj)
    result = probe(command)
    if not result.ok:
        raise ProbeFailedError(point.id, result.reason or "no reason given")
    q = check_vector3(np.asarray(result.point_m), f"probe result for point {point.id!r}")
    logger.debug("probed %s (round %d): %s", point.id, round_index, q)
    return ProbeStep(point.id, round_index, command, q)


def corrected_point(step: ProbeStep, edge_offset_m: float = 0.0) -> FloatArray:
    """``(3,)`` a step's measurement as a fit uses it: an edge search's point moved back along
    its direction by the sensor's known edge-event offset (how far past the edge the sensor
    reports it; 0 for a sensor that reports the edge itself), base frame, metres."""
    if edge_offset_m and step.command.kind == "edge":
        return step.measured_m - edge_offset_m * np.asarray(step.command.direction, float)
    return step.measured_m


def min_norm_update(
    cs: ConstraintSet,
    measured_base: ArrayLike,
    T_base_wobj: ArrayLike,
    pivot_m: FloatArray | None = None,
    scale_m: float | None = None,
    iterations: int = 10,
    basis: FloatArray | None = None,
) -> FloatArray:
    """Move ``T_base_wobj`` by the smallest motion that puts the measured points on their faces.

    The motion is measured with rotations about ``pivot_m`` (default: the layout centroid) scaled
    by ``scale_m`` (default: the layout size); constraints that the points do not fix are left
    as they were. With a full-rank layout this is the least-squares best fit.

    Which motions the points fix is decided on the *nominal* layout (the plan's points, as the
    prediction and :mod:`calib.estimators.steering` see it), not on the measured points: two
    edge searches on opposite, parallel edges at the same coordinate fix no turn between them,
    but measured a few micrometres apart they would "fix" it with a noise gain of thousands (a
    0.04 mm disagreement turned the plate's estimate by 40 degrees and commanded the next
    search 63 m away; the plate's mesh is float32, so "the same coordinate" differs by 0.1 um
    and the relative threshold is :data:`FIXED_RCOND`, not machine precision). The step is the
    min-norm solution in the nominally fixed motions only.

    Args:
        cs: constraints of the points measured so far.
        measured_base: ``(N, 3)`` their measurements, base frame, metres.
        T_base_wobj: ``(4, 4)`` current estimate.
        pivot_m: ``(3,)`` wobj point the rotations are taken about.
        scale_m: length that converts rotations to translations, metres.
        iterations: Gauss-Newton iterations (the step is min-norm in each).
        basis: ``(6, r)`` :func:`fixed_motions` of ``cs`` about ``pivot_m`` and ``scale_m``
            when the caller has it already (it depends on the nominal layout only).
    """
    T = check_transform(T_base_wobj, "T_base_wobj").copy()
    q = np.asarray(measured_base, dtype=np.float64)[cs.point_index]
    c = cs.centroid_m if pivot_m is None else pivot_m
    L = cs.scale_m if scale_m is None else scale_m
    V = fixed_motions(cs, c, L) if basis is None else basis
    for _ in range(iterations):
        x = (q - T[:3, 3]) @ T[:3, :3]
        r = np.einsum("ij,ij->i", cs.normals, x - cs.nominal_m)
        J = constraint_jacobian(cs.normals, x - c)
        J[:, 3:] /= L
        step = -V @ (np.linalg.pinv(J @ V, rcond=1e-9) @ r)
        w = step[3:] / L
        T = T @ small_motion_matrix(np.concatenate([step[:3] - cross_rows(w, c), w]))
        if float(np.max(np.abs(step))) < 1e-9:  # 1 nm: the estimate only steers the next search
            break
    return T


def fixed_motions(cs: ConstraintSet, pivot_m: FloatArray, scale_m: float) -> FloatArray:
    """``(6, r)`` orthonormal basis of the scaled motions ``(t, L w)`` the nominal layout fixes.

    The row space of the nominal constraint rows ``[n, (x - c) x n / L]``: singular values
    above :data:`FIXED_RCOND` of the largest (as :mod:`calib.estimators.steering` takes them).
    """
    J = constraint_jacobian(cs.normals, cs.nominal_m - pivot_m)
    J[:, 3:] /= scale_m
    _, sv, Vt = np.linalg.svd(J, full_matrices=False)
    rank = int(np.sum(sv > FIXED_RCOND * sv[0])) if len(sv) and sv[0] > 0 else 0
    return np.ascontiguousarray(Vt[:rank].T)


def leading_points(cs: ConstraintSet, n: int) -> ConstraintSet:
    """The constraints of the first ``n`` points of ``cs`` (already validated: no checks)."""
    rows = cs.point_index < n
    positions = cs.positions_m[:n]
    centroid = positions.mean(axis=0)
    rms = float(np.sqrt(np.mean(np.sum((positions - centroid) ** 2, axis=1))))
    return ConstraintSet(
        point_ids=cs.point_ids[:n],
        positions_m=positions,
        normals=cs.normals[rows],
        nominal_m=cs.nominal_m[rows],
        point_index=cs.point_index[rows],
        centroid_m=centroid,
        scale_m=max(rms, MIN_SCALE_M),
    )


def run_three_two_one(
    layout: ThreeTwoOneLayout,
    probe: Probe,
    T_base_wobj_start: ArrayLike,
    *,
    rounds: int = 1,
    edge_offset_m: float = 0.0,
) -> ProcedureRun:
    """Run a 3-2-1 alignment step by step.

    Round by round: probe the three primary points in the current estimate and fix the primary
    plane (smallest motion); probe the two secondary points in that estimate and fix both
    planes; probe the tertiary point and solve the 3-2-1 in closed form. Later rounds repeat
    all six probes in the latest estimate, so each point lands nearer its nominal spot.

    Args:
        layout: the roles.
        probe: runs one search (see :data:`calib.probing.Probe`).
        T_base_wobj_start: ``(4, 4)`` start estimate (e.g. the nominal part placement).
        rounds: number of passes over the six points (>= 1).
        edge_offset_m: the sensor's edge-event offset removed from edge searches, metres
            (:func:`corrected_point`).

    Raises:
        ProbeFailedError: a probe failed.
        DegenerateGeometryError: the measured points cannot define a frame.
    """
    T = check_transform(T_base_wobj_start, "T_base_wobj_start").copy()
    _check_rounds(rounds)
    all_cs = constraint_set(layout.points, "3-2-1 layout")
    groups = (layout.primary, layout.primary + layout.secondary)
    steps: list[ProbeStep] = []
    updates: list[EstimateUpdate] = []
    fit: ThreeTwoOneResult | None = None
    for rnd in range(rounds):
        done: list[ProbeStep] = []
        for group, new in zip(groups, (layout.primary, layout.secondary)):
            done += [probe_point(probe, p, T, rnd) for p in new]
            cs = constraint_set(group)
            q = np.array([corrected_point(s, edge_offset_m) for s in done])
            T = min_norm_update(cs, q, T, all_cs.centroid_m, all_cs.scale_m)
            updates.append(EstimateUpdate(T, SMALLEST_MOTION, _ids(done)))
        done.append(probe_point(probe, layout.tertiary[0], T, rnd))
        q = np.array([corrected_point(s, edge_offset_m) for s in done])
        fit = three_two_one(layout, q, T_base_wobj_guess=T)
        T = fit.T_base_wobj
        updates.append(EstimateUpdate(T, "3-2-1", _ids(done)))
        steps += done
        logger.info("3-2-1 round %d done", rnd)
    assert fit is not None  # rounds >= 1 is checked above
    return _run(T, all_cs.point_ids, steps, updates, fit)


def run_best_fit(
    points: Sequence[ProbePoint],
    probe: Probe,
    T_base_wobj_start: ArrayLike,
    *,
    rounds: int = 2,
    progressive: bool = True,
    sigma_m: float | None = None,
    edge_offset_m: float = 0.0,
    edge_rows: Literal["both", "edge"] = "both",
) -> ProcedureRun:
    """Probe all points, fit, and re-probe in the new estimate, for ``rounds`` passes.

    Args:
        points: the probe points (must constrain all 6 DOF).
        probe: runs one search.
        T_base_wobj_start: ``(4, 4)`` start estimate.
        rounds: number of passes over all points (>= 1).
        progressive: in the first pass, update the estimate (smallest motion) after every
            measurement, so later points are commanded where the part really is.
        sigma_m: measurement standard deviation for the covariance, metres (``None``: estimated
            from the residuals).
        edge_offset_m: the sensor's edge-event offset removed from edge searches, metres.
        edge_rows: ``"edge"``: an edge search constrains only the face whose end it finds
            (:func:`calib.estimators.layout.search_constraint_set`); ``"both"``: also the face
            it slides over.

    Raises:
        UnobservableError: the layout leaves a motion unconstrained (checked before probing).
        ProbeFailedError: a probe failed.
    """
    T = check_transform(T_base_wobj_start, "T_base_wobj_start").copy()
    _check_rounds(rounds)
    cs = constraint_set(points, edge_rows=edge_rows)
    require_observable(cs)
    pts = tuple(points)
    steps: list[ProbeStep] = []
    updates: list[EstimateUpdate] = []
    fit: BestFitResult | None = None
    for rnd in range(rounds):
        done: list[ProbeStep] = []
        for k, p in enumerate(pts):
            done.append(probe_point(probe, p, T, rnd))
            if progressive and rnd == 0 and k + 1 < len(pts):
                sub = leading_points(cs, k + 1)
                q = np.array([corrected_point(s, edge_offset_m) for s in done])
                T = min_norm_update(sub, q, T, cs.centroid_m, cs.scale_m)
                updates.append(EstimateUpdate(T, SMALLEST_MOTION, _ids(done)))
        q = np.array([corrected_point(s, edge_offset_m) for s in done])
        fit = best_fit(cs, q, T, sigma_m=sigma_m)
        T = fit.T_base_wobj
        updates.append(EstimateUpdate(T, "best fit", _ids(done)))
        steps += done
        logger.info("best-fit round %d: rms %.3g mm", rnd, fit.rms_m * 1e3)
    assert fit is not None  # rounds >= 1 is checked above
    return _run(T, cs.point_ids, steps, updates, fit)


def _ids(steps: Sequence[ProbeStep]) -> tuple[str, ...]:
    return tuple(s.point_id for s in steps)


def _run(
    T: FloatArray,
    used_ids: Sequence[str],
    steps: Sequence[ProbeStep],
    updates: Sequence[EstimateUpdate],
    fit: ThreeTwoOneResult | BestFitResult,
) -> ProcedureRun:
    """The run of a step runner: every measurement keyed ``"<id>"``, ``"<id>#<k>"``."""
    return ProcedureRun(
        T, tuple(used_ids), measured_by_key(steps), tuple(steps), tuple(updates), fit
    )


def _check_rounds(rounds: int) -> None:
    if not isinstance(rounds, int | np.integer) or isinstance(rounds, bool) or rounds < 1:
        raise ShapeError(f"rounds must be an integer >= 1, got {rounds!r}")
