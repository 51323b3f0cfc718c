"""wobjcal suggest on the demo stator cell: the target holds (predicted and simulated), --add,
and the clear refusals."""

from __future__ import annotations

from pathlib import Path

import msgspec
import pytest

from calib.plan.file import Plan, load_plan
from planner.suggest import SuggestError, SuggestResult, suggest_plan

ASSETS = Path(__file__).resolve().parent.parent / "assets" / "plans"


@pytest.fixture(scope="module")
def ah() -> Plan:
    return load_plan(ASSETS / "stator_section_ah.json")


@pytest.fixture(scope="module")
def suggested(ah: Plan) -> SuggestResult:
    return suggest_plan(ah, ASSETS, target_m=0.3e-3, max_points=10)


def test_suggested_plan_meets_its_target_checked_and_simulated(suggested: SuggestResult) -> None:
    from planner.check import check_plan
    from planner.validate import validate_plan

    res = suggested
    assert res.met and res.worst_m <= 0.3e-3
    assert res.quality is not None and res.quality.rating == "ok"
    assert 6 <= len(res.plan.points) <= 10
    check = check_plan(res.plan, ASSETS)
    assert check.feasible, [(p.point_id, p.reason) for p in check.points if not p.feasible]
    report = validate_plan(res.plan, trials=200, seed=3, workers=1, plan_dir=ASSETS)
    for poi in res.quality.poi:
        (row,) = [r for r in report.rows if r.key == poi.key and r.level_percent == 95.5]
        assert row.procedure <= 0.3  # simulated half-width, mm
        assert row.procedure == pytest.approx(row.procedure_predicted, rel=0.25)


def test_add_one_point_lowers_the_error(suggested: SuggestResult) -> None:
    more = suggest_plan(suggested.plan, ASSETS, add=1)
    assert len(more.plan.points) == len(suggested.plan.points) + 1
    assert [p.id for p in more.plan.points[:-1]] == [p.id for p in suggested.plan.points]
    assert more.worst_m < suggested.worst_m


def test_three_two_one_roles(ah: Plan) -> None:
    res = suggest_plan(ah, ASSETS, procedure="three_two_one")
    assert [p.role for p in res.plan.points] == ["primary"] * 3 + ["secondary"] * 2 + ["tertiary"]
    assert res.plan.method == "three_two_one" and res.quality is not None


def test_unreachable_target_says_the_best_reached(ah: Plan) -> None:
    res = suggest_plan(ah, ASSETS, target_m=1e-6, max_points=7)
    assert not res.met
    assert "not reached" in res.message and f"{res.worst_m * 1e3:.3f} mm" in res.message
    assert len(res.plan.points) == 7


def test_part_without_planar_faces_is_refused(ah: Plan, reference_dir: Path) -> None:
    from calib.plan.file import file_sha256

    mesh = reference_dir / "parts" / "noether_raw_mesh.ply"
    wo = msgspec.structs.replace(ah.work_object, mesh=str(mesh), sha256=file_sha256(mesh))
    plan = msgspec.structs.replace(ah, work_object=wo)
    with pytest.raises(SuggestError, match="no planar face"):
        suggest_plan(plan, ASSETS)


def test_cli_writes_the_plan(ah: Plan, tmp_path: Path) -> None:
    from planner.cli.main import main

    out = tmp_path / "s.json"
    code = main(
        ["suggest", str(ASSETS / "stator_section_ah.json"), "--max-points", "6", "-o", str(out)]
    )
    assert code == 0
    plan = load_plan(out)  # references rebased to tmp_path still resolve
    assert len(plan.points) == 6 and plan.method == "best_fit"
    assert main(["suggest", str(out), "--add", "1", "-o", str(tmp_path / "t.json")]) == 0
    assert len(load_plan(tmp_path / "t.json").points) == 7


def test_plate_sides_too_narrow_for_the_misplacement_are_named(reference_dir: Path) -> None:
    """The plate's flat side band (6.35 mm) cannot hold the touch probe's footprint grown by
    the plan's 3 mm misplacement: only the top remains, which cannot fix all six degrees of
    freedom. The refusal names the faces and what stopped them."""
    plan = load_plan(ASSETS / "plate_holes_best_fit.json")
    with pytest.raises(SuggestError) as err:
        suggest_plan(plan, ASSETS, target_m=0.2e-3)
    msg = str(err.value)
    assert "6 degrees of freedom" in msg
    assert "grown by the misplacement's translation, 3.0 mm" in msg
    assert "face 0 (normal +z" in msg and "feasible poses" in msg
    assert "(normal -x" in msg and "footprint over a hole/edge" in msg
