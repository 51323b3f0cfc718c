"""OPW parameters from URDFs: our IRB 4400, a KUKA-style file, and arms that are not OPW."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pybullet_data
import pytest

from planner.robot.kinematics.chain import KinematicChain
from planner.robot.kinematics.opw_from_urdf import NotOPWError, opw_from_chain, why_not_opw
from planner.robot.kinematics.opw_robot import OPWRobot
from planner.robot.urdf import parse_urdf

ROOT = Path(__file__).resolve().parents[3]
IRB4400 = ROOT / "assets/robots/irb4400/irb4400.urdf"
KUKA_STYLE = Path(__file__).resolve().parents[2] / "data/kuka_style_opw.urdf"
IIWA = Path(pybullet_data.getDataPath()) / "kuka_iiwa/model.urdf"


def _lengths(robot: OPWRobot) -> tuple[float, ...]:
    p = robot.params
    return (p.a1, p.a2, p.b, p.c1, p.c2, p.c3, p.c4)


def _check_fk_and_ik(chain: KinematicChain, rng: np.random.Generator) -> None:
    robot = opw_from_chain(chain)
    q = rng.uniform(chain.lower, chain.upper, (300, 6))
    T = chain.fk(q)
    assert np.abs(robot.fk(q) - T).max() <= 1e-9
    q_sol, valid, _ = robot.solve(T)
    assert valid.any(axis=1).all()
    K = q_sol.shape[1]
    assert np.abs(chain.fk(q_sol[valid]) - np.repeat(T, K, axis=0)[valid.ravel()]).max() <= 1e-9


def test_irb4400_parameters_are_the_datasheet_figures(rng: np.random.Generator) -> None:
    chain = KinematicChain.from_urdf(IRB4400)
    robot = opw_from_chain(chain)
    np.testing.assert_allclose(_lengths(robot), (0.2, -0.15, 0, 0.68, 0.89, 0.88, 0.14), atol=1e-12)
    np.testing.assert_allclose(robot.params.offsets, (0, 0, -np.pi / 2, 0, 0, 0), atol=1e-12)
    assert robot.params.sign_corrections == (1, 1, 1, 1, 1, 1)
    np.testing.assert_allclose(robot.T_base_opw, np.eye(4), atol=1e-12)
    _check_fk_and_ik(chain, rng)
    assert why_not_opw(chain) is None


def test_kuka_style_urdf_gives_the_published_kr6_parameters(rng: np.random.Generator) -> None:
    # rotated, offset mount; KUKA axis directions; upper arm horizontal at zero; rpy on origins
    chain = KinematicChain.from_urdf(KUKA_STYLE, base_link="base_link")
    robot = opw_from_chain(chain)
    # KR 6 R700 sixx (ROS-Industrial opw_kinematics): a1 .025, a2 -.035, b 0, c1 .4, c2 .315,
    # c3 .365, c4 .08, offsets (0, -pi/2, 0, 0, 0, 0); A1, A4, A6 (and in this file A5) turn
    # about negative axes
    np.testing.assert_allclose(
        _lengths(robot), (0.025, -0.035, 0, 0.4, 0.315, 0.365, 0.08), atol=1e-12
    )
    np.testing.assert_allclose(robot.params.offsets, (0, -np.pi / 2, 0, 0, 0, 0), atol=1e-12)
    assert robot.params.sign_corrections == (-1, 1, 1, -1, -1, -1)
    _check_fk_and_ik(chain, rng)
    # from the mount (the URDF root) the OPW frame is placed by T_base_opw
    mounted = KinematicChain.from_urdf(KUKA_STYLE)
    assert mounted.base_link == "world_mount"
    robot_m = opw_from_chain(mounted)
    np.testing.assert_allclose(robot_m.T_base_opw[:3, 3], (0.3, -0.2, 0.0), atol=1e-12)
    assert robot_m.params.c1 == pytest.approx(0.45)
    _check_fk_and_ik(mounted, rng)


def test_lateral_offset_b(rng: np.random.Generator) -> None:
    text = IRB4400.read_text().replace(
        '<origin xyz="0 0 0.150" rpy="0 0 0"/>', '<origin xyz="0 0.05 0.150" rpy="0 0 0"/>'
    )
    chain = KinematicChain.from_model(parse_urdf(text, source=IRB4400))
    robot = opw_from_chain(chain)
    assert robot.params.b == pytest.approx(0.05, abs=1e-12)
    _check_fk_and_ik(chain, rng)


def test_ur5_does_not_qualify(reference_dir: Path) -> None:
    chain = KinematicChain.from_urdf(reference_dir / "robots/ur5/ur5.urdf")
    with pytest.raises(NotOPWError, match=r"axes 4-6 do not meet.*0\.09465 m apart.*UR-style"):
        opw_from_chain(chain)


def test_iiwa_does_not_qualify() -> None:
    chain = KinematicChain.from_urdf(IIWA)
    assert why_not_opw(chain) == "OPW needs 6 revolute joints; the chain has 7"


def test_tilted_axis_2_does_not_qualify() -> None:
    text = IRB4400.read_text().replace(
        '<origin xyz="0.200 0 0.680" rpy="0 0 0"/>', '<origin xyz="0.200 0 0.680" rpy="0.1 0 0"/>'
    )
    # roll about x tilts axis 2 (y) towards z: no longer perpendicular to axis 1
    chain = KinematicChain.from_model(parse_urdf(text, source=IRB4400))
    with pytest.raises(NotOPWError, match=r"axis 2 is not perpendicular to axis 1 \(angle 5\.7"):
        opw_from_chain(chain)


def test_nearly_opw_is_refused_by_the_fk_check() -> None:
    # a forearm offset of 1e-8 m across the arm plane is below the geometric tolerance but the
    # OPW model would be 1e-8 m off: the verification must refuse it
    text = IRB4400.read_text().replace(
        '<origin xyz="0.140 0 0" rpy="0 0 0"/>', '<origin xyz="0.140 0 0.00000002" rpy="0 0 0"/>'
    )
    chain = KinematicChain.from_model(parse_urdf(text, source=IRB4400))
    with pytest.raises(NotOPWError, match="does not reproduce the chain's forward kinematics"):
        opw_from_chain(chain)
