"""Tests of planner.cell.scene.collision: clearance queries (pairs, distances, sensor rule, base
pose)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from calib.frames import make_transform
from planner.cell.cell import Cell
from planner.cell.scene.fixtures import table


@pytest.mark.slow
def test_ur5_upper_arm_into_the_base_is_a_self_collision(ur5: Cell) -> None:
    with ur5.saved_state():
        ur5.set_joint_positions([0, 0, 0, 0, 0, 0])  # arm stretched out horizontally
        assert ur5.clearance().ok
        ur5.set_joint_positions([0, np.pi / 2, 0, 0, 0, 0])  # upper arm straight down
        cl = ur5.clearance()
    assert not cl.ok
    assert set(cl.pair) == {"base_link_inertia", "upper_arm_link"}
    assert cl.clearance_m < 0 and "hits" in cl.describe()


@pytest.mark.slow
def test_clearance_names_the_pair_and_distance(cell: Cell) -> None:
    with cell.saved_state():
        cell.set_joint_positions(cell.home_q)
        T_world_sensor = cell.link_poses()["sensor"]
        face = T_world_sensor[:3, 3] - 0.008 * T_world_sensor[:3, 2]  # sensor face centre
        gap = 0.003
        centre = face + (gap + 0.05) * T_world_sensor[:3, 2]
        T_box = T_world_sensor.copy()
        T_box[:3, 3] = centre
        cell.add_fixture("block", size_m=(0.1, 0.1, 0.1), T_world_fixture=T_box)
        try:
            cl = cell.clearance(margin_m=0.005)
            assert cl.pair == ("sensor_body", "block")
            assert cl.clearance_m == pytest.approx(gap, abs=1e-6)
            assert not cl.ok and cl.slack_m == pytest.approx(gap - 0.005, abs=1e-6)
            loose = cell.clearance(margin_m=0.002)
            assert loose.ok
            assert loose.describe() == "sensor_body is near block (clearance 3.0 mm)"
        finally:
            cell.remove_fixture("block")
        assert cell.clearance(margin_m=0.005).ok


def test_sensor_may_approach_the_work_object_within_its_standoff(cell: Cell) -> None:
    with cell.saved_state():
        cell.set_joint_positions(cell.home_q)
        T_world_sensor = cell.link_poses()["sensor"]
        T_wobj = T_world_sensor.copy()
        T_wobj[:3, 3] = T_world_sensor[:3, 3] + 0.1 * T_world_sensor[:3, 2]
        # a box whose near face lies 5 mm in front of the sensor face (3 mm before the TCP)
        cell.set_work_object(trimesh.creation.box([0.2, 0.2, 0.2 + 0.006]), "m", T_wobj)
        cl = cell.clearance(margin_m=0.010)
        assert cl.ok  # only contact is forbidden for the sensor, not the 10 mm margin
        assert cl.pair is not None and cl.pair[0] == "sensor_body"
        # Bullet's triangle-mesh margin makes mesh distances up to 1 mm conservative
        assert 0.004 <= cl.clearance_m <= 0.005 + 1e-6
        strict = cell.clearance(margin_m=0.010, sensor_wobj_allowed=False)
        assert not strict.ok and strict.pair == cl.pair
        skipped = cell.clearance(margin_m=0.010, skip_wobj=True)
        assert skipped.pair is None or skipped.pair[1] != "work object"


@pytest.mark.slow
def test_static_base_on_a_table_is_not_a_collision() -> None:
    with Cell(use_acl_cache=False) as c:
        c.add_fixture(table(top_z_m=0.0, size_m=(1.0, 1.0, 0.05)))
        c.set_joint_positions(c.home_q)
        cl = c.clearance()
        assert cl.ok, cl.describe()
        c.set_joint_positions([0, np.radians(90), np.radians(60), 0, 0, 0])  # dive into it
        cl = c.clearance()
        assert not cl.ok and cl.pair[1] == "table"


@pytest.mark.slow
def test_base_pose_moves_everything(cell: Cell) -> None:
    T = make_transform(p=[2.0, 0, 0])
    with Cell(T_world_base=T, use_acl_cache=False) as moved:
        moved.set_joint_positions(moved.home_q)
        cell.set_joint_positions(cell.home_q)
        np.testing.assert_allclose(
            moved.link_poses()["sensor"], T @ cell.link_poses()["sensor"], atol=1e-6
        )
