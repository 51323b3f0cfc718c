"""make_ik_solver: OPW for OPW arms (checked against PyBullet), numeric otherwise; branches."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pybullet as pb
import pybullet_data
import pytest

from calib.errors import DegenerateGeometryError, NonFiniteError, ShapeError
from planner.robot.kinematics.branches import abb_confdata, branch_codes, classify, quadrant
from planner.robot.kinematics.chain import KinematicChain
from planner.robot.kinematics.opw_from_urdf import NotOPWError
from planner.robot.kinematics.solver import IKSolutions, make_ik_solver
from planner.robot.urdf import parse_urdf

IRB4400 = Path(__file__).resolve().parents[3] / "assets/robots/irb4400/irb4400.urdf"
IIWA = Path(pybullet_data.getDataPath()) / "kuka_iiwa/model.urdf"


@pytest.fixture(scope="module")
def irb() -> KinematicChain:
    return KinematicChain.from_urdf(IRB4400)


def test_irb4400_takes_the_analytic_path(irb: KinematicChain) -> None:
    solver = make_ik_solver(irb)
    assert solver.kind == "opw" and solver.why_not_opw is None


def test_coverage_and_round_trip_on_2000_reachable_poses(
    irb: KinematicChain, rng: np.random.Generator
) -> None:
    q_true = rng.uniform(irb.lower, irb.upper, (2000, 6))
    T = irb.fk(q_true)
    sol = make_ik_solver(irb).solve(T)
    assert isinstance(sol, IKSolutions)
    N, K, n = sol.q.shape
    assert (N, n) == (2000, 6) and K >= 8 and sol.valid.shape == sol.branch.shape == (N, K)
    assert sol.found.mean() >= 0.999
    ok = sol.valid.ravel()
    q = sol.q.reshape(-1, 6)[ok]
    assert np.abs(irb.fk(q) - np.repeat(T, K, axis=0)[ok]).max() <= 1e-9
    assert irb.within_limits(q, tol=1e-12).all()
    assert np.isnan(sol.q[~sol.valid]).all() and (sol.branch[~sol.valid] == -1).all()
    # solutions are packed first in each row; K is the largest count (at least 8)
    count = sol.valid.sum(axis=1)
    np.testing.assert_array_equal(sol.valid, np.arange(K) < count[:, None])
    assert max(8, count.max()) == K
    # the branch code stored with each solution is its geometric classification
    np.testing.assert_array_equal(sol.branch[sol.valid], branch_codes(make_ik_solver(irb).opw, q))


def test_solutions_agree_with_pybullet_fk(irb: KinematicChain, rng: np.random.Generator) -> None:
    q_true = rng.uniform(irb.lower, irb.upper, (30, 6))
    T = irb.fk(q_true)
    sol = make_ik_solver(irb).solve(T)
    cid = pb.connect(pb.DIRECT)
    try:
        body = pb.loadURDF(str(IRB4400), useFixedBase=True, physicsClientId=cid)
        worst = 0.0
        for i, k in zip(*np.nonzero(sol.valid)):
            for j in range(6):
                pb.resetJointState(body, j, sol.q[i, k, j], physicsClientId=cid)
            # tool0 (link 6) has its inertial frame at the link origin: state 0/1 is tool0
            st = pb.getLinkState(body, 6, computeForwardKinematics=True, physicsClientId=cid)
            R = np.array(pb.getMatrixFromQuaternion(st[1])).reshape(3, 3)
            worst = max(
                worst, np.abs(np.array(st[0]) - T[i, :3, 3]).max(), np.abs(R - T[i, :3, :3]).max()
            )
    finally:
        pb.disconnect(cid)
    assert worst <= 1e-6


def test_axis_6_turn_variants(irb: KinematicChain) -> None:
    q_true = np.deg2rad([10.0, 20.0, 10.0, 30.0, 40.0, 30.0])
    sol = make_ik_solver(irb).solve(irb.fk(q_true))
    same_arm = sol.valid[0] & (np.abs(sol.q[0, :, :5] - q_true[:5]).max(axis=1) < 1e-9)
    q6 = np.sort(np.rad2deg(sol.q[0, same_arm, 5]))
    np.testing.assert_allclose(q6, [-330.0, 30.0, 390.0], atol=1e-7)  # limit +-400 deg


def test_singular_and_unreachable_poses(irb: KinematicChain) -> None:
    T = irb.fk(np.array([[0.3, 0.2, -0.4, 1.1, 0.0, -0.7], [0.0] * 6]))
    far = np.eye(4)
    far[:3, 3] = [5.0, 0.0, 1.0]
    sol = make_ik_solver(irb).solve(np.concatenate([T, far[None]]))
    assert sol.found.tolist() == [True, True, False]
    assert np.isnan(sol.q[2]).all()
    ok = sol.valid[:2]
    assert (
        np.abs(irb.fk(sol.q[:2][ok]) - np.repeat(T, sol.q.shape[1], axis=0)[ok.ravel()]).max()
        < 1e-9
    )


def test_bad_poses_are_rejected(irb: KinematicChain) -> None:
    solver = make_ik_solver(irb)
    T = np.eye(4)
    T[1, 3] = np.nan
    with pytest.raises(NonFiniteError, match="T_base_flange"):
        solver.solve(T)
    with pytest.raises(ShapeError, match="T_base_flange"):
        solver.solve(np.zeros((3, 3)))
    bad = np.repeat(np.eye(4)[None], 3, axis=0)
    bad[1, 3, 0] = 1.0
    with pytest.raises(ShapeError, match=r"T_base_flange last row"):
        solver.solve(bad)
    bad = np.repeat(np.eye(4)[None], 3, axis=0)
    bad[2, 0, 0] = 1.1
    with pytest.raises(DegenerateGeometryError, match="not orthonormal"):
        solver.solve(bad)
    bad[2, 0, 0] = -1.0
    with pytest.raises(DegenerateGeometryError, match="reflection"):
        solver.solve(bad)


def test_classification_matches_link_geometry(
    irb: KinematicChain, rng: np.random.Generator
) -> None:
    solver = make_ik_solver(irb)
    q = rng.uniform(-np.pi, np.pi, (300, 6))
    poses = irb.link_poses(q)
    centre = poses["link_5"][:, :3, 3]  # the wrist centre (axes 4, 5, 6 meet there)
    R1 = poses["link_1"][:, :3, :3]
    j2, j3 = poses["link_2"][:, :3, 3], poses["link_3"][:, :3, 3]
    # in the frame turned by axis 1 (x forward, z up)
    c1 = np.einsum("nji,nj->ni", R1, centre)
    v = np.einsum("nji,nj->ni", R1, j3 - j2)  # lower arm, axis 2 -> axis 3
    w = np.einsum("nji,nj->ni", R1, centre - j2)
    back = c1[:, 0] < 0
    behind = v[:, 2] * w[:, 0] - v[:, 0] * w[:, 2] < 0
    expected = 4 * back + 2 * behind + (q[:, 4] < 0)
    np.testing.assert_array_equal(branch_codes(solver.opw, q), expected)
    flags = solver.classify(q[0])
    assert flags.cfx == expected[0]
    assert (flags.shoulder_back, flags.elbow_back) == (bool(back[0]), bool(behind[0]))


def test_abb_confdata() -> None:
    assert abb_confdata(np.zeros(6)) == (0, 0, 0, 0)
    q = np.deg2rad([100.0, 0.0, 0.0, -10.0, -5.0, 390.0])
    assert abb_confdata(q) == (1, -1, 4, 1)
    # upper arm tilted back and forearm folded up: wrist centre behind axis 1
    q_back = np.deg2rad([-170.0, -70.0, -60.0, 181.0, 30.0, -91.0])
    assert abb_confdata(q_back)[:3] == (-2, 2, -2)
    assert classify(make_ik_solver(KinematicChain.from_urdf(IRB4400)).opw, q_back).shoulder_back
    assert quadrant(np.deg2rad(-0.5)) == -1 and quadrant(np.deg2rad(89.9)) == 0


def test_non_opw_arms_use_numeric(reference_dir: Path, rng: np.random.Generator) -> None:
    ur5 = KinematicChain.from_urdf(reference_dir / "robots/ur5/ur5.urdf")
    solver = make_ik_solver(ur5, n_seeds=8)
    assert solver.kind == "numeric" and "UR-style" in (solver.why_not_opw or "")
    with pytest.raises(NotOPWError, match="OPW arms only"):
        solver.classify(np.zeros(6))
    iiwa = KinematicChain.from_urdf(IIWA)
    solver = make_ik_solver(iiwa, n_seeds=6)
    assert solver.kind == "numeric"
    q_true = rng.uniform(iiwa.lower, iiwa.upper, (10, 7))
    sol = solver.solve(iiwa.fk(q_true))
    assert sol.found.mean() >= 0.9 and (sol.branch == -1).all()
    q_near, found = sol.nearest(q_true)
    np.testing.assert_allclose(iiwa.fk(q_near[found]), iiwa.fk(q_true[found]), atol=1e-6)


def test_nearly_opw_urdf_takes_the_analytic_path_with_polishing(rng: np.random.Generator) -> None:
    # vendor files often round rpy to 4 digits: 1.5708 tilts axes by 4e-6 rad, so the exact
    # OPW model is refused; the approximate one is used and every branch polished on the chain
    path = Path(__file__).resolve().parents[2] / "data/kuka_style_opw.urdf"
    text = path.read_text().replace("1.5707963267948966", "1.5708")
    chain = KinematicChain.from_model(parse_urdf(text, source=path))
    solver = make_ik_solver(chain)
    assert (solver.kind, solver.opw_exact, solver.why_not_opw) == ("opw", False, None)
    q_true = rng.uniform(chain.lower, chain.upper, (300, 6))
    T = chain.fk(q_true)
    sol = solver.solve(T)
    assert sol.found.mean() >= 0.999
    K = sol.q.shape[1]
    err = np.abs(chain.fk(sol.q[sol.valid]) - np.repeat(T, K, axis=0)[sol.valid.ravel()]).max()
    assert err <= 1e-9
    assert sol.valid.sum(axis=1).mean() > 8  # several branches per pose, not one numeric answer
