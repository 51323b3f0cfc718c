"""One verdict: check, validate and export agree on which plans can run, for the shipped plans
and mutated ones (short searches, starts inside the misplacement, points off their faces or
over an edge, colliding vias, a misplacement bound that lands searches off narrow faces, a
layout that fixes too little), and validate names every problem check names.

``validate`` checks the plan as ``check --format`` does before simulating it and refuses what
check refuses (``check="refuse"``, the CLI's default; ``--force`` simulates anyway and the
report names the problems); its vetting of the displaced searches uses the sensor rotation
and IK branch check chose for each point (what every exported program's targets carry), so at
the nominal part pose it passes exactly the searches check passes.
"""

from __future__ import annotations

import copy
import dataclasses
import json
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from calib.errors import WobjcalError
from calib.plan.file import Plan, plan_from_json
from calib.probing import SearchCommand
from planner.check.job import check_plan
from planner.cli import main
from planner.errors import PlanRefused
from planner.export_plan.job import export_program
from planner.plan_cell import nominal_T_base_wobj, open_cell
from planner.program import measuring_program
from planner.program.model import search_keys
from planner.reasons import Reason
from planner.sim.search_events import ProgramPose, program_search_hook
from planner.validate.job import validate_plan

#: every test here runs a shipped plate plan, whose mesh is in ../shared/reference
pytestmark = pytest.mark.reference

PLANS = Path(__file__).resolve().parents[1] / "assets" / "plans"
BASES = ("plate_holes_best_fit.json", "plate_holes_321.json", "stator_section_ah.json")

Mutation = Callable[[dict[str, Any]], None]


def _point(raw: dict[str, Any], pid: str) -> dict[str, Any]:
    return next(p for p in raw["points"] if p["id"] == pid)


def _set(pid: str, *path: str, value: Any) -> Mutation:
    def mutate(raw: dict[str, Any]) -> None:
        node = _point(raw, pid)
        for key in path[:-1]:
            node = node[key]
        node[path[-1]] = value

    return mutate


def _moved(pid: str, delta: tuple[float, float, float]) -> Mutation:
    def mutate(raw: dict[str, Any]) -> None:
        p = _point(raw, pid)
        p["position_m"] = [a + b for a, b in zip(p["position_m"], delta, strict=True)]

    return mutate


def _flipped(pid: str) -> Mutation:
    return lambda raw: _point(raw, pid).update(normal=[-v for v in _point(raw, pid)["normal"]])


def _bound(translation_m: float, angle_deg: float) -> Mutation:
    def mutate(raw: dict[str, Any]) -> None:
        raw["validation"]["misplacement"] = {
            "max_translation_m": translation_m,
            "max_angle_rad": float(np.radians(angle_deg)),
        }

    return mutate


def _via(pid: str, q_rad: list[float]) -> Mutation:
    return lambda raw: _point(raw, pid).update(vias=[{"q_rad": q_rad, "tcp_wobj": None}])


def _only(*ids: str) -> Mutation:
    return lambda raw: raw.update(points=[p for p in raw["points"] if p["id"] in ids])


#: ``(base plan, format, what is changed, the change)``: more than 20 mutated plans, feasible
#: and infeasible ones, for the adaptive (RAPID) and the nominal (FANUC) programs.
MUTATIONS: list[tuple[str, str, str, Mutation | None]] = [
    *((base, fmt, "as shipped", None) for base in BASES for fmt in ("rapid", "fanuc")),
    (
        "plate_holes_best_fit.json",
        "rapid",
        "T1 overtravel 0.5 mm",
        _set("T1", "search", "overtravel_m", value=0.0005),
    ),
    (
        "plate_holes_best_fit.json",
        "rapid",
        "T2 start 0.5 mm out",
        _set("T2", "search", "start_offset_m", value=0.0005),
    ),
    (
        "plate_holes_best_fit.json",
        "rapid",
        "T4 3 mm from the edge",
        _moved("T4", (0.0, -0.057, 0.0)),
    ),
    ("plate_holes_best_fit.json", "rapid", "T3 off the part", _moved("T3", (0.3, 0.0, 0.0))),
    ("plate_holes_best_fit.json", "rapid", "T3 normal flipped", _flipped("T3")),
    (
        "plate_holes_best_fit.json",
        "rapid",
        "X2 via into the table",
        _via("X2", [0.0, 1.4, 1.2, 0.0, 0.5, 0.0]),
    ),
    ("plate_holes_best_fit.json", "rapid", "bound 20 mm / 3 deg", _bound(0.02, 3.0)),
    ("plate_holes_best_fit.json", "rapid", "bound 1 mm / 0.2 deg", _bound(0.001, 0.2)),
    (
        "plate_holes_best_fit.json",
        "rapid",
        "speed 5 mm/s",
        _set("T1", "search", "speed_m_s", value=0.005),
    ),
    ("plate_holes_best_fit.json", "rapid", "three points only", _only("T1", "T2", "T3")),
    ("plate_holes_best_fit.json", "fanuc", "bound 1 mm / 0.2 deg", _bound(0.001, 0.2)),
    (
        "plate_holes_321.json",
        "rapid",
        "S1 overtravel 0.5 mm",
        _set("S1", "search", "overtravel_m", value=0.0005),
    ),
    (
        "plate_holes_321.json",
        "rapid",
        "P1 start 50 mm out",
        _set("P1", "search", "start_offset_m", value=0.05),
    ),
    ("plate_holes_321.json", "rapid", "bound 10 mm / 2 deg", _bound(0.01, 2.0)),
    ("plate_holes_321.json", "fanuc", "bound 0.5 mm / 0.1 deg", _bound(0.0005, 0.1)),
    (
        "plate_holes_321.json",
        "rapid",
        "S2 via into the table",
        _via("S2", [0.0, 1.4, 1.2, 0.0, 0.5, 0.0]),
    ),
    (
        "stator_section_ah.json",
        "rapid",
        "D overtravel 1 mm",
        _set("D", "search", "overtravel_m", value=0.001),
    ),
    ("stator_section_ah.json", "rapid", "bound 5 mm / 1 deg", _bound(0.005, 1.0)),
    ("stator_section_ah.json", "rapid", "A normal flipped", _flipped("A")),
    (
        "stator_section_ah.json",
        "rapid",
        "G start 2 mm out",
        _set("G", "search", "start_offset_m", value=0.002),
    ),
]


def _plan(base: str, mutate: Mutation | None) -> Plan:
    raw = json.loads((PLANS / base).read_text())
    if mutate is not None:
        raw = copy.deepcopy(raw)
        mutate(raw)
    return plan_from_json(json.dumps(raw), f"{base} (mutated)")


@pytest.fixture(scope="module")
def cells() -> Iterator[dict[str, Any]]:
    """One open cell per shipped plan (the mutations keep robot, tool, part and fixtures)."""
    from contextlib import ExitStack

    with ExitStack() as stack:
        yield {b: stack.enter_context(open_cell(_plan(b, None), PLANS)) for b in BASES}


def _verdicts(plan: Plan, fmt: str, cell: Any) -> tuple[tuple[bool, bool, bool], str]:
    """``(check passes, validate runs, export writes)`` and the validate refusal's text."""
    checked = check_plan(plan, cell=cell, fmt=fmt)
    why = ""
    try:
        validate_plan(
            plan, trials=2, seed=1, workers=1, plan_dir=PLANS, fmt=fmt, check="refuse", cell=cell
        )
        validated = True
    except PlanRefused as exc:
        validated, why = False, str(exc)
        assert exc.problems == checked.problems()  # every problem check names, at once
    except WobjcalError as exc:  # refused before the check (roles, free degrees of freedom)
        validated, why = False, str(exc)
    try:
        res = export_program(plan, PLANS, fmt, cell=cell)
        exported = not res.layout and res.check is not None and res.check.feasible
    except WobjcalError:
        exported = False
    return (checked.feasible, validated, exported), why


@pytest.mark.slow
def test_check_validate_and_export_give_one_verdict(cells: dict[str, Any]) -> None:
    assert len([m for m in MUTATIONS if m[3] is not None]) >= 20
    seen = {True: 0, False: 0}
    disagree = []
    for base, fmt, what, mutate in MUTATIONS:
        plan = _plan(base, mutate)
        (c, v, e), why = _verdicts(plan, fmt, cells[base])
        seen[c] += 1
        if not c == v == e:
            disagree.append(f"{base} {fmt} {what}: check {c}, validate {v} ({why}), export {e}")
    assert disagree == []
    assert seen[True] >= 6 and seen[False] >= 10, seen  # both verdicts well represented


@pytest.mark.slow
def test_validate_refuses_what_check_refuses_naming_every_problem(tmp_path: Path) -> None:
    """The plate's 3-2-1 as the nominal FANUC program lands S1, S2 and T1 off the 12.7 mm side
    faces (check refuses it): validate exits 1 naming all three, writes nothing; with --force
    it simulates and the report says check refuses the plan, and why."""
    out = tmp_path / "report.json"
    argv = ["validate", str(PLANS / "plate_holes_321.json"), "--format", "fanuc"]
    argv += ["--trials", "4", "--seed", "1", "--reach-trials", "0", "--json", str(out)]
    assert main(argv) == 1
    assert not out.exists()
    assert main([*argv, "--force"]) in (0, 1)
    data = json.loads(out.read_text())
    problems = data["check_problems"]
    assert [p.split(":")[0] for p in problems] == ["point S1", "point S2", "point T1"]
    assert all("lands off its face" in p for p in problems)
    assert data["program"]["name"].startswith("TP, nominal 3-2-1")
    # --no-check: no verdict at all (a study of a plan known to fail)
    assert main([*argv, "--no-check"]) in (0, 1)
    assert json.loads(out.read_text())["check_problems"] == []


@pytest.mark.slow
@pytest.mark.parametrize("base", ["plate_holes_best_fit.json", "stator_section_ah.json"])
def test_the_vetting_passes_at_the_nominal_pose_what_check_passes(
    base: str, cells: dict[str, Any]
) -> None:
    """Every search of the program, commanded in the nominal frame, vetted by validate's hook
    (the checked pose's sensor rotation and IK branch): it passes where check's walk of the
    point passes; a hook free to choose any rotation and branch would not be the program."""
    plan = _plan(base, None)
    cell = cells[base]
    checked = check_plan(plan, cell=cell)
    T_nom = nominal_T_base_wobj(plan)
    program = measuring_program(plan, None)
    poses = {
        c.point_id: ProgramPose(np.asarray(c.T_base_tcp)[:3, 0], c.branch, np.asarray(c.q))
        for c in checked.points
        if c.T_base_tcp is not None and c.q is not None
    }
    assert len(poses) == len(plan.points) and all(p.branch >= 0 for p in poses.values())
    keys = search_keys(program.points)
    hook = program_search_hook(cell, poses, keys, T_nom, plan.cell.tool.tcp)
    by_id = {p.id: p for p in plan.points}
    for c in checked.points:
        if not c.path_feasible:
            continue
        cmd = SearchCommand.from_point(by_id[c.point_id].to_probe_point(), T_nom)
        assert hook(cmd) is None, c.point_id


class _Spy:
    """A cell whose ``check_search`` records what it was asked (and answers as the cell)."""

    def __init__(self, cell: Any) -> None:
        self.cell = cell
        self.asked: list[dict[str, Any]] = []

    def check_search(self, command: SearchCommand, **kw: Any) -> Any:
        self.asked.append(kw)
        return self.cell.check_search(command, **kw)


def test_the_vetting_turns_the_sensor_with_the_frame_the_search_is_commanded_in(
    cells: dict[str, Any],
) -> None:
    """A search commanded in an estimate turned 3 deg from the nominal frame is vetted with the
    sensor x axis of the exported target (the checked pose's, written in the work object) as
    the robot runs it in that estimate, and the checked IK branch; a point check found no pose
    for is named, not vetted with a pose no program runs; the x-offset run's searches take D's
    pose (the A-H programs command them with D's orientation)."""
    from calib.frames import make_transform, matrix_from_rotvec
    from planner.export_plan.job import export_job_for

    base = "plate_holes_best_fit.json"
    plan, cell = _plan(base, None), cells[base]
    checked = check_plan(plan, cell=cell)
    job, _ = export_job_for(plan, PLANS, checked)
    T_nom = nominal_T_base_wobj(plan)
    poses = {
        c.point_id: ProgramPose(np.asarray(c.T_base_tcp)[:3, 0], c.branch, np.asarray(c.q))
        for c in checked.points
        if c.T_base_tcp is not None and c.q is not None
    }
    keys = search_keys(measuring_program(plan, None).points)
    spy = _Spy(cell)
    hook = program_search_hook(spy, poses, keys, T_nom, plan.cell.tool.tcp)
    turn = make_transform(matrix_from_rotvec([0.0, 0.0, np.radians(3.0)]), [0.002, -0.001, 0.0])
    T_est = T_nom @ turn
    by_id = {p.id: p for p in plan.points}
    for t in job.targets:
        cmd = SearchCommand.from_point(by_id[t.point_id].to_probe_point(), T_est)
        hook(cmd)
        asked = spy.asked[-1]
        want = T_est[:3, :3] @ np.asarray(t.T_wobj_start)[:3, 0]  # the target's x, in the base
        assert np.abs(asked["sensor_x"] - want).max() < 1e-9, t.point_id
        assert asked["branch"] == poses[t.point_id].branch and asked["max_starts"] == 1
    # no pose: named; another search (x-offset): the given point's pose
    first = plan.points[0].id
    lost = program_search_hook(spy, {}, keys, T_nom, plan.cell.tool.tcp)
    cmd = SearchCommand.from_point(plan.points[0].to_probe_point(), T_nom)
    assert lost(cmd) == Reason(
        "reach", f"unreachable or colliding: check found no pose for point {first}"
    )
    px = program_search_hook(spy, poses, keys, T_nom, plan.cell.tool.tcp, other_searches=first)
    px(dataclasses.replace(cmd, point_id="PX1_1"))
    assert np.abs(spy.asked[-1]["sensor_x"] - poses[first].sensor_x_base).max() < 1e-12
