"""``work_object.T_wobj_mesh``: a plan re-expressed in a 3-point frame keeps the part and its
points where they are in the world, saves and loads, and every job sees the part in it."""

from __future__ import annotations

from pathlib import Path

import msgspec
import numpy as np
import pytest

from calib.frames import transform_points
from calib.plan.file import PlanError, load_plan, plan_from_json, plan_to_json
from calib.plan.reframe import plan_in_frame
from calib.user_frame import three_point_frame
from planner.plan_cell import plan_work_object

PLANS = Path(__file__).resolve().parents[3] / "assets" / "plans"
PLATE = PLANS / "plate_holes_321.json"


def _frame() -> np.ndarray:
    # origin, +x and xy-plane points on the plate, in the old wobj frame (a turned frame)
    return three_point_frame([0.01, 0.02, 0.0], [0.05, 0.05, 0.0], [-0.01, 0.06, 0.003])


def test_reframed_plan_keeps_part_and_points_in_the_world(reference_dir: Path) -> None:
    plan = load_plan(PLATE)
    new = plan_in_frame(plan, _frame())
    assert new.work_object.mesh_pose is not None
    T_old = plan.work_object.T_world_wobj.matrix()
    T_new = new.work_object.T_world_wobj.matrix()
    for p, q in zip(plan.points, new.points, strict=True):
        np.testing.assert_allclose(
            transform_points(T_new, q.position_m), transform_points(T_old, p.position_m), atol=1e-9
        )
        np.testing.assert_allclose(T_new[:3, :3] @ q.normal, T_old[:3, :3] @ p.normal, atol=1e-9)
    old_mesh = plan_work_object(plan, PLANS).mesh
    new_mesh = plan_work_object(new, PLANS).mesh
    np.testing.assert_allclose(
        transform_points(T_new, new_mesh.vertices),
        transform_points(T_old, old_mesh.vertices),
        atol=1e-9,
    )
    assert not np.allclose(new_mesh.vertices, old_mesh.vertices, atol=1e-3)  # really moved
    back = plan_in_frame(new, np.linalg.inv(_frame()))
    np.testing.assert_allclose(back.work_object.mesh_matrix(), np.eye(4), atol=1e-12)


def test_plan_file_round_trip_with_the_field(tmp_path: Path) -> None:
    plan = load_plan(PLATE, check_files=False)
    assert "T_wobj_mesh" not in plan_to_json(plan)  # an old plan saves as it was
    new = plan_in_frame(plan, _frame())
    text = plan_to_json(new)
    assert '"T_wobj_mesh"' in text
    assert plan_from_json(text) == new


def test_a_bad_mesh_pose_names_the_field() -> None:
    raw = msgspec.json.decode(plan_to_json(load_plan(PLATE, check_files=False)))
    raw["work_object"]["T_wobj_mesh"] = {"position_m": [0, 0, 0], "quat_wxyz": [2, 0, 0, 0]}
    with pytest.raises(PlanError, match=r"work_object.T_wobj_mesh.*quat_wxyz"):
        plan_from_json(msgspec.json.encode(raw).decode())


@pytest.mark.slow
def test_check_and_validate_see_the_part_in_the_new_frame(reference_dir: Path) -> None:
    from planner.check.job import check_plan
    from planner.check.simulatable import check_simulatable, preflight, work_object_mesh

    plan = load_plan(PLATE)
    new = plan_in_frame(plan, _frame())
    before, after = check_plan(plan, PLANS), check_plan(new, PLANS)
    assert after.feasible and [p.status for p in after.points] == [p.status for p in before.points]
    for a, b in zip(before.points, after.points, strict=True):
        # the same sensor position and axis (the turn about the axis is chosen in wobj)
        assert a.T_base_tcp is not None and b.T_base_tcp is not None
        np.testing.assert_allclose(a.T_base_tcp[:3, 3], b.T_base_tcp[:3, 3], atol=1e-6)
        np.testing.assert_allclose(a.T_base_tcp[:3, 2], b.T_base_tcp[:3, 2], atol=1e-6)
    models = check_simulatable(new)
    preflight(new, models, work_object_mesh(new, PLANS, models))  # points on the new mesh
    with pytest.raises(PlanError, match="not on a planar face"):  # the old mesh: off
        preflight(new, models, work_object_mesh(plan, PLANS, check_simulatable(plan)))
