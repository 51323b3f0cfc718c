"""The accuracy-versus-time front of a grown layout (a procedure whose
:class:`~calib.procedures.base.LayoutDesign` grows: the best fit, the iterative best fit), and
the fastest plan under a target.

For every size the design grows through (6 points up to ``max_points``,
:func:`planner.suggest.steps.best_fit_design`), two plans are written and judged as
``wobjcal check --format`` judges them, with their vias (:func:`planner.check.vias.
plan_with_vias`), so every number in the front describes a plan that can be written and
exported as it stands:

- ``landing``: the design's points in the order that keeps each footprint on its face
  (:meth:`planner.suggest.order.Sequencer.order_progressive`, what ``--objective accuracy``
  writes);
- ``time``: the same points in the order of least joint-move time between their checked safe
  starts (:func:`planner.suggest.time_order.shortest_order`) that still lands every point on
  its face; edge searches stay last, nearest first.

Both are written with every search sized for the whole misplacement. When the controller runs
the procedure adaptively, steering it search by search (its registry entry's
:class:`~calib.procedures.base.Steering`), a third plan of each size takes the faster of the
two orders with its searches ``steered`` (:func:`planner.suggest.search_sizing.steered_plan`):
the searches after the first start nearer and run shorter, sized for what the estimate before
them leaves. Only an adaptive program runs such a plan (a FANUC TP export refuses it), so its
row says so.

Each row carries the check's predicted error at the confidence (the controller's program
linearised, :func:`planner.check.job.plan_quality`) and its estimated cycle time
(:mod:`planner.check.cycle`). ``--objective time`` writes the row of least cycle time whose
plan check passes, whose layout is not weak and whose error holds the target.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import NDArray

from calib.estimators.design import Design
from calib.plan.file import Plan
from calib.procedures import ProcedureKind
from planner.check.cycle import cell_motion_limits
from planner.check.job import check_plan, plan_quality
from planner.check.results import PlanCheck
from planner.check.vias import plan_with_vias
from planner.program.controllers import controller
from planner.program.cycle_time import JointMotionLimits, joint_move_time
from planner.suggest.search_sizing import steered_plan
from planner.suggest.steps import Context, SuggestProgress, best_fit_design, suggested_plan
from planner.suggest.time_order import shortest_order

if TYPE_CHECKING:
    from planner.sim.quality import LayoutQuality

FloatArray = NDArray[np.float64]
Order = Literal["landing", "time"]
Searches = Literal["whole", "steered"]
OBJECTIVES = ("accuracy", "time")


@dataclass(frozen=True)
class FrontRow:
    """One written plan of the front.

    Attributes:
        points: its number of points.
        order: ``"landing"`` (the design's order) or ``"time"`` (least move time).
        searches: ``"whole"`` (sized for the whole misplacement) or ``"steered"`` (for an
            adaptive program, :func:`planner.suggest.search_sizing.steered_plan`).
        worst_m: the predicted error at the points of interest at the confidence, metres
            (NaN: no prediction).
        cycle_s: its program's estimated cycle time, s (NaN: not timed).
        rating: the layout's rating (``"ok"``, ``"weak"``, ``"unobservable"``, ``""``: none).
        problems: what ``wobjcal check`` refuses in it, one line each (``()``: passes).
        meets_target: the error holds the target (always True without one).
        plan: the plan written for the row (with its vias).
        quality: its predicted quality, or None.
        check: its check.
        pareto: usable, and no other usable row is at least as good in both error and time
            and better in one.
        written: the plan ``wobjcal suggest`` wrote.
    """

    points: int
    order: Order
    worst_m: float
    cycle_s: float
    rating: str
    problems: tuple[str, ...]
    meets_target: bool
    plan: Plan = field(repr=False, compare=False)
    quality: LayoutQuality | None = field(repr=False, compare=False)
    check: PlanCheck = field(repr=False, compare=False)
    pareto: bool = False
    written: bool = False
    searches: Searches = "whole"

    @property
    def usable(self) -> bool:
        """Check passes, the layout is not weak and it was timed and predicted."""
        return (
            not self.problems
            and self.rating == "ok"
            and math.isfinite(self.cycle_s)
            and math.isfinite(self.worst_m)
        )

    def to_json(self) -> dict[str, object]:
        """The row for JSON and CSV (mm, s)."""
        return {
            "points": self.points,
            "order": self.order,
            "searches": self.searches,
            "error_mm": round(self.worst_m * 1e3, 6) if math.isfinite(self.worst_m) else None,
            "cycle_time_s": round(self.cycle_s, 3) if math.isfinite(self.cycle_s) else None,
            "rating": self.rating,
            "meets_target": self.meets_target,
            "pareto": self.pareto,
            "check": "passes" if not self.problems else "; ".join(self.problems),
        }


def design_front(
    ctx: Context,
    plan: Plan,
    kind: ProcedureKind,
    *,
    max_points: int,
    fmt: str | None,
    at_m: FloatArray | None,
    level_percent: float,
    target_m: float | None,
    say: SuggestProgress,
) -> list[FrontRow]:
    """The front's rows (module docstring), sizes ascending, ``landing`` before ``time`` (a
    ``time`` row only where its order differs), then the steered row (only when the controller
    ``fmt`` steers ``kind`` search by search).

    Args:
        ctx: the suggestion's context (pool, sequencer, cell; its search sizing is reset for
            each design).
        plan: the plan the points are written into (its cell, part and models).
        kind: the procedure of the plans written (its layout design grows).
        max_points: the largest size designed.
        fmt: the controller whose program is checked, predicted and timed.
        at_m: points of interest given on the command line, or None.
        level_percent: the confidence of ``worst_m``.
        target_m: the target, metres (None: every row meets it).
        say: progress.
    """
    designs: list[tuple[int, Design]] = []
    best_fit_design(ctx, None, max_points, 0, None, say, collect=designs)
    limits = cell_motion_limits(ctx.cell, plan, fmt)
    steers = kind.steering is not None and kind.method in controller(fmt).adaptive_methods
    rows: list[FrontRow] = []
    for k, (n, d) in enumerate(designs):
        say("front", k, len(designs))
        landing = _row(ctx, plan, kind, d, n, "landing", fmt, at_m, level_percent, target_m)
        rows.append(landing)
        order = _time_order(ctx, d.chosen, landing.check, limits)
        fast = (landing, d)
        if order is not None and order != tuple(d.chosen):
            timed = dataclasses.replace(d, chosen=order)
            fast = (
                _row(ctx, plan, kind, timed, n, "time", fmt, at_m, level_percent, target_m),
                timed,
            )
            rows.append(fast[0])
        if steers and not ctx.pool.is_edge[list(d.chosen)].any():
            row, design = fast
            steered = _steered_row(ctx, plan, kind, design, n, row.order, fmt, at_m,
                                   level_percent, target_m)  # fmt: skip
            if steered is not None:
                rows.append(steered)
    say("front", len(designs), len(designs))
    return _mark_pareto(rows)


def with_written(rows: Sequence[FrontRow], row: FrontRow) -> list[FrontRow]:
    """``rows`` with ``row`` (or the row of the same plan: same points, in the same order)
    marked as the plan written; ``row`` is added, and the Pareto marks redone, when no row has
    its plan."""
    key = _points_key(row.plan)
    out = [dataclasses.replace(r, written=_points_key(r.plan) == key) for r in rows]
    if not any(r.written for r in out):
        out = _mark_pareto([*out, dataclasses.replace(row, written=True)])
    return out


def _points_key(plan: Plan) -> tuple[tuple[object, ...], ...]:
    return tuple((p.id, p.position_m, p.normal, p.search) for p in plan.points)


def row_of(plan: Plan, check: PlanCheck, quality: LayoutQuality | None, level: float,
           target_m: float | None) -> FrontRow:  # fmt: skip
    """The front's row of a plan already written and checked (its order: ``landing``)."""
    worst = quality.worst_poi_m(level) if quality is not None else math.nan
    return FrontRow(
        points=len(plan.points),
        order="landing",
        searches="steered" if plan.steered_searches else "whole",
        worst_m=worst,
        cycle_s=check.cycle.total_s if check.cycle is not None else math.nan,
        rating=quality.rating if quality is not None else "",
        problems=check.refusals(),
        meets_target=target_m is None or (math.isfinite(worst) and worst <= target_m),
        plan=plan,
        quality=quality,
        check=check,
    )


def checked_quality(
    plan: Plan, check: PlanCheck, mesh: Any, fmt: str | None
) -> tuple[LayoutQuality | None, str]:
    """The predicted quality of ``plan`` for the program ``fmt`` and why there is none: the
    one ``check`` made, or, when check refused the layout (it then predicts nothing), the
    prediction itself (:func:`planner.check.job.plan_quality`, work object ``mesh``, wobj, m)."""
    if check.layout:
        return plan_quality(plan, mesh, fmt)
    return check.quality, check.quality_note


def fastest(rows: Sequence[FrontRow]) -> FrontRow | None:
    """The usable row that meets the target with the least cycle time (ties: the smaller
    error, then fewer points); None when no row does."""
    ok = [r for r in rows if r.usable and r.meets_target]
    return min(ok, key=lambda r: (r.cycle_s, r.worst_m, r.points), default=None)


def _row(
    ctx: Context,
    plan: Plan,
    kind: ProcedureKind,
    d: Design,
    n: int,
    order: Order,
    fmt: str | None,
    at_m: FloatArray | None,
    level: float,
    target_m: float | None,
) -> FrontRow:
    """Write ``d`` as a plan (every search for the whole misplacement), add its vias, check,
    predict and time it."""
    ctx.size_searches(tuple(d.chosen))  # the searches sized about this layout's centroid
    written = suggested_plan(plan, ctx, d, kind, 0, at_m)
    return _judged(ctx, written, n, order, fmt, level, target_m)


def _steered_row(
    ctx: Context,
    plan: Plan,
    kind: ProcedureKind,
    d: Design,
    n: int,
    order: Order,
    fmt: str | None,
    at_m: FloatArray | None,
    level: float,
    target_m: float | None,
) -> FrontRow | None:
    """:func:`_row` with the searches steered (:func:`planner.suggest.search_sizing.
    steered_plan`); None when that shortens no search (the floors already hold every one: the
    same program, which only an adaptive controller would run)."""
    ctx.size_searches(tuple(d.chosen))
    whole = suggested_plan(plan, ctx, d, kind, 0, at_m)
    written = steered_plan(whole)
    if [p.search for p in written.points] == [p.search for p in whole.points]:
        return None
    return _judged(ctx, written, n, order, fmt, level, target_m)


def _judged(
    ctx: Context,
    written: Plan,
    n: int,
    order: Order,
    fmt: str | None,
    level: float,
    target_m: float | None,
) -> FrontRow:
    """The row of ``written`` with its vias added: checked, predicted and timed."""
    written, _ = plan_with_vias(written, ctx.cell)
    check = check_plan(written, cell=ctx.cell, fmt=fmt)
    assert ctx.cell.work_object is not None
    quality, _ = checked_quality(written, check, ctx.cell.work_object.mesh, fmt)
    return dataclasses.replace(
        row_of(written, check, quality, level, target_m), points=n, order=order
    )


def _time_order(
    ctx: Context, chosen: Sequence[int], check: PlanCheck, limits: JointMotionLimits
) -> tuple[int, ...] | None:
    """``chosen`` (candidate indices, in the plan's order) reordered for least joint-move time
    between the checked safe starts, every approach still landing on its face after the ones
    before it (:meth:`~planner.suggest.order.Sequencer.fits`); edge searches last, nearest
    first. None when a point has no checked pose."""
    q = [c.q_safe for c in check.points]
    if len(q) != len(chosen) or any(x is None for x in q):
        return None
    qs = [np.asarray(x, dtype=np.float64) for x in q if x is not None]
    m = len(qs)
    cost = np.zeros((m, m))
    for a in range(m):
        for b in range(m):
            if a != b:
                cost[a, b] = joint_move_time(qs[a], qs[b], limits)
    edge = ctx.pool.is_edge
    appr = [k for k, i in enumerate(chosen) if not edge[i]]
    edges = [k for k, i in enumerate(chosen) if edge[i]]
    layout = list(chosen)
    seq = ctx.sequencer

    def fits(a: int, earlier: frozenset[int]) -> bool:
        if seq is None:
            return True
        return seq.fits(chosen[appr[a]], [chosen[appr[e]] for e in sorted(earlier)], layout)

    landing = tuple(range(len(appr)))  # the design's order is a landing order
    sub = shortest_order(cost[np.ix_(appr, appr)], fits, fallback=landing)
    if sub is None:
        return None
    out = [appr[a] for a in sub]
    left = list(edges)
    while left:  # edge searches after the approaches, nearest first
        here = out[-1] if out else left[0]
        nxt = min(left, key=lambda e: (cost[here, e], e))
        out.append(nxt)
        left.remove(nxt)
    return tuple(chosen[k] for k in out)


def _mark_pareto(rows: list[FrontRow]) -> list[FrontRow]:
    """``rows`` with ``pareto`` set on the non-dominated usable ones."""

    def dominated(r: FrontRow) -> bool:
        return any(
            o is not r
            and o.usable
            and o.worst_m <= r.worst_m
            and o.cycle_s <= r.cycle_s
            and (o.worst_m < r.worst_m or o.cycle_s < r.cycle_s)
            for o in rows
        )

    return [dataclasses.replace(r, pareto=r.usable and not dominated(r)) for r in rows]
