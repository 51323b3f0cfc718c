"""Tests of planner.cell.scene.bodies: pose conversions and link frames vs PyBullet's inertial
frames."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pybullet as pb
import pybullet_data
import pytest

from calib.frames import make_transform, matrix_from_rotvec, random_transform
from planner.cell.scene.bodies import (
    load_urdf_body,
    pb_pose,
    pb_transform,
    set_link_pose,
    world_link_pose,
)


def test_pose_round_trip(rng) -> None:
    poses = [random_transform(rng, 2.0, np.pi) for _ in range(500)]
    # half turns about each axis and diagonals: the branches of Shepperd's method
    for axis in [*np.eye(3).tolist(), [1, 1, 0], [0, 1, 1], [1, 1, 1]]:
        a = np.asarray(axis, float) / np.linalg.norm(axis)
        poses.append(make_transform(matrix_from_rotvec(np.pi * a), [0.1, 0.2, 0.3]))
    for T in poses:
        pos, quat = pb_pose(T)
        assert np.linalg.norm(quat) == pytest.approx(1.0, abs=1e-12)
        np.testing.assert_allclose(pb_transform(pos, quat), T, atol=1e-12)
        # and PyBullet agrees on the meaning of the quaternion
        R = np.reshape(pb.getMatrixFromQuaternion(quat), (3, 3))
        np.testing.assert_allclose(R, T[:3, :3], atol=1e-12)


def test_link_frame_not_inertial_frame(rng) -> None:
    """The KUKA iiwa's base has an inertial offset: link frames must still land exactly."""
    client = pb.connect(pb.DIRECT)
    try:
        path = Path(pybullet_data.getDataPath()) / "kuka_iiwa" / "model.urdf"
        body = load_urdf_body(client, path, np.eye(4), "robot")
        assert not np.allclose(body.T_link_inertial, np.eye(4))
        T = random_transform(rng, 1.0, np.pi)
        set_link_pose(client, body, T)
        np.testing.assert_allclose(world_link_pose(client, body, -1), T, atol=1e-6)
        # the first joint's child sits 0.1575 m above the base link frame (URDF origin)
        T1 = world_link_pose(client, body, 0)
        np.testing.assert_allclose(T1[:3, 3], T[:3, 3] + 0.1575 * T[:3, 2], atol=1e-6)
    finally:
        pb.disconnect(client)


def test_pybullet_chatter_goes_to_the_log_not_the_terminal(
    tmp_path, capfd: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    """Item 10: PyBullet's "No inertial data" lines flooded stderr (two per link)."""
    import logging

    from planner.cell.scene.bodies import load_urdf_body
    from planner.cell.scene.pybullet_client import connect_direct, pb

    urdf = tmp_path / "bare.urdf"
    urdf.write_text(
        '<robot name="bare"><link name="base"/><link name="arm"/>'
        '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'
    )
    client = connect_direct()
    try:
        capfd.readouterr()
        with caplog.at_level(logging.DEBUG, logger="planner.cell.scene.pybullet_client"):
            load_urdf_body(client, urdf, np.eye(4), "robot")
    finally:
        pb.disconnect(client)
    out, err = capfd.readouterr()
    assert "No inertial data" not in out + err and "b3Warning" not in out + err
    assert "no inertial data (mass 1 assumed) for links ['base', 'arm']" in caplog.text
