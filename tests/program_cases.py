"""Plans whose exported programs the grammar tests check
(:mod:`tests.planner.export.test_rapid_grammar`,
:mod:`tests.planner.export.test_krl_grammar`): the shipped plans and variants of them that reach
every
procedure the exporters write, vias, the fewest points a frame takes, one point, 90 points, and
hostile point ids and plan name.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import msgspec
import numpy as np

from calib.plan.file import Plan, PlanPoint, load_plan
from calib.procedures import BestFit, Iterative

PLANS = Path(__file__).resolve().parents[1] / "assets" / "plans"


def load(name: str) -> Plan:
    """The shipped plan ``assets/plans/<name>``, its mesh not read: the programs are written
    from the plan alone (the plate plans' mesh is in ``../shared/reference``,
    :mod:`tests.reference_data`)."""
    return load_plan(PLANS / name, check_files=False)


def _stator(**settings: object) -> Plan:
    plan = load("stator_section_ah.json")
    return msgspec.structs.replace(
        plan, procedure=msgspec.structs.replace(plan.procedure, **settings)
    )


def _fit(plan: Plan, points: list[PlanPoint]) -> Plan:
    return msgspec.structs.replace(plan, points=points, procedure=BestFit())


def ninety() -> Plan:
    """The plate best fit with 80 more points on its top: 90 points."""
    plan = load("plate_holes_best_fit.json")
    top = next(p for p in plan.points if p.id == "T1")
    xs, ys = np.linspace(0.02, 0.17, 8), np.linspace(0.03, 0.27, 10)
    more = [
        msgspec.structs.replace(top, id=f"G{k}", position_m=(float(x), float(y), 0.0127))
        for k, (x, y) in enumerate((x, y) for x in xs for y in ys)
    ]
    return _fit(plan, [*plan.points, *more])


def one_point() -> Plan:
    """The plate's nominal iterative best fit of its one point T1: the fewest points any
    exporter takes (a best fit needs 3, a 3-2-1 its 6; the iterative procedure, run on the
    nominal frame, takes 1)."""
    plan = load("plate_holes_best_fit.json")
    return msgspec.structs.replace(
        plan, points=[p for p in plan.points if p.id == "T1"], procedure=Iterative()
    )


def _with_edge() -> Plan:
    """The plate best fit plus the stator's edge point F: RAPID runs it nominal."""
    plan = load("plate_holes_best_fit.json")
    f = next(p for p in load("stator_section_ah.json").points if p.role == "F")
    return _fit(plan, [*plan.points, msgspec.structs.replace(f, id="E9", role="fit")])


def _hostile() -> Plan:
    plan = load("plate_holes_321.json")
    ids = ["P1", "p1.x", "P-2", "S_1", "s.2", "T1"]
    points = [msgspec.structs.replace(p, id=i) for p, i in zip(plan.points, ids, strict=True)]
    return msgspec.structs.replace(plan, points=points, name="plate (v2): A/B + C, 1.5 -- x")


def _fewest() -> Plan:
    """A best fit of the fewest points that fix a frame (six)."""
    plan = load("plate_holes_best_fit.json")
    keep = ["T1", "T2", "T3", "X1", "X2", "Y1"]
    return _fit(plan, [p for p in plan.points if p.id in keep])


#: Every procedure the exporters write, from the shipped plans (90 points: :func:`ninety`;
#: one point: :func:`one_point`).
PLANS_MADE: dict[str, Callable[[], Plan]] = {
    "stator A-H (shipped)": lambda: load("stator_section_ah.json"),
    "stator A-H, edges from the face approach": lambda: _stator(edge_start_from_measured=False),
    "plate 3-2-1 (shipped)": lambda: load("plate_holes_321.json"),
    "plate best fit with vias (shipped)": lambda: load("plate_holes_best_fit.json"),
    "plate iterative (nominal)": lambda: msgspec.structs.replace(
        load("plate_holes_best_fit.json"), procedure=Iterative()
    ),
    "best fit with an edge search (nominal)": _with_edge,
    "best fit of six points": _fewest,
    "hostile ids and name": _hostile,
}
