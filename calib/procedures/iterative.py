"""``iterative``: the iterative best fit, measure all, fit, re-command all, until it settles.

Every ``fit`` point is measured in the current estimate, the frame is fitted by least squares,
and every search is commanded again in the fitted frame, round after round, until a round's fit
moves the frame less than ``tolerance_m`` (:func:`calib.estimators.runners.run_iterative_fit`).
It is the general form of the paper's step-by-step idea (each measurement commanded where the
part is now believed to be) and of the iterative alignments of CMM software. Its roles are the
best fit's (``fit``), so a best-fit plan can switch to it unchanged.
"""

from __future__ import annotations

from collections.abc import Sequence

import msgspec
import numpy as np

from calib.errors import PlanError
from calib.estimators.best_fit import best_fit
from calib.estimators.layout import search_constraint_set
from calib.estimators.runners import run_iterative_fit
from calib.probing import Probe
from calib.procedures.base import (
    FloatArray,
    Measured,
    ProcedureRun,
    RolePoint,
    check_edge_offset,
    edge_corrected,
    edge_offset_of,
)
from calib.procedures.best_fit import BestFitProcedure
from calib.structs import check_count, check_positive


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
            noise, or every round runs (0.1 mm by default).
        max_rounds: at most this many rounds of measurements.
        edge_event_offset_m: how far past a face's end the sensor reports it, removed from
            edge searches, metres (``None``: not measured; the validation uses the sensor
            model's value, ``wobjcal calibrate`` 0).
    """

    tolerance_m: float = 5e-4
    max_rounds: int = 5
    edge_event_offset_m: float | None = None

    def __post_init__(self) -> None:
        check_positive(self.tolerance_m, "tolerance_m")
        check_count(self.max_rounds, "max_rounds")
        check_edge_offset(self.edge_event_offset_m)


class IterativeProcedure(BestFitProcedure):
    """The iterative best fit as a :class:`~calib.procedures.base.ProcedureKind`: the best
    fit's roles and role checks, its own run and estimate."""

    method = "iterative"
    settings_type: type = Iterative
    summary = "measure all, fit, re-command every search in the new frame, until it settles"

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
        res = run_iterative_fit(
            pts,
            probe,
            T_base_wobj_nominal,
            tolerance_m=cfg.tolerance_m,
            max_rounds=cfg.max_rounds,
            edge_offset_m=edge_offset_of(cfg),
        )
        measured: dict[str, FloatArray] = {}
        for step in res.steps:  # every round's measurement: "<id>", "<id>#2", ...
            k = sum(1 for key in measured if key.split("#")[0] == step.point_id)
            measured[step.point_id if k == 0 else f"{step.point_id}#{k + 1}"] = step.measured_m
        return ProcedureRun(res.T_base_wobj, tuple(p.id for p in pts), measured)

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
        q = np.array([np.asarray(measured[p.id], dtype=float).reshape(-1, 3)[-1] for p in pts])
        q = edge_corrected(pts, q, T_base_wobj_nominal, edge_offset_of(cfg))
        res = best_fit(search_constraint_set(pts), q, T_base_wobj_nominal)
        ids = tuple(p.id for p in pts)
        return ProcedureRun(res.T_base_wobj, ids, dict(zip(ids, q, strict=True)))


def _settings(settings: object) -> Iterative:
    if settings is None:
        return Iterative()
    if not isinstance(settings, Iterative):
        raise PlanError(f"iterative needs Iterative settings, got {type(settings).__name__}")
    return settings


ITERATIVE = IterativeProcedure()
