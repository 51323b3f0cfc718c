"""Tests of planner.plan_cell: frames of the plan, the tool data, the cell built from a plan."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from calib.frames import invert_transform
from calib.plan.file import load_plan
from planner.plan_cell import T_base_world, nominal_T_base_wobj, open_cell, tool_data

REPO = Path(__file__).resolve().parent.parent
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"
DATA = REPO / "tests" / "data" / "plans"


def test_nominal_frames() -> None:
    plan = load_plan(DATA / "valid_three_two_one.json")
    T_wb = plan.cell.robot.T_world_base.matrix()
    np.testing.assert_allclose(T_base_world(plan), invert_transform(T_wb), atol=1e-15)
    np.testing.assert_allclose(
        nominal_T_base_wobj(plan), plan.work_object.T_world_wobj.matrix(), atol=1e-12
    )


def test_tool_data_of_builtin_cable_feeder() -> None:
    plan = load_plan(STATOR)
    tool, note = tool_data(plan, STATOR.parent)
    assert tool.T_flange_tcp.shape == (4, 4)
    assert tool.T_flange_tcp[2, 3] > 0.2  # the sensor TCP sits well in front of the flange
    assert tool.mass_kg == 5.0 and "placeholder" in note
    assert 0.0 < tool.cog_m[2] < tool.T_flange_tcp[2, 3]


def test_open_cell_places_the_work_object_and_table() -> None:
    plan = load_plan(STATOR)
    with open_cell(plan, STATOR.parent) as cell:
        assert set(cell.fixtures) == {"table"}
        assert cell.work_object is not None
