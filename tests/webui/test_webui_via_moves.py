"""The points table judges the moves between the points as ``wobjcal check`` does (helper-56,
D5): with the stator moved 100 mm in x, the table showed D feasible while the Files tab and
``wobjcal check`` refused D for its via move into it; and C's first cause was a joint near its
limit (only marginal) instead of the search path that fails (D6)."""

from __future__ import annotations

import time

import msgspec
import pytest

from calib.plan.file import Plan
from planner.check.job import check_plan
from webui.app import WobjcalApp
from webui.status_table import table_rows


def _moved(plan: Plan, dx_m: float) -> Plan:
    wo = plan.work_object
    pose = wo.T_world_wobj
    x, y, z = pose.position_m
    moved = msgspec.structs.replace(pose, position_m=(x + dx_m, y, z))
    return msgspec.structs.replace(
        plan, work_object=msgspec.structs.replace(wo, T_world_wobj=moved)
    )


def _wait(pred: object, what: str, timeout_s: float = 60.0) -> None:
    t0 = time.monotonic()
    while not pred():  # type: ignore[operator]
        assert time.monotonic() - t0 < timeout_s, f"timed out waiting for {what}"
        time.sleep(0.05)


@pytest.mark.slow
def test_the_table_refuses_a_point_whose_move_in_fails_as_check_does(demo_app: WobjcalApp) -> None:
    app = demo_app
    source = app.state.doc.source
    assert isinstance(source, Plan)
    plan = _moved(source, 0.1)
    app.replace_source(plan, "move the part")
    ids = app.state.doc.ids
    _wait(lambda: set(app.checks()) == set(ids), "every point checked")
    _wait(lambda: app.via_future is not None and app.via_future.done(), "the moves checked")
    _wait(lambda: app.check_of("D") is not None and app.check_of("D").via_cause is not None, "D")
    cli = {c.point_id: c for c in check_plan(plan, app.plan_dir).points}
    shown = app.checks()
    assert {pid: c.status for pid, c in shown.items()} == {p: c.status for p, c in cli.items()}
    d = shown["D"]
    assert d.status == "infeasible" and d.via_reason == cli["D"].via_reason
    assert "guide_tube_1 is too near table" in d.via_reason
    rows = "\n".join(table_rows(app.state.doc, shown, {}, "-")).replace("\\_", "_")  # Markdown
    row_d = next(r for r in rows.splitlines() if "| D |" in r)
    assert "infeasible" in row_d and "move: guide_tube_1 – table" in row_d
    row_c = next(r for r in rows.splitlines() if "| C |" in r)
    assert shown["C"].pose_status != "infeasible" and "collision: feeder_body – table" in row_c
    app.state.undo()
    _wait(lambda: app.check_of("D") is not None and app.check_of("D").via_cause is None, "undo")
    # a finished check of the moves is asked again, never reused (helper-58: a result thrown
    # away for a later edit was never asked for again after an undo back to its plan)
    _wait(lambda: app.via_future is not None and app.via_future.done(), "the moves checked")
    done = app.via_future
    again = app.update_via_moves()
    assert again is not done
    again.result(60)
