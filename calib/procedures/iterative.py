"""``iterative``: the iterative best fit, measure all, fit, re-command all, until it settles.

Every ``fit`` point is measured in the current estimate, the frame is fitted by least squares,
and every search is commanded again in the fitted frame, round after round, until a round's fit
moves the frame less than ``tolerance_m`` (:func:`run_iterative_fit`).
It is the general form of the paper's step-by-step idea (each measurement commanded where the
part is now believed to be) and of the iterative alignments of CMM software. Its roles are the
best fit's (``fit``), so a best-fit plan can switch to it unchanged.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence

import msgspec
import numpy as np
from numpy.typing import ArrayLike

from calib.errors import PlanError, ShapeError
from calib.estimators.best_fit import BestFitResult, best_fit
from calib.estimators.layout import constraint_set, search_constraint_set
from calib.estimators.observability import require_observable
from calib.estimators.runners import corrected_point, probe_point
from calib.frames import check_transform, motion_between
from calib.limits import MAX_ROUNDS
from calib.probing import Probe, ProbePoint
from calib.procedure_run import EstimateUpdate, ProbeStep, measured_by_key
from calib.procedures.base import (
    FloatArray,
    Measured,
    ProcedureRun,
    RolePoint,
    Steering,
    check_edge_offset,
    edge_corrected,
    edge_offset_of,
)
from calib.procedures.best_fit import BestFitProcedure
from calib.structs import check_count, check_positive

logger = logging.getLogger(__name__)


class Iterative(
    msgspec.Struct,
    tag="iterative",
    tag_field="method",
    frozen=True,
    forbid_unknown_fields=True,
    kw_only=True,
):
    """The iterative best fit.

    Attributes:
        tolerance_m: stop when a round's fit moves the frame by less than this (translation in
            metres, rotation in radians times the layout size); it must exceed the frame's
            noise, or every round runs (0.5 mm by default).
        max_rounds: at most this many rounds of measurements.
        edge_event_offset_m: how far past a face's end the sensor reports it, removed from
            edge searches, metres (``None``: not measured; every face uses the sensor model's
            value: ``planner.program.settings``).
    """

    tolerance_m: float = 5e-4
    max_rounds: int = 5
    edge_event_offset_m: float | None = None

    def __post_init__(self) -> None:
        check_positive(self.tolerance_m, "tolerance_m")
        check_count(
            self.max_rounds,
            "max_rounds",
            maximum=MAX_ROUNDS,
            why="each round runs every search again; it settles in 2 or 3",
        )
        check_edge_offset(self.edge_event_offset_m)


class IterativeProcedure(BestFitProcedure):
    """The iterative best fit as a :class:`~calib.procedures.base.ProcedureKind`: the best
    fit's roles and role checks, its own run and estimate."""

    method = "iterative"
    settings_type: type = Iterative
    label = "iterative best fit"
    summary = "measure all, fit, re-command every search in the new frame, until it settles"
    #: the best fit's design (inherited); no search-by-search steering: its rounds re-command
    #: every search in the last round's fit
    steering: Steering | None = None

    def run(
        self,
        points: Sequence[RolePoint],
        T_base_wobj_nominal: FloatArray,
        probe: Probe,
        settings: object,
    ) -> ProcedureRun:
        """Round after round until the fit settles; the frame is the last round's fit."""
        cfg = _settings(settings)
        pts = [rp.point for rp in self.assign(points)]
        return run_iterative_fit(
            pts,
            probe,
            T_base_wobj_nominal,
            tolerance_m=cfg.tolerance_m,
            max_rounds=cfg.max_rounds,
            edge_offset_m=edge_offset_of(cfg),
        )

    def estimate(
        self,
        points: Sequence[RolePoint],
        measured: Measured,
        T_base_wobj_nominal: FloatArray,
        settings: object,
    ) -> ProcedureRun:
        """The fit of the last measurement of every measured point (its last round), an edge
        search counted by its edge coordinate only."""
        cfg = _settings(settings)
        pts = [rp.point for rp in self.assign(points) if rp.point.id in measured]
        raw = np.array([np.asarray(measured[p.id], dtype=float).reshape(-1, 3)[-1] for p in pts])
        q = edge_corrected(pts, raw, T_base_wobj_nominal, edge_offset_of(cfg))
        res = best_fit(search_constraint_set(pts), q, T_base_wobj_nominal)
        ids = tuple(p.id for p in pts)
        return ProcedureRun(res.T_base_wobj, ids, dict(zip(ids, raw, strict=True)))


def run_iterative_fit(
    points: Sequence[ProbePoint],
    probe: Probe,
    T_base_wobj_start: ArrayLike,
    *,
    tolerance_m: float = 5e-4,
    max_rounds: int = 5,
    edge_offset_m: float = 0.0,
    sigma_m: float | None = None,
) -> ProcedureRun:
    """The iterative best fit: measure every point, fit, re-command every search in the new
    estimate, and repeat until a round's fit moves the frame less than ``tolerance_m``.

    The general form of the paper's step-by-step idea and of the iterative alignment of CMM
    software: each round commands all searches where the previous fit says the part is, so
    the searches land where the plan put them. The final frame is the fit of the last round's
    measurements; an edge search contributes only its edge coordinate
    (:func:`calib.estimators.layout.search_constraint_set`).

    Args:
        points: the probe points (must constrain all 6 DOF with edge searches counted by
            their edge coordinate only).
        probe: runs one search.
        T_base_wobj_start: ``(4, 4)`` start estimate (the first round is commanded in it).
        tolerance_m: stop when a round's fit moves the frame it was commanded in by less than
            this: translation in metres, rotation in radians times the layout size. A round's
            fit moves by about the frame's noise even at the fixed point, so the tolerance must
            exceed that (0.5 mm by default).
        max_rounds: at most this many rounds (>= 1); the last round's fit is returned even
            when it moved more than the tolerance.
        edge_offset_m: the sensor's edge-event offset removed from edge searches, metres.
        sigma_m: measurement standard deviation for the covariance, metres.

    Raises:
        UnobservableError: the layout leaves a motion unconstrained (checked before probing).
        ProbeFailedError: a probe failed.
        ShapeError: a bad tolerance or round count.
    """
    T = check_transform(T_base_wobj_start, "T_base_wobj_start").copy()
    if isinstance(max_rounds, bool) or not isinstance(max_rounds, int) or max_rounds < 1:
        raise ShapeError(f"max_rounds must be an integer >= 1, got {max_rounds!r}")
    if not (np.isfinite(tolerance_m) and tolerance_m > 0):
        raise ShapeError(f"tolerance_m must be > 0, got {tolerance_m!r}")
    cs = constraint_set(points, edge_rows="edge")
    require_observable(cs)
    pts = tuple(points)
    steps: list[ProbeStep] = []
    updates: list[EstimateUpdate] = []
    fit: BestFitResult | None = None
    for rnd in range(max_rounds):
        done = [probe_point(probe, p, T, rnd) for p in pts]
        q = np.array([corrected_point(s, edge_offset_m) for s in done])
        fit = best_fit(cs, q, T, sigma_m=sigma_m)
        moved = motion_between(T, fit.T_base_wobj)
        T = fit.T_base_wobj
        updates.append(EstimateUpdate(T, f"best fit (round {rnd + 1})", cs.point_ids))
        steps += done
        size = max(float(np.linalg.norm(moved[:3])), float(np.linalg.norm(moved[3:])) * cs.scale_m)
        logger.info("iterative fit round %d: moved %.3g mm", rnd, size * 1e3)
        if size < tolerance_m:
            break
    assert fit is not None  # max_rounds >= 1 is checked above
    return ProcedureRun(T, cs.point_ids, measured_by_key(steps), tuple(steps), tuple(updates), fit)


def _settings(settings: object) -> Iterative:
    if settings is None:
        return Iterative()
    if not isinstance(settings, Iterative):
        raise PlanError(f"iterative needs Iterative settings, got {type(settings).__name__}")
    return settings


ITERATIVE = IterativeProcedure()
