"""The joint moves between points are checked, and vias that clear them can be searched
(:mod:`planner.cell.moves.via_search`, :mod:`planner.check.vias`, ``wobjcal check --add-vias``)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import msgspec
import numpy as np
import pytest

from calib.plan.file import Plan, load_plan
from calib.plan.vias import ViaPoint
from planner.cell.moves.joint_moves import check_via_path
from planner.cell.moves.via_search import suggest_vias
from planner.check.job import check_plan
from planner.check.vias import plan_with_vias
from planner.cli.main import main
from planner.plan_cell import open_cell

PLANS = Path(__file__).resolve().parents[3] / "assets" / "plans"
DEMO = PLANS / "stator_section_ah.json"


def _bare(plan: Plan) -> Plan:
    points = [msgspec.structs.replace(p, vias=msgspec.UNSET) for p in plan.points]
    return msgspec.structs.replace(plan, points=points)


@pytest.fixture(scope="module")
def bare() -> Plan:
    """The demo without the vias it ships with."""
    return _bare(load_plan(DEMO))


@pytest.fixture(scope="module")
def cell(bare: Plan) -> Iterator[object]:
    with open_cell(bare, PLANS) as c:
        yield c


@pytest.mark.slow
def test_a_colliding_move_between_points_makes_the_point_infeasible(bare: Plan, cell) -> None:  # type: ignore[no-untyped-def]
    """Without vias the demo's program would drag the guide tube through the table on its way
    from C to D: the check says so at D (and at C, reached from B too near the table)."""
    check = check_plan(bare, PLANS, cell=cell)
    bad = {c.point_id: c for c in check.points if not c.feasible}
    assert set(bad) == {"C", "D"}
    assert bad["D"].via_reason.startswith("move C -> D at ")
    assert "hits table" in bad["D"].via_reason
    assert "wobjcal check --add-vias" in bad["D"].reason
    assert bad["D"].to_json()["vias"] == {"count": 0, "reason": bad["D"].via_reason}
    shipped = check_plan(load_plan(DEMO), PLANS, cell=cell)
    assert shipped.feasible  # the shipped plan carries the vias


@pytest.mark.slow
def test_the_via_search_clears_the_moves_from_every_predecessor(bare: Plan, cell) -> None:  # type: ignore[no-untyped-def]
    check = {c.point_id: c for c in check_plan(bare, PLANS, cell=cell).points}
    tcp = bare.cell.tool.tcp
    froms = [check["B"].q_safe, check["H"].q_safe]  # C comes after B, and after H (retake)
    vias = suggest_vias(cell, froms, check["C"].q_safe, tcp)
    assert vias, "no via found for C"
    for q in froms:
        assert check_via_path(cell, q, vias, check["C"].q_safe, tcp).problem == ""
    assert suggest_vias(cell, [check["A"].q_safe], check["B"].q_safe, tcp) == []  # clear


@pytest.mark.slow
def test_add_vias_writes_a_plan_that_passes_and_keeps_taught_vias(
    bare: Plan,
    cell,  # type: ignore[no-untyped-def]
    tmp_path: Path,
) -> None:
    new, done = plan_with_vias(bare, cell)
    assert set(done) == {"C", "D"} and all("added" in v for v in done.values())
    assert check_plan(new, PLANS, cell=cell).feasible
    assert all(not p.via_points for p in new.points if p.id not in done)
    # a taught (bad) via is left alone and named
    q = np.asarray(check_plan(bare, PLANS, cell=cell).points[3].q_safe)
    taught = list(bare.points)
    taught[3] = taught[3].with_vias([ViaPoint(q_rad=[float(v) for v in q])])
    again, said = plan_with_vias(msgspec.structs.replace(bare, points=taught), cell)
    assert again.points[3].via_points == taught[3].via_points
    assert said["D"].startswith("has taught vias")  # the move C -> D still collides
    # the command line: writes the plan (relative references kept) and checks it
    out = tmp_path / "with_vias.json"
    src = tmp_path / "bare.json"
    from calib.plan.file import plan_to_json
    from planner.suggest import moved_plan

    src.write_text(plan_to_json(moved_plan(bare, PLANS, tmp_path)))
    assert main(["check", str(src)]) == 1
    assert main(["check", str(src), "--add-vias", str(out)]) == 0
    assert load_plan(out).points[2].via_points
