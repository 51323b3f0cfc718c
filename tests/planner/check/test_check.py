"""Tests of planner.check.job: the procedure's preconditions, and the facts the check shows."""

from __future__ import annotations

import json
from pathlib import Path

import msgspec
import numpy as np
import pytest

from calib.plan.file import load_plan
from planner.check.job import check_plan, layout_problem
from planner.cli.main import main

REPO = Path(__file__).resolve().parents[3]
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"
SMALL = REPO / "tests" / "data" / "plans" / "valid_three_two_one.json"


def _moved(plan, point_id: str, position):  # type: ignore[no-untyped-def]
    points = [
        msgspec.structs.replace(p, position_m=tuple(position)) if p.id == point_id else p
        for p in plan.points
    ]
    return msgspec.structs.replace(plan, points=points)


def test_shipped_plans_pass_the_layout_dry_run() -> None:
    assert layout_problem(load_plan(STATOR)) == ""
    assert layout_problem(load_plan(SMALL)) == ""


def test_a_plan_without_points_fails() -> None:
    """Item 8: a plan with no points passed `check`."""
    plan = msgspec.structs.replace(load_plan(SMALL), points=[])
    assert layout_problem(plan) == "the plan has no points: nothing to measure"


def test_a_missing_role_fails() -> None:
    plan = load_plan(STATOR)
    plan = msgspec.structs.replace(plan, points=[p for p in plan.points if p.id != "E"])
    assert "wrong count of ['E']" in layout_problem(plan)


def test_a_layout_calibrate_would_refuse_fails_at_check() -> None:
    """Item 3: `check` passed layouts that `calibrate` refused after the robot had measured.
    Here the two secondary points of a 3-2-1 lie on a line along the primary normal."""
    plan = load_plan(SMALL)
    s1 = next(p for p in plan.points if p.id == "S1")
    bad = _moved(plan, "S2", (s1.position_m[0] - 0.05, *s1.position_m[1:]))
    problem = layout_problem(bad)
    assert problem.startswith("three_two_one: ") and "rotation about the primary normal" in problem


def test_an_a_h_layout_off_its_assumptions_is_named() -> None:
    """A 1 mm step between A and B (the A-H procedure takes B - A along +y) is refused by the
    layout check, with the numbers; 0.2 mm passes."""
    plan = load_plan(STATOR)
    a = next(p for p in plan.points if p.id == "A").position_m
    assert "A and B share z" in layout_problem(_moved(plan, "A", (a[0], a[1], a[2] + 1e-3)))
    assert layout_problem(_moved(plan, "A", (a[0], a[1], a[2] + 2e-4))) == ""


def test_an_a_h_point_named_after_another_role_is_named_once() -> None:
    """A and B's ids swapped against their roles: the procedure's own message, under its name
    once (the procedure's errors carry the name already)."""
    plan = load_plan(STATOR)
    ids = {"A": "B", "B": "A"}
    swapped = [msgspec.structs.replace(p, id=ids.get(p.id, p.id)) for p in plan.points]
    problem = layout_problem(msgspec.structs.replace(plan, points=swapped))
    assert problem.startswith("hultman2013: point 'B' (role A): its id is what"), problem
    assert problem.count("hultman2013") == 1, problem


@pytest.mark.slow
def test_check_reports_the_layout_problem_and_fails(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    plan = load_plan(SMALL)
    s1 = next(p for p in plan.points if p.id == "S1")
    bad = _moved(plan, "S2", (s1.position_m[0] - 0.05, *s1.position_m[1:]))
    result = check_plan(bad, SMALL.parent)
    assert result.layout and not result.feasible
    assert json.loads(json.dumps(result.to_json()))["layout"] == result.layout


# ---- facts shown (item 10): IK kind and clearance pair, in the table and the JSON -----------
@pytest.mark.slow
def test_ik_kind_and_clearance_pair_are_shown(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", str(STATOR), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["ik_kind"] == "opw" and all(p["ik_kind"] == "opw" for p in data["points"])
    pairs = [p["clearance_pair"] for p in data["points"] if p["clearance_pair"]]
    assert pairs and all(len(pair) == 2 for pair in pairs)
    assert main(["check", str(STATOR)]) == 0
    table = capsys.readouterr().out
    assert "IK: opw" in table
    a, b = pairs[0]
    assert f"({a} - {b})" in table


@pytest.mark.slow
def test_numeric_ik_is_named_with_why(reference_dir: Path, tmp_path: Path) -> None:
    """A vendor UR5 (offset wrist) runs on the numeric IK, and the check says so and why."""
    plan = load_plan(SMALL)
    robot = msgspec.structs.replace(
        plan.cell.robot, urdf=str(reference_dir / "robots" / "ur5" / "ur5.urdf")
    )
    plan = msgspec.structs.replace(plan, cell=msgspec.structs.replace(plan.cell, robot=robot))
    result = check_plan(plan, SMALL.parent)
    assert result.ik_kind == "numeric" and result.ik_note
    assert result.to_json()["ik_note"] == result.ik_note
    assert all(p.ik_kind == "numeric" for p in result.points)
    assert np.isfinite([p.clearance_m for p in result.points if p.q is not None]).all()


@pytest.mark.slow
def test_a_part_in_the_wrong_units_is_named_with_its_size(reference_dir: Path) -> None:
    """Item 4: the plate in mm loaded as metres put points metres off, with no word of size or
    units; now every reason about the part says how big it came out and in which units."""
    plan = load_plan(SMALL)
    wo = msgspec.structs.replace(
        plan.work_object, mesh=str(reference_dir / "parts" / "plate_holes.STL"), units="m"
    )
    result = check_plan(msgspec.structs.replace(plan, work_object=wo), SMALL.parent)
    about_part = [p.reason for p in result.points if "work object plate_holes" in p.reason]
    assert about_part, [p.reason for p in result.points]
    assert all("203 x 305 x 12.7 m (file units 'm', given)" in r for r in about_part)
    # the note goes where the reason says it measures the part, or its pair names the part
    # (issue 23, item 3), and --json's reasons say the same words with their kinds
    noted = [c for p in result.points for c in p.causes if c.note]
    assert noted and all(c.about_part or "plate_holes" in (c.pair or ()) for c in noted)
    assert {c.kind for c in noted} <= {"reach", "collision", "footprint"}
    for p in result.points:
        out = p.to_json()
        assert "; ".join(r["text"] for r in out["reasons"]) == out["reason"]


@pytest.mark.parametrize(
    ("from_measured", "start_offset", "event_offset"),
    [(True, 0.004, None), (True, 0.004, 0.002), (False, 0.0, 0.003)],
)
def test_the_dry_run_measures_edges_as_the_robot_does(
    from_measured: bool, start_offset: float, event_offset: float | None
) -> None:
    """An edge search started off the face (``edge_start_offset_m``) switches off the face, and
    a sensor that reports edges late (``edge_event_offset_m``) reports them late; the procedure
    removes both, so the dry run gives back the nominal frame. (It used to feed the nominal
    points unchanged, and refused these plans: "moves point C by 15.2 mm".)"""
    plan = load_plan(STATOR)
    proc = msgspec.structs.replace(
        plan.procedure,
        edge_start_from_measured=from_measured,
        edge_start_offset_m=start_offset,
        edge_event_offset_m=event_offset,
    )
    assert layout_problem(msgspec.structs.replace(plan, procedure=proc)) == ""
