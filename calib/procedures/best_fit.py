"""``best_fit``: least-squares point-to-plane fit of all ``fit`` points.

At least 3 points; together they must constrain all 6 degrees of freedom (an edge point
constrains two faces). The fit itself is :func:`calib.estimators.best_fit.best_fit`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from types import MappingProxyType
from typing import Literal

import msgspec
import numpy as np

from calib.errors import PlanError, UnobservableError
from calib.estimators.best_fit import best_fit
from calib.estimators.layout import search_constraint_set
from calib.estimators.runners import run_best_fit
from calib.limits import MAX_FIT_ITERATIONS
from calib.paper.stator_layout import StatorLayout
from calib.probing import Probe
from calib.procedures.base import (
    FloatArray,
    LayoutDesign,
    Measured,
    ProcedureRun,
    RolePoint,
    Steering,
    check_edge_offset,
    edge_corrected,
    edge_offset_of,
    unknown_role_problem,
)
from calib.structs import check_count

ROLE = "fit"
MIN_POINTS = 3


class BestFit(
    msgspec.Struct,
    tag="best_fit",
    tag_field="method",
    frozen=True,
    forbid_unknown_fields=True,
    kw_only=True,
):
    """Least-squares point-to-plane fit.

    Attributes:
        max_iterations: largest number of Gauss-Newton iterations.
        tol: stop when the step is smaller than this (metres, and radians times the layout
            size).
        edge_event_offset_m: how far past a face's end the sensor reports it, removed from
            edge searches, metres (``None``: not measured; every face uses the sensor model's
            value: ``planner.program.settings``).
    """

    max_iterations: int = 30
    tol: float = 1e-13
    edge_event_offset_m: float | None = None

    def __post_init__(self) -> None:
        check_count(
            self.max_iterations,
            "max_iterations",
            maximum=MAX_FIT_ITERATIONS,
            why="Gauss-Newton converges in fewer than 10",
        )
        check_edge_offset(self.edge_event_offset_m)


class BestFitProcedure:
    """The best fit as a :class:`~calib.procedures.base.ProcedureKind`."""

    method = "best_fit"
    settings_type: type = BestFit
    roles: tuple[str, ...] = (ROLE,)
    role_limits: Mapping[str, int | None] = MappingProxyType({ROLE: None})
    label = "best fit"
    summary = "least-squares fit of every point to its face"
    #: suggest grows the layout point by point until the target holds
    design: LayoutDesign | None = LayoutDesign(role=ROLE)
    #: an adaptive program updates after every point (the progressive best fit)
    steering: Steering | None = Steering()
    published: Mapping[tuple[str, float], float] | None = None
    #: Its linearised covariance is the least-squares one of its searches, ``(A^T W A)^-1``,
    #: for approach searches without a shared TCP error (a test checks it against the
    #: linearisation): the UI's live layout quality takes that fast path.
    least_squares = True
    #: an edge search counts by its edge coordinate only (see :meth:`run`)
    edge_rows: Literal["both", "edge"] = "edge"

    def role_problem(self, roles: Sequence[str], complete: bool) -> str:
        """See :meth:`ProcedureKind.role_problem`."""
        problem = unknown_role_problem(self.method, roles, self.roles)
        if problem or not complete:
            return problem
        if sum(r == ROLE for r in roles) < MIN_POINTS:
            return f"points: {self.method} needs at least {MIN_POINTS} points, got {len(roles)}"
        return ""

    def assign(self, points: Sequence[RolePoint]) -> list[RolePoint]:
        """Every point, with the role ``fit``."""
        if len(points) < MIN_POINTS:
            raise PlanError(f"{self.method} needs at least {MIN_POINTS} points, got {len(points)}")
        return [RolePoint(ROLE, rp.point) for rp in points]

    def run(
        self,
        points: Sequence[RolePoint],
        T_base_wobj_nominal: FloatArray,
        probe: Probe,
        settings: object,
    ) -> ProcedureRun:
        """Probe all points (updating the estimate after each), fit, and re-probe once.

        An edge search counts only by its edge coordinate (its track's coordinate across the
        face is the command's), with the sensor's edge-event offset removed.
        """
        pts = [rp.point for rp in self.assign(points)]
        return run_best_fit(
            pts,
            probe,
            T_base_wobj_nominal,
            edge_offset_m=edge_offset_of(settings),
            edge_rows="edge",
        )

    def estimate(
        self,
        points: Sequence[RolePoint],
        measured: Measured,
        T_base_wobj_nominal: FloatArray,
        settings: object,
    ) -> ProcedureRun:
        """The fit of the first measurement of every measured point (unmeasured points are
        left out; the fit refuses a set that no longer fixes all 6 degrees of freedom)."""
        cfg = settings if isinstance(settings, BestFit) else BestFit()
        pts = [rp.point for rp in self.assign(points) if rp.point.id in measured]
        raw = np.array([np.asarray(measured[p.id], dtype=float).reshape(-1, 3)[0] for p in pts])
        q = edge_corrected(pts, raw, T_base_wobj_nominal, edge_offset_of(cfg))
        cs = search_constraint_set(pts)  # an edge search: its edge coordinate only, as in run
        try:
            res = best_fit(
                cs, q, T_base_wobj_nominal, max_iterations=cfg.max_iterations, tol=cfg.tol
            )
        except UnobservableError as exc:
            if not any(p.search.kind == "edge" for p in pts):
                raise
            raise UnobservableError(
                f"{exc} (an edge search counts by its edge coordinate only: its height over "
                "the face it slides over is the program's command)",
                unconstrained=exc.unconstrained,
            ) from None
        ids = tuple(p.id for p in pts)
        return ProcedureRun(res.T_base_wobj, ids, dict(zip(ids, raw, strict=True)))

    def adaptive_layout(self, points: Sequence[RolePoint]) -> StatorLayout | None:
        """``None``: programs run the searches in the nominal frame."""
        return None


BEST_FIT = BestFitProcedure()
