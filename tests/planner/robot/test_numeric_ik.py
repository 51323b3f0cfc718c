"""Numeric IK: reaches random reachable poses of the UR5 and kuka_iiwa, respects limits."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pybullet_data
import pytest

from calib.errors import NonFiniteError, ShapeError
from planner.robot.kinematics.chain import KinematicChain
from planner.robot.kinematics.numeric_ik import NumericIK

IIWA = Path(pybullet_data.getDataPath()) / "kuka_iiwa/model.urdf"


def _coverage(chain: KinematicChain, rng: np.random.Generator, n: int = 150) -> float:
    lo = np.where(np.isfinite(chain.lower), chain.lower, -np.pi)
    hi = np.where(np.isfinite(chain.upper), chain.upper, np.pi)
    q_true = rng.uniform(lo, hi, (n, chain.n_joints))
    T = chain.fk(q_true)
    res = NumericIK(chain).solve(T)
    # every valid solution reproduces its pose and is within limits
    N, K, _ = res.q.shape
    ok = res.valid.ravel()
    q = res.q.reshape(N * K, -1)[ok]
    T_rep = np.repeat(T, K, axis=0)[ok]
    T_sol = chain.fk(q)
    assert np.abs(T_sol[:, :3, 3] - T_rep[:, :3, 3]).max() <= 1e-6
    assert np.abs(T_sol[:, :3, :3] - T_rep[:, :3, :3]).max() <= 2e-6
    assert chain.within_limits(q).all()
    assert np.isnan(res.q[~res.valid]).all()
    return float(res.valid.any(axis=1).mean())


@pytest.mark.slow
def test_ur5_reaches_95_percent(reference_dir: Path, rng: np.random.Generator) -> None:
    chain = KinematicChain.from_urdf(reference_dir / "robots/ur5/ur5.urdf")
    assert _coverage(chain, rng) >= 0.95


def test_iiwa_reaches_95_percent(rng: np.random.Generator) -> None:
    chain = KinematicChain.from_urdf(IIWA)
    assert _coverage(chain, rng) >= 0.95


def test_supplied_seed_is_used_and_solutions_deduplicated(rng: np.random.Generator) -> None:
    chain = KinematicChain.from_urdf(IIWA)
    q_true = np.array([0.3, -0.5, 0.2, 1.0, -0.4, 0.6, 0.1])
    ik = NumericIK(chain, n_seeds=4, max_iter=30)
    res = ik.solve(chain.fk(q_true), seeds=np.stack([q_true, q_true]))
    assert res.q.shape == (1, 6, 7)
    assert res.valid[0, 0] and not res.valid[0, 1]  # the second identical seed is a duplicate
    np.testing.assert_allclose(res.q[0, 0], q_true, atol=1e-9)


def test_unreachable_pose_is_invalid() -> None:
    chain = KinematicChain.from_urdf(IIWA)
    T = np.eye(4)
    T[:3, 3] = [5.0, 0.0, 0.0]
    res = NumericIK(chain, n_seeds=4, max_iter=30).solve(T)
    assert not res.valid.any()
    assert np.isnan(res.q).all()
    assert np.all(res.pos_err_m > 3.0)


def test_bad_input() -> None:
    chain = KinematicChain.from_urdf(IIWA)
    ik = NumericIK(chain, n_seeds=2)
    with pytest.raises(ShapeError, match="T_base_tip"):
        ik.solve(np.eye(3))
    T = np.eye(4)
    T[0, 3] = np.nan
    with pytest.raises(NonFiniteError, match="T_base_tip"):
        ik.solve(T)
    with pytest.raises(ShapeError, match="seeds"):
        ik.solve(np.eye(4), seeds=np.zeros((2, 3)))


def test_random_seeds_from_rng_are_reproducible() -> None:
    chain = KinematicChain.from_urdf(IIWA)
    a = NumericIK(chain, n_seeds=5, rng=np.random.default_rng(3)).seeds
    b = NumericIK(chain, n_seeds=5, rng=np.random.default_rng(3)).seeds
    np.testing.assert_array_equal(a, b)
    assert a.shape == (5, 7) and chain.within_limits(a).all()
