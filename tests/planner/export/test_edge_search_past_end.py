"""An edge search whose measured face point lies past where the plan's search ends fails, in
the executor and in the exported programs, instead of running backwards.

The executor (``planner.program.execute``) counts an edge search with no run left (the face
point at or past the end of the search) as no detection; KRL's program does too (``fDot<=0``),
and so now do RAPID's and URScript's. On a real part it cannot happen: the face approach runs
along the estimate's normal, so its point lies on the commanded line and the edge run from it
is the nominal length, whatever the misplacement (the KRL and URScript interpreters refuse an
answer off the commanded line, rightly). It is a guard against a sensor answering elsewhere;
here the part answers F's face approach 300 mm along F's edge search (past its end), which the
RAPID interpreter (no line check) accepts: F is failed, the procedure stops, and F's edge
search never runs.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import msgspec
import numpy as np
import pytest

from calib.plan.file import Plan, load_plan
from calib.probing import ProbeResult, SearchCommand
from planner.export import export_files
from planner.export.job import ToolData, build_job
from planner.plan_cell import nominal_T_base_wobj
from planner.program import execute, measuring_program
from tests.planner.export.test_export_rapid_adaptive import full_misplacement
from tests.planner.export.test_krl_program_runs import PlaneWorld
from tests.rapid_interp import Machine

PLANS = Path(__file__).resolve().parents[3] / "assets" / "plans"
PAST_M = 0.3


def _plan() -> Plan:
    plan = load_plan(PLANS / "stator_section_ah.json")
    proc = msgspec.structs.replace(plan.procedure, edge_start_from_measured=False, xoffset=None)
    return msgspec.structs.replace(plan, procedure=proc)


class _Part:
    """An ideal misplaced stator box (``PlaneWorld``) whose answer to F's face approach lies
    :data:`PAST_M` beyond the end of F's edge search, along its direction (base frame)."""

    def __init__(self, plan: Plan, T_nom: np.ndarray, T_true: np.ndarray) -> None:
        self.world = PlaneWorld(plan, T_true)
        f = next(p for p in plan.points if p.role == "F")
        assert f.search.edge_direction is not None
        self.shift = PAST_M * (T_nom[:3, :3] @ np.asarray(f.search.edge_direction, dtype=float))
        self.calls: list[bool] = []  # neg_flank of every search run, in order
        self.face_call = 5  # A B C D E, then F's face approach

    def __call__(self, start: Any, end: Any, axis: Any, neg_flank: bool) -> Any:
        self.calls.append(bool(neg_flank))
        hit = self.world(start, end, axis, neg_flank)
        if len(self.calls) - 1 == self.face_call and not isinstance(hit, str):
            return np.asarray(hit, dtype=float) + self.shift
        return hit


def _setup(seed: int) -> tuple[Plan, np.ndarray, np.ndarray]:
    plan = _plan()
    T_nom = nominal_T_base_wobj(plan)
    T_true = T_nom @ full_misplacement(plan, np.random.default_rng(seed))
    return plan, T_nom, T_true


def test_the_executor_fails_the_edge_search() -> None:
    plan, T_nom, T_true = _setup(1)
    prog = measuring_program(plan, "rapid")
    world = PlaneWorld(plan, T_true)
    f = next(p for p in plan.points if p.role == "F")
    assert f.search.edge_direction is not None
    shift = PAST_M * (T_nom[:3, :3] @ np.asarray(f.search.edge_direction, dtype=float))
    keys: list[str] = []

    def probe(cmd: SearchCommand) -> ProbeResult:
        keys.append(cmd.point_id)
        end = cmd.start_m + cmd.length_m * cmd.direction
        hit = world(cmd.start_m, end, cmd.sensor_axis, cmd.kind == "edge")
        if isinstance(hit, str):
            return ProbeResult(None, reason="no detection")
        q = np.asarray(hit, dtype=float)
        if cmd.point_id == "F@face":
            q = q + shift
        return ProbeResult(q, travel_m=float((q - cmd.start_m) @ cmd.direction))

    with pytest.raises(Exception, match="F"):
        execute(prog, T_nom, probe)
    assert keys[-1] == "F@face"  # F's edge search never ran


@pytest.mark.parametrize("fmt", ["rapid"])
def test_every_program_fails_it_and_stops(fmt: str) -> None:
    plan, T_nom, T_true = _setup(1)
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    assert job.program(fmt).adaptive
    files = export_files(job, fmt)
    part = _Part(plan, T_nom, T_true)
    if fmt == "rapid":
        m = Machine(files[".mod"], part)
        m.main()
        slot = next(i for i, t in enumerate(job.targets) if t.role == "F")
        assert m.globals["measuredOk"][slot] is False
        assert "edge not found" in m.globals["measuredErr"][slot]
        assert any("stopped" in line for line in m.tp), m.tp
    # F's face approach ran, its edge search (the input falling) never did
    assert part.calls[: part.face_call + 1] == [False] * (part.face_call + 1)
    assert True not in part.calls
