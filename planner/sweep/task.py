"""One placement of a sweep, checked where it runs (a Dask worker or this process).

:func:`check_placement` is what every task of ``wobjcal sweep`` calls: it gets the plan as its
JSON text and its folder (so a task is a few kilobytes and any worker with wobjcal installed and
the plan's files at the same path can run it), parses and checks the plan once per process
(:data:`_PLANS`, keyed by the digest of text and folder), moves the base and the part
(:func:`planner.sweep.space.placed_plan`) and runs the one plan check,
:func:`planner.check.job.check_plan`, which opens its own cell (PyBullet is per process) and closes
it. A placement the check refuses with a :class:`~calib.errors.WobjcalError` (the part out of
the robot's reach, a mesh the moved cell cannot hold) is a row with the error, not a failure of
the sweep.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from pathlib import Path

from calib.errors import WobjcalError
from calib.plan.file import Plan, check_plan_files, plan_from_json
from planner.check.job import check_plan
from planner.check.results import PlanCheck
from planner.sweep.space import Placement, placed_plan

#: Parsed plans of this process, by :func:`plan_key` (a worker parses each plan once).
_PLANS: dict[str, Plan] = {}


@dataclass(frozen=True)
class SweepRow:
    """The check of one placement: a row of ``sweep.csv``.

    Attributes:
        placement: where the base and the part were put (offsets, mm and deg).
        status: ``feasible`` (every point, path and the layout pass), ``infeasible``, or
            ``error`` (the check raised: ``reason`` says why).
        points_feasible: how many of the plan's points are feasible (marginal counts).
        points_total: how many points the plan has.
        layout_status: the layout's ``feasible``/``marginal``/``infeasible``, ``""`` on error.
        accuracy_mm: the worst point-of-interest half width at the plan's top confidence level,
            mm (:func:`worst_half_width_m`); NaN when the quality was not predicted.
        cycle_s: the estimated cycle time of the judged program, s; NaN when none.
        reason: why the placement fails: the plan's error, the first infeasible point
            (``point <id>: <reason>``) or the layout's problem, first found first; ``""`` when
            feasible.
    """

    placement: Placement
    status: str
    points_feasible: int
    points_total: int
    layout_status: str
    accuracy_mm: float
    cycle_s: float
    reason: str


def plan_key(plan_text: str, plan_dir: str) -> str:
    """The cache key of a plan sent to workers: sha256 of its JSON text and its folder."""
    return hashlib.sha256(f"{plan_dir}\0{plan_text}".encode()).hexdigest()


def cached_plan(plan_text: str, plan_dir: str) -> Plan:
    """The plan of ``plan_text`` (its files checked against ``plan_dir``), parsed once per
    process.

    Raises:
        PlanError: the text is not a valid plan, or a file it names is missing or changed.
    """
    key = plan_key(plan_text, plan_dir)
    plan = _PLANS.get(key)
    if plan is None:
        plan = plan_from_json(plan_text, source="plan")
        check_plan_files(plan, plan_dir)
        _PLANS.clear()  # one sweep at a time: keep one plan
        _PLANS[key] = plan
    return plan


def worst_half_width_m(check: PlanCheck) -> float:
    """The worst half width of the points of interest at the highest confidence level the plan
    asks for, m (the whole position error a point may have in that share of calibrations);
    NaN when the quality was not predicted or the plan has no point of interest."""
    q = check.quality
    if q is None or not q.poi:
        return math.nan
    worst = math.nan
    for p in q.poi:
        top = max(range(len(p.levels_percent)), key=lambda i: p.levels_percent[i])
        h = float(p.half_width_m[top])
        worst = h if math.isnan(worst) else max(worst, h)
    return worst


def first_reason(check: PlanCheck) -> str:
    """What fails first: the plan's error, the first infeasible point, the layout (``""``)."""
    problems = check.problems()
    return problems[0] if problems else ""


def check_placement(plan_text: str, plan_dir: str, fmt: str | None, where: Placement) -> SweepRow:
    """Check the plan in one placement (see the module docstring).

    Args:
        plan_text: the plan file's JSON text.
        plan_dir: the folder its relative file references resolve against (on the worker).
        fmt: the controller whose program is judged (``None``: the default).
        where: the placement.

    Raises:
        PlanError: the plan itself is invalid or its files are missing on this machine (every
            placement would fail alike: the sweep stops with this message).
    """
    plan = cached_plan(plan_text, plan_dir)
    n = len(plan.points)
    try:
        check = check_plan(placed_plan(plan, where), Path(plan_dir), fmt=fmt)
    except WobjcalError as exc:
        message = " ".join(str(exc).split()) or type(exc).__name__
        return SweepRow(where, "error", 0, n, "", math.nan, math.nan, f"error: {message}")
    cycle = check.cycle.total_s if check.cycle is not None else math.nan
    return SweepRow(
        where,
        "feasible" if check.feasible else "infeasible",
        sum(p.feasible for p in check.points),
        n,
        check.layout_status,
        worst_half_width_m(check) * 1e3,
        cycle,
        " ".join(first_reason(check).split()),
    )
