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

import numpy as np
import pytest

from calib.plan.file import Plan
from planner.export import export_files
from planner.export.job import ToolData, build_job
from planner.plan_cell import nominal_T_base_wobj
from tests.program_cases import PLANS_MADE, load, ninety
from tests.rapid_grammar import rapid_errors

pytest.importorskip("rapidchecker")


def _errors(plan: Plan) -> list[str]:
    job = build_job(plan, nominal_T_base_wobj(plan), ToolData(T_flange_tcp=np.eye(4)))
    return rapid_errors(export_files(job, "rapid")[".mod"])


@pytest.mark.slow
@pytest.mark.parametrize("case", list(PLANS_MADE))
def test_the_module_passes_rapidchecker(case: str) -> None:
    assert _errors(PLANS_MADE[case]()) == [], case


@pytest.mark.slow
def test_a_module_of_90_points_passes_rapidchecker() -> None:
    """2,950 lines: the tool takes about 45 s over it."""
    assert _errors(ninety()) == []


@pytest.mark.slow
def test_the_checker_sees_a_declaration_after_a_routine() -> None:
    """The layout error the tool found, put back by hand: it is reported."""
    plan = load("plate_holes_321.json")
    job = build_job(plan, nominal_T_base_wobj(plan), ToolData(T_flange_tcp=np.eye(4)))
    text = export_files(job, "rapid")[".mod"]
    bad = text.replace("ENDMODULE", "    CONST num nLate:=1;\nENDMODULE")
    assert any("found 'CONST'" in e for e in rapid_errors(bad))
    broken = text.replace("nH{(r+1)*(c-1)+c}", "nH{(r+1)*(c-1)+}", 1)  # an index that is not
    assert any(e.startswith("index") for e in rapid_errors(broken))
