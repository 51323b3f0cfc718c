"""KinematicChain: forward kinematics against PyBullet on our URDF, the UR5 and kuka_iiwa."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pybullet as pb
import pybullet_data
import pytest

from calib.errors import NonFiniteError, ShapeError
from planner.errors import UnknownFrameError
from planner.robot.kinematics.chain import KinematicChain
from planner.robot.urdf import transform_from_xyz_rpy

IRB4400 = Path(__file__).resolve().parents[3] / "assets/robots/irb4400/irb4400.urdf"
IIWA = Path(pybullet_data.getDataPath()) / "kuka_iiwa/model.urdf"


def _inertial_frames(path: Path) -> dict[str, np.ndarray]:
    """``T_link_com`` of every link from the URDF's <inertial><origin> (identity if absent)."""
    out = {}
    for link in ET.parse(path).getroot().findall("link"):
        o = link.find("inertial/origin")
        xyz = [float(v) for v in o.get("xyz", "0 0 0").split()] if o is not None else [0.0] * 3
        rpy = [float(v) for v in o.get("rpy", "0 0 0").split()] if o is not None else [0.0] * 3
        out[link.get("name")] = transform_from_xyz_rpy(tuple(xyz), tuple(rpy))
    return out


def pybullet_com_frames(path: Path, chain: KinematicChain, q: np.ndarray) -> dict[str, np.ndarray]:
    """PyBullet's link centre-of-mass frames ``(N, 4, 4)`` for configurations ``q``.

    PyBullet's COM frame (link state 0/1) is exact in double precision, while its URDF link frame
    (state 4/5) passes through a float32 inertial offset (errors ~1e-7 m), so we compare COM
    frames against ours composed with the URDF inertial origins.
    """
    cid = pb.connect(pb.DIRECT)
    try:
        body = pb.loadURDF(str(path), useFixedBase=True, physicsClientId=cid)
        nj = pb.getNumJoints(body, physicsClientId=cid)
        info = [pb.getJointInfo(body, i, physicsClientId=cid) for i in range(nj)]
        jidx = {i[1].decode(): i[0] for i in info}
        lidx = {i[12].decode(): i[0] for i in info}
        out: dict[str, np.ndarray] = {name: np.empty((len(q), 4, 4)) for name in lidx}
        for k, qk in enumerate(q):
            for name, v in zip(chain.joint_names, qk):
                pb.resetJointState(body, jidx[name], v, physicsClientId=cid)
            for name, i in lidx.items():
                st = pb.getLinkState(body, i, computeForwardKinematics=True, physicsClientId=cid)
                T = np.eye(4)
                T[:3, :3] = np.array(pb.getMatrixFromQuaternion(st[1])).reshape(3, 3)
                T[:3, 3] = st[0]
                out[name][k] = T
        return out
    finally:
        pb.disconnect(cid)


def random_q(chain: KinematicChain, rng: np.random.Generator, n: int) -> np.ndarray:
    lo = np.where(np.isfinite(chain.lower), chain.lower, -np.pi)
    hi = np.where(np.isfinite(chain.upper), chain.upper, np.pi)
    return rng.uniform(lo, hi, (n, chain.n_joints))


def _check_against_pybullet(path: Path, rng: np.random.Generator) -> KinematicChain:
    chain = KinematicChain.from_urdf(path)
    q = random_q(chain, rng, 25)
    ours = chain.link_poses(q)
    theirs = pybullet_com_frames(path, chain, q)
    com = _inertial_frames(path)
    checked = 0
    for name, T_pb in theirs.items():
        if name not in ours:
            continue
        T_ours = ours[name] @ com[name]
        np.testing.assert_allclose(T_ours[:, :3, 3], T_pb[:, :3, 3], atol=1e-9, err_msg=name)
        # PyBullet's quaternion -> matrix is double precision too
        np.testing.assert_allclose(T_ours[:, :3, :3], T_pb[:, :3, :3], atol=1e-9, err_msg=name)
        checked += 1
    assert checked >= chain.n_joints
    np.testing.assert_allclose(chain.fk(q), ours[chain.tip_link], atol=0)
    return chain


def test_irb4400_fk_matches_pybullet(rng: np.random.Generator) -> None:
    chain = _check_against_pybullet(IRB4400, rng)
    assert chain.joint_names == tuple(f"joint_{i}" for i in range(1, 7))
    assert (chain.base_link, chain.tip_link) == ("base_link", "tool0")
    np.testing.assert_allclose(np.rad2deg(chain.upper), [165, 95, 65, 200, 120, 400])
    np.testing.assert_allclose(np.rad2deg(chain.lower), [-165, -70, -60, -200, -120, -400])


def test_irb4400_zero_pose_matches_datasheet() -> None:
    chain = KinematicChain.from_urdf(IRB4400)
    T = chain.fk(np.zeros(6))[0]
    # flange at shoulder offset + forearm + flange, height base-shoulder + upper arm + offset
    np.testing.assert_allclose(T[:3, 3], [0.2 + 0.88 + 0.14, 0, 0.68 + 0.89 + 0.15], atol=1e-12)
    np.testing.assert_allclose(T[:3, 2], [1, 0, 0], atol=1e-12)  # flange normal along +x


def test_ur5_fk_matches_pybullet(reference_dir: Path, rng: np.random.Generator) -> None:
    path = reference_dir / "robots/ur5/ur5.urdf"
    chain = _check_against_pybullet(path, rng)
    assert chain.tip_link == "tool0"
    # the reference README quotes the zero-configuration tool0 position
    np.testing.assert_allclose(
        chain.fk(np.zeros(6))[0, :3, 3], [0.81725, 0.19145, -0.00549], atol=1e-5
    )


def test_iiwa_fk_matches_pybullet(rng: np.random.Generator) -> None:
    chain = _check_against_pybullet(IIWA, rng)
    assert chain.n_joints == 7
    assert chain.tip_link == "lbr_iiwa_link_7"


def test_jacobian_matches_finite_differences(rng: np.random.Generator) -> None:
    chain = KinematicChain.from_urdf(IRB4400)
    q = random_q(chain, rng, 4)
    T, J = chain.fk_jacobian(q)
    np.testing.assert_allclose(T, chain.fk(q), atol=1e-12)
    h = 1e-6
    for k in range(chain.n_joints):
        dq = np.zeros(chain.n_joints)
        dq[k] = h
        Tp, Tm = chain.fk(q + dq), chain.fk(q - dq)
        v = (Tp[:, :3, 3] - Tm[:, :3, 3]) / (2 * h)
        dR = (Tp[:, :3, :3] - Tm[:, :3, :3]) / (2 * h) @ np.swapaxes(T[:, :3, :3], 1, 2)
        w = np.stack([dR[:, 2, 1], dR[:, 0, 2], dR[:, 1, 0]], axis=1)
        np.testing.assert_allclose(J[:, :3, k], v, atol=1e-7)
        np.testing.assert_allclose(J[:, 3:, k], w, atol=1e-7)


def test_explicit_base_and_tip_links() -> None:
    chain = KinematicChain.from_urdf(IRB4400, base_link="link_2", tip_link="link_5")
    assert chain.joint_names == ("joint_3", "joint_4", "joint_5")
    np.testing.assert_allclose(chain.fk(np.zeros(3))[0, :3, 3], [0.88, 0, 0.89 + 0.15])
    with pytest.raises(UnknownFrameError, match=r"tip_link 'flange'.*tool0"):
        KinematicChain.from_urdf(IRB4400, tip_link="flange")


def test_bad_q_is_rejected_with_its_name() -> None:
    chain = KinematicChain.from_urdf(IRB4400)
    with pytest.raises(ShapeError, match=r"q must be \(N, 6\)"):
        chain.fk(np.zeros((3, 5)))
    with pytest.raises(NonFiniteError, match="q holds NaN"):
        chain.fk(np.full(6, np.nan))


def test_within_limits() -> None:
    chain = KinematicChain.from_urdf(IRB4400)
    q = np.zeros((3, 6))
    q[1, 1] = np.deg2rad(96)
    q[2, 5] = np.deg2rad(-399)
    np.testing.assert_array_equal(chain.within_limits(q), [True, False, True])


PRISMATIC = """<robot name="slide">
  <link name="rail"/><link name="carriage"/><link name="arm"/><link name="tip"/><link name="side"/>
  <joint name="slide" type="prismatic"><parent link="rail"/><child link="carriage"/>
    <axis xyz="1 0 0"/><limit lower="0" upper="2"/></joint>
  <joint name="turn" type="continuous"><parent link="carriage"/><child link="arm"/>
    <origin xyz="0 0 0.5" rpy="0 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="to_tip" type="fixed"><parent link="arm"/><child link="tip"/>
    <origin xyz="0.3 0 0"/></joint>
  <joint name="to_side" type="fixed"><parent link="carriage"/><child link="side"/>
    <origin xyz="0 0.1 0"/></joint>
</robot>"""


def test_prismatic_and_continuous_joints() -> None:
    from planner.robot.urdf import parse_urdf

    chain = KinematicChain.from_model(parse_urdf(PRISMATIC))
    assert chain.tip_link == "tip" and chain.joint_types == ("prismatic", "continuous")
    np.testing.assert_array_equal(chain.lower, [0.0, -np.inf])
    q = np.array([[1.5, np.pi / 2]])
    T, J = chain.fk_jacobian(q)
    np.testing.assert_allclose(T[0, :3, 3], [1.5, 0.3, 0.5], atol=1e-12)
    np.testing.assert_allclose(J[0, :, 0], [1, 0, 0, 0, 0, 0], atol=1e-12)  # slide: pure x
    np.testing.assert_allclose(J[0, :, 1], [-0.3, 0, 0, 0, 0, 1], atol=1e-12)  # z x (0, .3, 0)
    poses = chain.link_poses(q)
    np.testing.assert_allclose(poses["side"][0, :3, 3], [1.5, 0.1, 0.0], atol=1e-12)


def test_floating_joint_in_the_chain_is_refused() -> None:
    from planner.errors import URDFError
    from planner.robot.urdf import parse_urdf

    text = PRISMATIC.replace('type="prismatic"', 'type="floating"')
    with pytest.raises(URDFError, match="joint 'slide' is floating"):
        KinematicChain.from_model(parse_urdf(text))
