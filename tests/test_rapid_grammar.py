"""Every RAPID module the exporter writes passes ``rapidchecker``, a RAPID grammar not written
here (:mod:`tests.rapid_grammar`): the shipped plans and generated ones, every procedure
(adaptive A-H with and without retakes, edge starts from measured points and the x-offset run;
adaptive 3-2-1 and best fit; the nominal iterative best fit and a best fit with an edge search),
vias, the fewest points a frame takes and 90 points, and hostile point ids and plan name. The
tool takes about 5 s a module (45 s for 90 points: marked ``slow``).

The tool found that the modules declared the frame update's constants after the routines before
them; RAPID's module syntax puts every data declaration before the first routine, and the writer
now does (:func:`planner.export.rapid._data_first`).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import msgspec
import numpy as np
import pytest

from calib.plan.file import Plan, load_plan
from calib.procedures import BestFit, Iterative
from planner.export import export_files
from planner.export.job import ToolData, build_job
from planner.plan_cell import nominal_T_base_wobj
from tests.rapid_grammar import rapid_errors

pytest.importorskip("rapidchecker")

PLANS = Path(__file__).resolve().parents[1] / "assets" / "plans"


def _load(name: str) -> Plan:
    return load_plan(PLANS / name)


def _stator(**settings: object) -> Plan:
    plan = _load("stator_section_ah.json")
    return msgspec.structs.replace(
        plan, procedure=msgspec.structs.replace(plan.procedure, **settings)
    )


def _fit(plan: Plan, points: list) -> Plan:  # type: ignore[type-arg]
    return msgspec.structs.replace(plan, points=points, procedure=BestFit())


def _ninety() -> Plan:
    """The plate best fit with 80 more points on its top: 90 points."""
    plan = _load("plate_holes_best_fit.json")
    top = next(p for p in plan.points if p.id == "T1")
    xs, ys = np.linspace(0.02, 0.17, 8), np.linspace(0.03, 0.27, 10)
    more = [
        msgspec.structs.replace(top, id=f"G{k}", position_m=(float(x), float(y), 0.0127))
        for k, (x, y) in enumerate((x, y) for x in xs for y in ys)
    ]
    return _fit(plan, [*plan.points, *more])


def _with_edge() -> Plan:
    """The plate best fit plus the stator's edge point F: RAPID runs it nominal."""
    plan = _load("plate_holes_best_fit.json")
    f = next(p for p in _load("stator_section_ah.json").points if p.role == "F")
    return _fit(plan, [*plan.points, msgspec.structs.replace(f, id="E9", role="fit")])


def _hostile() -> Plan:
    plan = _load("plate_holes_321.json")
    ids = ["P1", "p1.x", "P-2", "S_1", "s.2", "T1"]
    points = [msgspec.structs.replace(p, id=i) for p, i in zip(plan.points, ids, strict=True)]
    return msgspec.structs.replace(plan, points=points, name="plate (v2): A/B + C, 1.5 -- x")


def _fewest() -> Plan:
    """A best fit of the fewest points that fix a frame (six)."""
    plan = _load("plate_holes_best_fit.json")
    keep = ["T1", "T2", "T3", "X1", "X2", "Y1"]
    return _fit(plan, [p for p in plan.points if p.id in keep])


PLANS_MADE: dict[str, Callable[[], Plan]] = {
    "stator A-H (shipped)": lambda: _load("stator_section_ah.json"),
    "stator A-H, edges from the face approach": lambda: _stator(edge_start_from_measured=False),
    "plate 3-2-1 (shipped)": lambda: _load("plate_holes_321.json"),
    "plate best fit with vias (shipped)": lambda: _load("plate_holes_best_fit.json"),
    "plate iterative (nominal)": lambda: msgspec.structs.replace(
        _load("plate_holes_best_fit.json"), procedure=Iterative()
    ),
    "best fit with an edge search (nominal)": _with_edge,
    "best fit of six points": _fewest,
    "hostile ids and name": _hostile,
}


def _errors(plan: Plan) -> list[str]:
    job = build_job(plan, nominal_T_base_wobj(plan), ToolData(T_flange_tcp=np.eye(4)))
    return rapid_errors(export_files(job, "rapid")[".mod"])


@pytest.mark.parametrize("case", list(PLANS_MADE))
def test_the_module_passes_rapidchecker(case: str) -> None:
    assert _errors(PLANS_MADE[case]()) == [], case


@pytest.mark.slow
def test_a_module_of_90_points_passes_rapidchecker() -> None:
    """2,950 lines: the tool takes about 45 s over it."""
    assert _errors(_ninety()) == []


def test_the_checker_sees_a_declaration_after_a_routine() -> None:
    """The layout error the tool found, put back by hand: it is reported."""
    plan = _load("plate_holes_321.json")
    job = build_job(plan, nominal_T_base_wobj(plan), ToolData(T_flange_tcp=np.eye(4)))
    text = export_files(job, "rapid")[".mod"]
    bad = text.replace("ENDMODULE", "    CONST num nLate:=1;\nENDMODULE")
    assert any("found 'CONST'" in e for e in rapid_errors(bad))
    broken = text.replace("nH{(r+1)*(c-1)+c}", "nH{(r+1)*(c-1)+}", 1)  # an index that is not
    assert any(e.startswith("index") for e in rapid_errors(broken))
