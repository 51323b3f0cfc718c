"""The URDF parser against PyBullet's own URDF importer, on the robots wobjcal ships or meets.

At zero joint values, for every joint: parent and child, type, world axis and limits; for every
link: the link frame, and the mass and centre-of-mass frame of its ``<inertial>``; and the total
mass and centre of mass of the arm. PyBullet's centre-of-mass frames (link state 0/1) are exact
in double precision; its URDF link frames (state 4/5) pass through a float32 inertial offset
(errors ~1e-7 m), hence the two tolerances.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pybullet_data
import pytest

from planner.cell.scene.bodies import pb_transform
from planner.cell.scene.pybullet_client import connect_direct, pb
from planner.robot.urdf import load_urdf

ASSETS = Path(__file__).resolve().parents[3] / "assets"
#: PyBullet joint type codes.
PB_TYPES = {pb.JOINT_REVOLUTE: "revolute", pb.JOINT_PRISMATIC: "prismatic", pb.JOINT_FIXED: "fixed"}


def _path(which: str, request: pytest.FixtureRequest) -> Path:
    if which == "irb4400":
        return ASSETS / "robots/irb4400/irb4400.urdf"
    if which == "ur5":
        reference_dir: Path = request.getfixturevalue("reference_dir")
        return reference_dir / "robots/ur5/ur5.urdf"
    return Path(pybullet_data.getDataPath()) / "kuka_iiwa/model.urdf"


@pytest.mark.parametrize("which", ["irb4400", "ur5", "kuka_iiwa"])
def test_parser_agrees_with_pybullet_at_zero(which: str, request: pytest.FixtureRequest) -> None:
    path = _path(which, request)
    model = load_urdf(path, check_meshes=False)
    joints = {j.name: j for j in model.joints}
    poses = model.link_poses_at_zero()
    cid = connect_direct()
    try:
        body = pb.loadURDF(str(path), useFixedBase=True, physicsClientId=cid)
        assert pb.getBodyInfo(body, physicsClientId=cid)[0].decode() == model.root
        names = {-1: model.root}
        pb_mass, pb_moment = 0.0, np.zeros(3)
        n = pb.getNumJoints(body, physicsClientId=cid)
        assert n == len(model.joints)
        for i in range(n):
            info = pb.getJointInfo(body, i, physicsClientId=cid)
            j = joints[info[1].decode()]
            names[i] = info[12].decode()
            assert (names[info[16]], names[i]) == (j.parent, j.child)
            ours_type = "revolute" if j.type == "continuous" else j.type
            assert PB_TYPES[info[2]] == ours_type, j.name

            state = pb.getLinkState(body, i, computeForwardKinematics=True, physicsClientId=cid)
            T_world_com = pb_transform(state[0], state[1])
            T_world_link = pb_transform(state[4], state[5])
            np.testing.assert_allclose(T_world_link, poses[j.child], atol=1e-6, err_msg=j.child)

            inertial = model.link(j.child).inertial
            if inertial is not None:
                T_com = poses[j.child] @ inertial.T_link_com
                np.testing.assert_allclose(T_world_com, T_com, atol=1e-9, err_msg=j.child)
                mass = pb.getDynamicsInfo(body, i, physicsClientId=cid)[0]
                assert mass == pytest.approx(inertial.mass, rel=1e-12), j.child
                pb_mass += mass
                pb_moment += mass * T_world_com[:3, 3]

            if j.is_moving:  # PyBullet gives the axis in the child's centre-of-mass frame
                np.testing.assert_allclose(
                    T_world_com[:3, :3] @ info[13],
                    poses[j.child][:3, :3] @ np.array(j.axis),
                    atol=1e-9,
                    err_msg=j.name,
                )
            if j.limit is not None:
                lim = j.limit
                expected = (lim.lower, lim.upper, lim.effort, lim.velocity)
                assert info[8:12] == pytest.approx(expected, rel=1e-12), j.name
    finally:
        pb.disconnect(cid)
    # PyBullet zeroes a fixed base's mass: compare the arm below the root link
    mass, com = model.mass_and_com()
    root = model.link(model.root).inertial
    m_root = 0.0 if root is None else root.mass
    c_root = np.zeros(3) if root is None else root.T_link_com[:3, 3]
    assert mass - m_root == pytest.approx(pb_mass, rel=1e-12)
    np.testing.assert_allclose(mass * com - m_root * c_root, pb_moment, atol=1e-9)
