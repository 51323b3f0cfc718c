"""Tests of planner.cell.scene.robot_body: PyBullet indices, static links and adjacency of real
URDFs."""

from __future__ import annotations

import numpy as np
import pybullet as pb
import pytest

from calib.frames import make_transform, matrix_from_rotvec
from planner.builtins import robot_urdf
from planner.cell.scene.acl import pair
from planner.cell.scene.bodies import world_link_pose
from planner.cell.scene.robot_body import load_robot_body
from planner.robot.kinematics.chain import KinematicChain


@pytest.fixture
def client():
    c = pb.connect(pb.DIRECT)
    yield c
    pb.disconnect(c)


def test_ur5_indices_static_links_and_adjacency(client, reference_dir) -> None:
    path = reference_dir / "robots" / "ur5" / "ur5.urdf"
    chain = KinematicChain.from_urdf(path)
    T = make_transform(matrix_from_rotvec([0, 0, 1.0]), [0.3, -0.2, 0.5])
    body = load_robot_body(client, path, chain, T)
    names = body.links.names
    assert [names[i] for i in body.joint_index] == [
        "shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link",
        "wrist_3_link",
    ]  # fmt: skip
    assert {names[i] for i in body.static_links} == {"base_link", "base_link_inertia", "base"}
    assert names[body.flange_index] == chain.tip_link == "tool0"
    # the chain's base link lands on T_world_base; the flange follows our FK
    np.testing.assert_allclose(world_link_pose(client, body.links, -1), T, atol=1e-6)
    q = np.array([0.3, -1.0, 1.2, -0.5, 0.8, 0.1])
    body.set_q(client, q)
    np.testing.assert_allclose(
        world_link_pose(client, body.links, body.flange_index), T @ chain.fk(q)[0], atol=1e-6
    )
    adjacent = set(body.adjacent_pairs("tool_mount"))
    assert pair("shoulder_link", "upper_arm_link") in adjacent
    # tool0 is fixed to flange, flange to wrist_3_link: the tool root touches all three
    for link in ("tool0", "flange", "wrist_3_link"):
        assert pair("tool_mount", link) in adjacent
    assert pair("tool_mount", "wrist_2_link") not in adjacent


def test_builtin_robot_base_link_is_the_only_static_link(client) -> None:
    path = robot_urdf("builtin:irb4400")
    body = load_robot_body(client, path, KinematicChain.from_urdf(path), np.eye(4))
    assert body.static_links == frozenset({-1})
    assert len(body.joint_index) == 6
