"""Pure edits of the UI's plan document."""

from __future__ import annotations

import numpy as np
import pytest

from calib.errors import InputError
from webui.plan_doc import UiPlan, delete_point, edit_search, next_id, place_point


def test_place_new_and_move_existing() -> None:
    plan = place_point(UiPlan(), "A", [0.1, 0.0, 0.0], [0, 0, 2.0])
    assert plan.ids == ("A",)
    assert plan.get("A").probe.normal == (0.0, 0.0, 1.0), "normal is normalised"
    plan = place_point(plan, "B", [0.2, 0.0, 0.0], [0, 0, 1])
    plan = edit_search(
        plan,
        "A",
        kind="edge",
        start_offset_m=0.01,
        overtravel_m=0.02,
        edge_direction=[1, 0, 0.3],
        role="edge",
    )
    moved = place_point(plan, "A", [0.3, 0.0, 0.0], [0, 1, 0])
    a = moved.get("A")
    assert moved.ids == ("A", "B") and a.role == "edge"
    assert a.probe.search.kind == "edge"
    np.testing.assert_allclose(a.probe.search.edge_direction, [1, 0, 0], atol=1e-12)
    assert a.probe.position_m == (0.3, 0.0, 0.0)


def test_next_id_fills_gaps() -> None:
    plan = UiPlan()
    for _ in range(3):
        plan = place_point(plan, next_id(plan), [0, 0, 0], [0, 0, 1])
    assert plan.ids == ("A", "B", "C")
    plan = delete_point(plan, "B")
    assert next_id(plan) == "B"


def test_bad_edits_name_the_problem() -> None:
    plan = place_point(UiPlan(), "A", [0, 0, 0], [0, 0, 1])
    with pytest.raises(InputError, match=r"no point .Z.*A"):
        delete_point(plan, "Z")
    with pytest.raises(InputError, match="along its normal"):
        edit_search(
            plan, "A", kind="edge", start_offset_m=0.01, overtravel_m=0.01, edge_direction=[0, 0, 1]
        )
    with pytest.raises(InputError, match="start_offset_m"):
        edit_search(plan, "A", kind="approach", start_offset_m=-1, overtravel_m=0.01)


def test_the_plan_as_edited_carries_every_edited_point_or_is_none() -> None:
    """The UI checks one edited point against the plan as edited now (the safe starts' pivot
    is the centroid of all the points); edits that make no plan fall back to ``None``."""
    from dataclasses import replace as dc_replace

    from calib.plan.file import load_plan
    from planner.demo import DEMO_PLAN
    from webui.plan_adapter import plan_as_edited, ui_plan_from_plan

    ui = ui_plan_from_plan(load_plan(DEMO_PLAN))
    moved = dc_replace(
        ui.points[0], probe=dc_replace(ui.points[0].probe, position_m=(0.01, -0.6, 0.05))
    )
    edited = dc_replace(ui, points=(moved, *ui.points[1:]))
    plan = plan_as_edited(edited)
    assert plan is not None and plan.points[0].position_m == (0.01, -0.6, 0.05)
    assert plan.points[2].via_points == load_plan(DEMO_PLAN).points[2].via_points  # vias kept
    twice = dc_replace(ui, points=(*ui.points, ui.points[0]))  # a duplicate id: no plan
    assert plan_as_edited(twice) is None
    assert plan_as_edited(dc_replace(ui, source=None)) is None
