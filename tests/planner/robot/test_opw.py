"""Analytic OPW inverse kinematics: round trips over all 8 branches, coverage, singularities."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from planner.robot.kinematics.chain import KinematicChain
from planner.robot.kinematics.opw import OPWParameters, opw_fk, opw_ik, wrist_centre

IRB4400 = Path(__file__).resolve().parents[3] / "assets/robots/irb4400/irb4400.urdf"
# datasheet figures; axis 3's zero has the forearm horizontal: theta3 = q3 + 90 deg
IRB_PARAMS = OPWParameters(0.2, -0.15, 0.0, 0.68, 0.89, 0.88, 0.14, (0, 0, -np.pi / 2, 0, 0, 0))
# a made-up arm with every parameter non-zero and mixed signs (tests the general formulas)
ODD_PARAMS = OPWParameters(
    0.15, 0.07, -0.11, 0.5, 0.7, 0.6, 0.1, (0.1, -0.3, 0.2, 0.4, -0.2, 0.5), (1, -1, 1, -1, -1, 1)
)


@pytest.fixture
def chain() -> KinematicChain:
    return KinematicChain.from_urdf(IRB4400)


def _max_pose_err(A: np.ndarray, B: np.ndarray) -> float:
    return float(np.abs(A - B).max()) if A.size else 0.0


def test_opw_fk_matches_the_urdf_chain(chain: KinematicChain, rng: np.random.Generator) -> None:
    q = rng.uniform(-np.pi, np.pi, (500, 6))
    assert _max_pose_err(opw_fk(IRB_PARAMS, q), chain.fk(q)) <= 1e-12


def test_theta_and_q_are_inverse(rng: np.random.Generator) -> None:
    q = rng.uniform(-3, 3, (10, 6))
    np.testing.assert_allclose(ODD_PARAMS.to_q(ODD_PARAMS.to_theta(q)), q, atol=1e-15)


@pytest.mark.parametrize("params", [IRB_PARAMS, ODD_PARAMS], ids=["irb4400", "odd"])
def test_all_branches_round_trip(params: OPWParameters, rng: np.random.Generator) -> None:
    q_true = rng.uniform(-np.pi, np.pi, (2000, 6))
    T = opw_fk(params, q_true)
    q, ok = opw_ik(params, T)
    assert q.shape == (2000, 8, 6) and ok.shape == (2000, 8)
    assert ok.all(axis=1).mean() > 0.5  # most random poses have all 8 branches
    T_back = opw_fk(params, q[ok])
    assert _max_pose_err(T_back, np.repeat(T, 8, axis=0)[ok.ravel()]) <= 1e-9
    assert np.isnan(q[~ok]).all() and np.isfinite(q[ok]).all()
    # the configuration we started from is one of the branches (modulo 2 pi)
    d = np.abs(np.angle(np.exp(1j * (q - q_true[:, None])))).max(axis=-1)
    assert (np.nanmin(d, axis=1) < 1e-8).all()
    # the 8 branches of a pose are distinct configurations
    full = ok.all(axis=1)
    diff = np.abs(q[full][:, :, None] - q[full][:, None]).max(axis=-1)
    assert (diff + np.eye(8) * 10 > 1e-6).all()


def test_wrist_singularity_is_solved_exactly(chain: KinematicChain) -> None:
    q_true = np.array([[0.3, 0.2, -0.4, 1.1, 0.0, -0.7], [0.3, 0.2, -0.4, 0.0, 0.0, 0.0]])
    T = chain.fk(q_true)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        q, ok = opw_ik(IRB_PARAMS, T)
    assert ok.any(axis=1).all()
    assert _max_pose_err(chain.fk(q[ok]), np.repeat(T, 8, axis=0)[ok.ravel()]) <= 1e-9
    # the branch with the original arm: theta4 + theta6 is what is determined, and the solver
    # puts it all in axis 6
    k = int(np.nanargmin(np.abs(q[0, :, :3] - q_true[0, :3]).max(axis=1)))
    assert k in (0, 1) and ok[:, k].all()
    np.testing.assert_allclose(q[:, k, :3], q_true[:, :3], atol=1e-9)
    np.testing.assert_allclose(q[0, k, 3] + q[0, k, 5], 1.1 - 0.7, atol=1e-9)


def test_shoulder_singularity_wrist_centre_on_axis_1() -> None:
    # wrist centre exactly on axis 1 (x = y = 0): theta1 is free, atan2(0, 0) picks 0
    T = np.eye(4)
    T[:3, 3] = [0.0, 0.0, 1.2 + IRB_PARAMS.c4]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        q, ok = opw_ik(IRB_PARAMS, T[None])
    assert ok.any()
    assert _max_pose_err(opw_fk(IRB_PARAMS, q[ok]), np.repeat(T[None], ok.sum(), axis=0)) <= 1e-9
    np.testing.assert_allclose(
        wrist_centre(IRB_PARAMS, IRB_PARAMS.to_theta(q[ok]))[:, :2], 0, atol=1e-12
    )


def test_stretched_arm_on_the_workspace_boundary() -> None:
    # theta3 + psi3 = 0: upper arm and the line axis 3 -> wrist centre aligned (D = 1)
    psi3 = np.arctan2(IRB_PARAMS.a2, IRB_PARAMS.c3)
    q_true = IRB_PARAMS.to_q(np.array([[0.4, 0.3, -psi3, 0.2, 0.5, 0.1]]))
    T = opw_fk(IRB_PARAMS, q_true)
    q, ok = opw_ik(IRB_PARAMS, T)
    assert ok.any()
    assert _max_pose_err(opw_fk(IRB_PARAMS, q[ok]), np.repeat(T, ok.sum(), axis=0)) <= 1e-9


def test_unreachable_poses_are_invalid_without_warnings() -> None:
    T = np.repeat(np.eye(4)[None], 2, axis=0)
    T[0, :3, 3] = [5.0, 0.0, 1.0]  # too far
    T[1, :3, 3] = [0.0, 0.0, 30.0]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        q, ok = opw_ik(IRB_PARAMS, T)
    assert not ok.any()
    assert np.isnan(q).all()


def test_lateral_offset_b_needs_distance_from_axis_1() -> None:
    # with b != 0 the wrist centre cannot come closer than |b| to axis 1
    T = np.eye(4)[None].copy()
    T[0, :3, 3] = [0.05, 0.0, 0.8 + ODD_PARAMS.c4]
    q, ok = opw_ik(ODD_PARAMS, T)
    assert not ok.any() and np.isnan(q).all()
