"""The paper's equations 1-12 against hand-worked examples, scipy and known geometry."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from calib.errors import DegenerateGeometryError, NonFiniteError, ShapeError
from calib.frames import make_transform, matrix_from_tait_bryan_zyx
from calib.paper import hultman

seeds = st.integers(0, 2**32 - 1)


def test_eq1_to_6_hand_worked_identity() -> None:
    R = hultman.orientation_from_three_points([0, 0, 0], [0, 1, 0], [0, 1, 1])
    np.testing.assert_array_equal(R, np.eye(3))


def test_eq1_to_6_hand_worked_quarter_turn() -> None:
    # WOCS y along base -x, P3 straight above P2: X = (-1,0,0) x (0,0,1) = (0,1,0)
    p1 = np.array([1.0, 2.0, 3.0])
    p2, p3 = p1 + np.array([-0.5, 0, 0]), p1 + np.array([-0.5, 0, 0.2])
    np.testing.assert_allclose(hultman.v1_vector(p1, p2), [-0.5, 0, 0])
    np.testing.assert_allclose(hultman.v2_vector(p2, p3), [0, 0, 0.2])
    x = hultman.x_vector([-0.5, 0, 0], [0, 0, 0.2])
    np.testing.assert_allclose(x, [0, 0.1, 0])
    np.testing.assert_allclose(hultman.z_vector(x, [-0.5, 0, 0]), [0, 0, 0.05])
    R = hultman.orientation_from_three_points(p1, p2, p3)
    np.testing.assert_allclose(R, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15)
    np.testing.assert_allclose(hultman.tait_bryan_angles(R), [math.pi / 2, 0, 0], atol=1e-15)


def test_eq5_6_element_ij_is_dot_of_wocs_axis_j_with_base_axis_i(rng) -> None:
    R_true = Rotation.random(random_state=rng).as_matrix()
    R = hultman.rotation_from_axes(R_true[:, 0], R_true[:, 1], R_true[:, 2])
    for i in range(3):
        for j in range(3):
            assert R[i, j] == pytest.approx(np.eye(3)[i] @ R_true[:, j], abs=1e-15)


@settings(max_examples=200, deadline=None, derandomize=True)
@given(seed=seeds, invert=st.booleans())
def test_three_points_on_a_posed_face_give_its_rotation(seed: int, invert: bool) -> None:
    rng = np.random.default_rng(seed)
    R_true = Rotation.random(random_state=rng).as_matrix()
    T = make_transform(R_true, rng.uniform(-2, 2, 3))
    y1, z1 = rng.uniform(-1, 0, 2)
    length = rng.uniform(0.05, 1.0)
    y3 = rng.uniform(-1, 0)
    dz = rng.uniform(0.02, 0.5) * (-1 if invert else 1)  # P3 above P2, or below when inverted
    pts = np.array([[0, y1, z1], [0, y1 + length, z1], [0, y3, z1 + dz]])
    pb = pts @ T[:3, :3].T + T[:3, 3]
    R = hultman.orientation_from_three_points(*pb, invert_v2=invert)
    np.testing.assert_allclose(R, R_true, atol=1e-9)
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-14)
    assert np.linalg.det(R) == pytest.approx(1.0)


@settings(max_examples=200, deadline=None, derandomize=True)
@given(seed=seeds)
def test_eq7_9_agree_with_scipy_zyx(seed: int) -> None:
    rng = np.random.default_rng(seed)
    R = Rotation.random(random_state=rng).as_matrix()
    abg = hultman.tait_bryan_angles(R)
    np.testing.assert_allclose(abg, Rotation.from_matrix(R).as_euler("ZYX"), atol=1e-9)
    # the printed formulas, written out
    beta = math.atan2(-R[2, 0], math.hypot(R[0, 0], R[1, 0]))
    cb = math.cos(beta)
    alpha = math.atan2(R[1, 0] / cb, R[0, 0] / cb)
    gamma = math.atan2(R[2, 1] / cb, R[2, 2] / cb)
    np.testing.assert_allclose(abg, [alpha, beta, gamma], atol=1e-12)


def test_eq10_hand_worked() -> None:
    # preliminary WOCS turned 90 deg about z at (1, 2, 3); the true origin is 0.01 m further
    # along WOCS x (= base y), 0.02 along WOCS y (= base -x) and -0.03 along WOCS z
    R = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])
    T = make_transform(R, [1, 2, 3])
    p4 = [7.0, 2.01, -5.0]  # x in WOCS: 0.01
    p5 = [0.98, 9.0, 4.0]  # y in WOCS: 0.02
    p6 = [-3.0, 8.0, 2.97]  # z in WOCS: -0.03
    T_adj = hultman.adjust_origin(T, p4, p5, p6)
    np.testing.assert_allclose(T_adj[:3, 3], [1 - 0.02, 2 + 0.01, 3 - 0.03], atol=1e-15)
    np.testing.assert_array_equal(T_adj[:3, :3], R)
    only_x = hultman.adjust_origin(T, p4)
    np.testing.assert_allclose(only_x[:3, 3], [1, 2.01, 3], atol=1e-15)
    only_z = hultman.adjust_origin(T, p4, p5, p6, use=(False, False, True))
    np.testing.assert_allclose(only_z[:3, 3], [1, 2, 2.97], atol=1e-15)


@settings(max_examples=100, deadline=None, derandomize=True)
@given(seed=seeds)
def test_eq10_points_on_three_faces_give_the_true_origin(seed: int) -> None:
    rng = np.random.default_rng(seed)
    R = Rotation.random(random_state=rng).as_matrix()
    o_true = rng.uniform(-1, 1, 3)
    faces = rng.uniform(-0.01, 0.01, 3)  # faces x = f0, y = f1, z = f2 in the true WOCS
    T_prelim = make_transform(R, o_true + rng.uniform(-0.05, 0.05, 3))
    on_face = rng.uniform(-0.5, 0, (3, 3))
    for axis in range(3):
        on_face[axis, axis] = faces[axis]
    pb = on_face @ R.T + o_true
    T = hultman.adjust_origin(T_prelim, *pb, face_coords_wobj=tuple(faces))
    np.testing.assert_allclose(T[:3, 3], o_true, atol=1e-12)


def test_eq11_hand_worked_and_fold() -> None:
    assert hultman.alpha1_from_points([0, 0, 0], [0.1, 1.0, 5]) == pytest.approx(math.atan(0.1))
    # B - A pointing to -y: atan of the same ratio, not atan2's +-180 deg branch
    assert hultman.alpha1_from_points([0, 0, 0], [-0.1, -1.0, 0]) == pytest.approx(math.atan(0.1))
    assert hultman.alpha1_from_points([1, 1, 0], [1.3, 1, 0]) == pytest.approx(math.pi / 2)


@pytest.mark.parametrize("alpha_deg", [-20.0, -3.0, 0.0, 3.0, 20.0])
def test_eq11_alpha1_is_minus_the_tait_bryan_alpha(alpha_deg: float) -> None:
    R = matrix_from_tait_bryan_zyx(math.radians(alpha_deg), math.radians(15), 0.0)
    a, b = R @ [0, -0.8, -0.25], R @ [0, -0.2, -0.25]
    assert hultman.alpha1_from_points(a, b) == pytest.approx(-math.radians(alpha_deg))


def test_eq12_hand_worked() -> None:
    tb = math.tan(math.radians(15.0))
    p3 = hultman.p3_estimate([0, 0, 0], [0, 1, 0], math.radians(15.0))
    np.testing.assert_allclose(p3, [0.05 * tb, 1, 0.05], atol=1e-15)
    # alpha1 = atan(0.1): cos^2 = 1 / 1.01, sin cos = 0.1 / 1.01
    p3 = hultman.p3_estimate([0, 0, 0], [0.1, 1.0, 0.2], math.radians(15.0), height_m=0.050)
    expect = [0.1 + 0.05 * tb / 1.01, 1.0 + 0.05 * tb * 0.1 / 1.01, 0.25]
    np.testing.assert_allclose(p3, expect, atol=1e-15)


@pytest.mark.parametrize("robot_at_plus_x", [False, True])
def test_eq12_p3_lies_on_the_inclined_face_when_aligned(robot_at_plus_x: bool) -> None:
    # side face inclined 15 deg, top leaning towards base +x; WOCS y along base +y (alpha = 0)
    # or, facing a robot at +x, along base -y (alpha = 180 deg, Tait-Bryan beta = -15 deg)
    b15 = math.radians(15.0)
    abg = (math.pi, -b15, 0.0) if robot_at_plus_x else (0.0, b15, 0.0)
    R = matrix_from_tait_bryan_zyx(*abg)
    T = make_transform(R, [1.0, 0.3, 0.5])
    a, b = (T @ [0, -0.8, -0.25, 1])[:3], (T @ [0, -0.2, -0.25, 1])[:3]
    p3 = hultman.p3_estimate(a, b, math.radians(15.0))
    assert R[:, 0] @ (p3 - b) == pytest.approx(0.0, abs=1e-15)  # on the face
    assert p3[2] - b[2] == pytest.approx(0.050)
    np.testing.assert_allclose(hultman.orientation_from_three_points(a, b, p3), R, atol=1e-12)


@pytest.mark.parametrize("alpha_deg", [3.0, -3.0, 10.0])
def test_eq12_printed_sign_only_tilts_about_y_second_order(alpha_deg: float) -> None:
    alpha = math.radians(alpha_deg)
    R = matrix_from_tait_bryan_zyx(alpha, math.radians(15.0), 0.0)
    a, b = R @ [0, -0.8, -0.25], R @ [0, -0.2, -0.25]
    p3 = hultman.p3_estimate(a, b, math.radians(15.0))
    err = Rotation.from_matrix(R.T @ hultman.orientation_from_three_points(a, b, p3)).as_rotvec()
    # no error about x or z; about y roughly 2 tan(beta1) sin(alpha)^2
    assert abs(err[0]) < 1e-12 and abs(err[2]) < 1e-12
    predicted = 2 * math.tan(math.radians(15.0)) * math.sin(alpha) ** 2
    assert abs(err[1]) == pytest.approx(predicted, rel=0.25)


@pytest.mark.parametrize(
    ("points", "error", "match"),
    [
        (([0, 0, 0], [0, 0, 0], [0, 0, 1]), DegenerateGeometryError, "P1 and P2 coincide"),
        (([0, 0, 0], [0, 1, 0], [0, 1, 0]), DegenerateGeometryError, "P2 and P3 coincide"),
        (([0, 0, 1], [0, 1, 0], [0, 0, 1]), DegenerateGeometryError, "P1 and P3 coincide"),
        (([0, 0, 0], [0, 1, 0], [0, 3, 0]), DegenerateGeometryError, "P1, P2, P3 are collinear"),
        (([0, 0, 0], [0, 1, 0], [0, 2, 1e-12]), DegenerateGeometryError, "collinear"),
        (([0, 0, np.nan], [0, 1, 0], [0, 1, 1]), NonFiniteError, "P1 holds NaN"),
        (([0, 0, 0], [0, 1, np.inf], [0, 1, 1]), NonFiniteError, "P2"),
        (([0, 0], [0, 1, 0], [0, 1, 1]), ShapeError, r"P1 must be \(3\), got \(2,\)"),
        (([0, 0, 0], "abc", [0, 1, 1]), ShapeError, "P2 must be numeric"),
    ],
)
def test_degenerate_points_raise_named_errors(points, error, match) -> None:
    with pytest.raises(error, match=match):
        hultman.orientation_from_three_points(*points)


def test_degenerate_errors_use_given_names() -> None:
    with pytest.raises(DegenerateGeometryError, match="points H, F, D are collinear"):
        hultman.orientation_from_three_points(
            [0, 0, 0], [0, 1, 0], [0, 2, 0], names=("H", "F", "D")
        )
    with pytest.raises(DegenerateGeometryError, match="vectors V1 and V2 are parallel"):
        hultman.orientation_from_vectors([0, 1, 0], [0, -2, 0])
    with pytest.raises(DegenerateGeometryError, match="V2 has zero length"):
        hultman.orientation_from_vectors([0, 1, 0], [0, 0, 0])


def test_adjust_origin_bad_input() -> None:
    with pytest.raises(ShapeError, match="P5 is required"):
        hultman.adjust_origin(np.eye(4), [0, 0, 0], use=(True, True, False))
    with pytest.raises(ShapeError, match="T_prelim"):
        hultman.adjust_origin(np.eye(3), [0, 0, 0])
    with pytest.raises(DegenerateGeometryError, match="T_prelim rotation part"):
        hultman.adjust_origin(np.diag([1.0, 1, 2, 1]), [0, 0, 0])
    with pytest.raises(NonFiniteError, match="P6"):
        hultman.adjust_origin(np.eye(4), p6_base=[0, 0, np.nan])


def test_p3_bad_input() -> None:
    with pytest.raises(DegenerateGeometryError, match="A and B coincide"):
        hultman.p3_estimate([1, 2, 0], [1, 2, 0.5], 0.2)
    with pytest.raises(ShapeError, match="beta1_rad must lie in"):
        hultman.p3_estimate([0, 0, 0], [0, 1, 0], math.pi / 2)
    with pytest.raises(NonFiniteError, match="beta1_rad"):
        hultman.p3_estimate([0, 0, 0], [0, 1, 0], float("nan"))
    with pytest.raises(ShapeError, match="height_m must be > 0"):
        hultman.p3_estimate([0, 0, 0], [0, 1, 0], 0.2, height_m=-0.05)
    with pytest.raises(ShapeError, match="beta1_rad must be a scalar"):
        hultman.p3_estimate([0, 0, 0], [0, 1, 0], [0.2, 0.3])
