"""Frames and conventions: Tait-Bryan against scipy, quaternion orders, transforms."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from calib import frames
from calib.errors import DegenerateGeometryError, NonFiniteError, ShapeError

angles = st.floats(-np.pi, np.pi, allow_nan=False)
betas = st.floats(-np.pi / 2, np.pi / 2, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(angles, betas, angles)
def test_tait_bryan_matches_scipy_zyx(alpha: float, beta: float, gamma: float) -> None:
    R = frames.matrix_from_tait_bryan_zyx(alpha, beta, gamma)
    np.testing.assert_allclose(
        R, Rotation.from_euler("ZYX", [alpha, beta, gamma]).as_matrix(), atol=1e-12
    )
    abg = frames.tait_bryan_zyx_from_matrix(R)
    # angles may differ at gimbal lock; the rotation they describe must not
    np.testing.assert_allclose(frames.matrix_from_tait_bryan_zyx(*abg), R, atol=1e-9)
    assert -np.pi / 2 <= abg[1] <= np.pi / 2


@pytest.mark.parametrize("beta", [np.pi / 2, -np.pi / 2, np.pi / 2 - 1e-7, -np.pi / 2 + 1e-10])
def test_tait_bryan_near_gimbal_lock(beta: float, rng: np.random.Generator) -> None:
    for _ in range(50):
        alpha, gamma = rng.uniform(-np.pi, np.pi, 2)
        R = Rotation.from_euler("ZYX", [alpha, beta, gamma]).as_matrix()
        abg = frames.tait_bryan_zyx_from_matrix(R)
        np.testing.assert_allclose(frames.matrix_from_tait_bryan_zyx(*abg), R, atol=1e-6)
        assert abs(abg[1] - beta) < 1e-6


def test_tait_bryan_angles_equal_scipy_away_from_lock(rng: np.random.Generator) -> None:
    R = Rotation.random(1000, random_state=1).as_matrix()
    ours = frames.tait_bryan_zyx_from_matrix(R)
    theirs = Rotation.from_matrix(R).as_euler("ZYX")
    np.testing.assert_allclose(ours, theirs, atol=1e-9)


def test_quaternion_orders_round_trip(rng: np.random.Generator) -> None:
    R = Rotation.random(100, random_state=2).as_matrix()
    q_wxyz = frames.quat_wxyz_from_matrix(R)
    assert np.all(q_wxyz[:, 0] >= 0)
    np.testing.assert_allclose(frames.matrix_from_quat_wxyz(q_wxyz), R, atol=1e-12)
    q_xyzw = frames.quat_xyzw_from_matrix(R)
    np.testing.assert_allclose(q_xyzw, frames.quat_wxyz_to_xyzw(q_wxyz))
    np.testing.assert_allclose(frames.matrix_from_quat_xyzw(q_xyzw), R, atol=1e-12)
    # scipy's own quaternions are xyzw
    np.testing.assert_allclose(
        np.abs(Rotation.from_matrix(R).as_quat()), np.abs(q_xyzw), atol=1e-12
    )


def test_transform_chain_and_inverse(rng: np.random.Generator) -> None:
    T_a_b = frames.random_transform(rng, 1.0, np.pi)
    T_b_c = frames.random_transform(rng, 1.0, np.pi)
    p_c = rng.normal(size=(10, 3))
    T_a_c = T_a_b @ T_b_c
    np.testing.assert_allclose(
        frames.transform_points(T_a_c, p_c),
        frames.transform_points(T_a_b, frames.transform_points(T_b_c, p_c)),
        atol=1e-12,
    )
    np.testing.assert_allclose(frames.invert_transform(T_a_c) @ T_a_c, np.eye(4), atol=1e-12)
    np.testing.assert_allclose(frames.invert_transform(T_a_c), np.linalg.inv(T_a_c), atol=1e-12)


def test_small_motion_round_trip(rng: np.random.Generator) -> None:
    T = frames.random_transform(rng, 2.0, np.pi)
    delta = np.array([0.01, -0.02, 0.003, 0.01, -0.002, 0.03])
    np.testing.assert_allclose(
        frames.motion_between(T, T @ frames.small_motion(delta)), delta, atol=1e-12
    )


@pytest.mark.parametrize("angle", [0.0, 1e-12, 1e-7, 1e-3, 0.1, 1.0, 1.5, 1.5707, 2.0, 3.1])
def test_motion_between_one_pair_is_scipys(angle: float, rng: np.random.Generator) -> None:
    """One pair of transforms takes a plain-float path for rotations under 90 degrees: the
    same rotation vector as scipy's (the batch path) within a few units in the last place,
    at every size of rotation, and scipy's own above 90 degrees."""
    for _ in range(200):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        T_a = frames.random_transform(rng, 2.0, np.pi)
        T_c = T_a @ frames.make_transform(
            Rotation.from_rotvec(angle * axis).as_matrix(), rng.normal(0.0, 0.01, 3)
        )
        one = frames.motion_between(T_a, T_c)
        batch = frames.motion_between(T_a[None], T_c[None])[0]  # scipy's Rotation
        np.testing.assert_allclose(one, batch, rtol=1e-14, atol=1e-300)
        np.testing.assert_allclose(np.linalg.norm(one[3:]), angle, rtol=1e-9, atol=1e-15)


def test_motion_between_leaves_a_matrix_that_is_no_rotation_to_scipy() -> None:
    """A scaled "rotation" (trace above 3) is not read by the plain-float path: scipy's
    answer (or its refusal), as for a batch."""
    T = np.diag([2.0, 2.0, -0.5, 1.0])
    try:
        want = frames.motion_between(np.eye(4)[None], T[None])[0]
    except ValueError as exc:
        with pytest.raises(ValueError, match=re.escape(str(exc))):
            frames.motion_between(np.eye(4), T)
    else:
        np.testing.assert_array_equal(frames.motion_between(np.eye(4), T), want)


def test_check_transform_errors() -> None:
    with pytest.raises(ShapeError, match=r"T_base_wobj must be a \(4, 4\)"):
        frames.check_transform(np.eye(3), "T_base_wobj")
    bad = np.eye(4)
    bad[0, 0] = np.nan
    with pytest.raises(NonFiniteError, match="T_base_wobj holds NaN"):
        frames.check_transform(bad, "T_base_wobj")
    skew = np.eye(4)
    skew[0, 1] = 0.5
    with pytest.raises(DegenerateGeometryError, match="not orthonormal"):
        frames.check_transform(skew, "T_base_wobj")
    mirror = np.diag([1.0, 1.0, -1.0, 1.0])
    with pytest.raises(DegenerateGeometryError, match="reflection"):
        frames.check_transform(mirror, "T_base_wobj")
    # errors are ValueErrors for callers that only know the standard library
    with pytest.raises(ValueError):
        frames.check_transform("not a matrix", "T")


def _bad_transforms() -> list[np.ndarray]:
    """One of each kind of bad transform, and some that pass at the tolerance's edge."""
    out = []
    for i, j, v in [(0, 0, np.nan), (1, 3, np.inf), (3, 0, 2e-6), (3, 3, 1.0 + 2e-5), (0, 1, 2e-6)]:
        T = np.eye(4)
        T[i, j] = v
        out.append(T)
    out.append(np.diag([1.0, 1.0, -1.0, 1.0]))  # a reflection
    out.append(np.diag([-1.0, -1.0, 1.0, 1.0]))  # a half turn: fine
    edge = np.eye(4)
    edge[3, 3] = 1.0 + 5e-6  # within tol + 1e-5
    out.append(edge)
    return out


@pytest.mark.parametrize("T", _bad_transforms())
def test_one_transform_is_judged_as_a_batch_of_one_is(T: np.ndarray) -> None:
    """The single-transform path gives the batch's verdict and message for each case."""

    def verdict(value: np.ndarray) -> str:
        try:
            frames.check_transform(value, "T")
        except ValueError as exc:  # (the index of a bad entry has the batch's axis too)
            return f"{type(exc).__name__}: {str(exc).split(' (first at index')[0]}"
        return "ok"

    assert verdict(T) == verdict(T[None])


def test_import_calib_is_pure() -> None:
    import subprocess
    import sys

    code = (
        "import sys, calib, calib.frames, calib.probing;"
        "bad = [m for m in ('pybullet', 'viser', 'planner', 'webui', 'trimesh') "
        "if m in sys.modules]; print(bad); sys.exit(1 if bad else 0)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr
