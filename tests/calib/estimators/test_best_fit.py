"""Point-to-plane best fit: exact without noise, order-invariant, covariance that matches the
spread of many noisy fits, and named refusals for unobservable layouts and bad input."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from calib.errors import NonFiniteError, ShapeError, UnobservableError
from calib.estimators.best_fit import best_fit, best_fit_many
from calib.estimators.layout import constraint_set, random_face_layout
from calib.estimators.three_two_one import ThreeTwoOneLayout, three_two_one
from calib.frames import (
    invert_transform,
    motion_between,
    random_transform,
    small_motion,
    transform_points,
)
from calib.probing import ProbePoint

seeds = st.integers(min_value=0, max_value=2**32 - 1)


def _slide(rng: np.random.Generator, points, amount: float) -> np.ndarray:
    """Points moved within their faces (along the edge line for edge points), wobj frame."""
    out = []
    for p in points:
        n = np.asarray(p.normal)
        if p.edge_normal is not None:
            d = np.cross(n, p.edge_normal)
            d /= np.linalg.norm(d)
        else:
            d = rng.normal(size=3)
            d -= (d @ n) * n
        out.append(np.asarray(p.position_m) + rng.uniform(-amount, amount) * d)
    return np.array(out)


@settings(derandomize=True, max_examples=50, deadline=None)
@given(seed=seeds, n_edge=st.integers(0, 2))
def test_noise_free_random_pose_is_recovered_exactly(seed: int, n_edge: int) -> None:
    rng = np.random.default_rng(seed)
    faces = random_face_layout(rng, (4, 3, 2), n_edge_points=n_edge)
    T_true = random_transform(rng, 2.0, np.pi)
    q = transform_points(T_true, _slide(rng, faces.points, 0.03))
    guess = T_true @ random_transform(rng, 0.02, np.deg2rad(3.0))  # 20 mm / 3 deg off
    res = best_fit(faces.points, q, guess)
    assert np.abs(motion_between(T_true, res.T_base_wobj)).max() < 1e-9
    assert res.rms_m < 1e-10
    assert res.converged


def test_residuals_are_point_to_plane_distances(rng: np.random.Generator) -> None:
    faces = random_face_layout(rng, (4, 3, 2), n_edge_points=1)
    T_true = random_transform(rng, 1.0, 1.0)
    q = transform_points(T_true, _slide(rng, faces.points, 0.01))
    q += rng.normal(scale=2e-4, size=q.shape)
    res = best_fit(faces.points, q, T_true, sigma_m=2e-4)
    cs = constraint_set(faces.points)
    x = transform_points(invert_transform(res.T_base_wobj), q)[cs.point_index]
    expected = np.einsum("ij,ij->i", cs.normals, x - cs.nominal_m)
    np.testing.assert_allclose(res.residuals_m, expected, atol=1e-15)
    assert res.residual_ids.count("e0") == 2 and len(res.residual_ids) == len(faces.points) + 1
    assert res.rms_m == pytest.approx(np.sqrt(np.mean(expected**2)))
    # at the least-squares optimum the residuals are orthogonal to the Jacobian columns
    J = np.concatenate([-cs.normals, -np.cross(x, cs.normals)], axis=1)
    assert np.abs(J.T @ res.residuals_m).max() < 1e-12


def test_invariant_under_point_order(rng: np.random.Generator) -> None:
    faces = random_face_layout(rng, (4, 3, 2), n_edge_points=1)
    T_true = random_transform(rng, 1.0, 2.0)
    q = transform_points(T_true, np.array([p.position_m for p in faces.points]))
    q += rng.normal(scale=3e-4, size=q.shape)
    ref = best_fit(faces.points, q, T_true).T_base_wobj
    for _ in range(5):
        perm = rng.permutation(len(faces.points))
        T = best_fit([faces.points[i] for i in perm], q[perm], T_true).T_base_wobj
        np.testing.assert_allclose(T, ref, atol=1e-12)


def test_exactly_determined_fit_equals_three_two_one(rng: np.random.Generator) -> None:
    faces = random_face_layout(rng, (3, 2, 1))
    T_true = random_transform(rng, 1.0, 2.0)
    q = transform_points(T_true, np.array([p.position_m for p in faces.points]))
    q += rng.normal(scale=5e-4, size=q.shape)
    p = faces.points
    T321 = three_two_one(ThreeTwoOneLayout.from_points(p[:3], p[3:5], p[5]), q).T_base_wobj
    res = best_fit(p, q, T_true)
    np.testing.assert_allclose(res.T_base_wobj, T321, atol=1e-10)
    assert res.sigma_m == 0.0  # no redundancy: nothing to estimate sigma from


def _stator_like_points() -> list[ProbePoint]:
    """A side face (+x), top face (+z, via edge points) and short side (+y), like Fig. 8a."""
    up = (0.0, 0.0, 1.0)
    from calib.probing import SearchSpec

    edge = SearchSpec("edge", edge_direction=up)
    return [
        ProbePoint("A", (0.0, -0.80, -0.08), (1.0, 0.0, 0.0)),
        ProbePoint("B", (0.0, -0.20, -0.08), (1.0, 0.0, 0.0)),
        ProbePoint("D", (0.0, -0.30, -0.03), (1.0, 0.0, 0.0)),
        ProbePoint("E", (0.0, -0.70, -0.03), (1.0, 0.0, 0.0)),
        ProbePoint("F", (0.0, -0.25, 0.0), (1.0, 0.0, 0.0), edge, edge_normal=up),
        ProbePoint("H", (0.0, -0.75, 0.0), (1.0, 0.0, 0.0), edge, edge_normal=up),
        ProbePoint("C", (-0.05, 0.0, -0.05), (0.0, 1.0, 0.0)),
    ]


def test_covariance_matches_spread_of_noisy_fits() -> None:
    rng = np.random.default_rng(11)
    pts = _stator_like_points()
    cs = constraint_set(pts)
    T_true = random_transform(rng, 1.5, np.pi)
    x = np.array([p.position_m for p in pts])
    q0 = transform_points(T_true, x)
    sigma = 1e-4
    ref = best_fit(cs, q0, T_true, sigma_m=sigma)
    eps = np.array([0.0, -1.0, -0.1])  # the paper's epsilon
    n = 1000
    deltas = np.empty((n, 6))
    eps_err = np.empty((n, 3))
    for k in range(n):
        q = q0 + rng.normal(scale=sigma, size=q0.shape)
        T = best_fit(cs, q, T_true).T_base_wobj
        deltas[k] = motion_between(T_true, T)
        eps_err[k] = transform_points(invert_transform(T_true) @ T, eps) - eps
    emp = np.cov(deltas.T)
    pred = ref.covariance
    np.testing.assert_allclose(np.sqrt(np.diag(emp)), np.sqrt(np.diag(pred)), rtol=0.10)
    # whole matrix, not just the diagonal: whitened empirical covariance close to identity
    Lc = np.linalg.cholesky(pred)
    white = np.linalg.solve(Lc, np.linalg.solve(Lc, emp).T)
    assert np.abs(np.linalg.eigvalsh(white) - 1.0).max() < 0.25
    # predicted error at epsilon (wobj axes) against the Monte Carlo spread
    emp_eps = np.cov(eps_err.T)
    pred_eps = ref.predicted_error(eps)
    np.testing.assert_allclose(np.sqrt(np.diag(emp_eps)), np.sqrt(np.diag(pred_eps)), rtol=0.10)
    for d in (np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.6, 0.8])):
        mc = float(np.std(eps_err @ d, ddof=1))
        assert ref.predicted_sigma(eps, d) == pytest.approx(mc, rel=0.10)
    # epsilon lies 1 m from the origin: rotation errors must dominate there
    assert np.trace(pred_eps) > np.trace(ref.predicted_error(np.zeros(3)))


def test_sigma_is_estimated_from_residuals() -> None:
    rng = np.random.default_rng(5)
    faces = random_face_layout(rng, (20, 15, 15))
    T_true = random_transform(rng, 1.0, 1.0)
    q = transform_points(T_true, np.array([p.position_m for p in faces.points]))
    sigma = 3e-4
    # noise along each point's normal only, so every residual sees exactly sigma
    normals = np.array([p.normal for p in faces.points])
    q += transform_points(
        T_true, normals * rng.normal(scale=sigma, size=(len(q), 1))
    ) - transform_points(T_true, np.zeros(3))
    res = best_fit(faces.points, q, T_true)
    assert res.sigma_m == pytest.approx(sigma, rel=0.25)
    np.testing.assert_allclose(res.covariance, res.sigma_m**2 * res.unit_covariance)
    res_given = best_fit(faces.points, q, T_true, sigma_m=1e-3)
    np.testing.assert_allclose(res_given.covariance, 1e-6 * res.unit_covariance, rtol=1e-9)


def test_converges_from_a_poor_guess() -> None:
    rng = np.random.default_rng(8)
    faces = random_face_layout(rng, (4, 3, 3))
    T_true = random_transform(rng, 1.0, 3.0)
    q = transform_points(T_true, np.array([p.position_m for p in faces.points]))
    guess = T_true @ small_motion([0.1, -0.1, 0.05, 0.3, -0.2, 0.25])  # 150 mm, ~24 deg
    res = best_fit(faces.points, q, guess)
    assert np.abs(motion_between(T_true, res.T_base_wobj)).max() < 1e-9


def test_unobservable_layout_is_refused_with_the_free_motion_named() -> None:
    pts = [p for p in _stator_like_points() if p.id != "C"]  # nothing on the short side
    q = np.array([p.position_m for p in pts])
    with pytest.raises(UnobservableError, match="translation along wobj y") as info:
        best_fit(pts, q, np.eye(4))
    assert info.value.unconstrained == ("translation along wobj y",)
    assert isinstance(info.value, ValueError)


def test_bad_input_raises_named_errors() -> None:
    pts = _stator_like_points()
    q = np.array([p.position_m for p in pts])
    with pytest.raises(ShapeError, match="one row per point"):
        best_fit(pts, q[:-1], np.eye(4))
    with pytest.raises(ShapeError, match="measured_base"):
        best_fit(pts, q[:, :2], np.eye(4))
    bad = q.copy()
    bad[3, 2] = np.inf
    with pytest.raises(NonFiniteError, match="measured_base"):
        best_fit(pts, bad, np.eye(4))
    with pytest.raises(ShapeError, match="T_base_wobj_guess"):
        best_fit(pts, q, np.eye(3))
    with pytest.raises(ShapeError, match="sigma_m"):
        best_fit(pts, q, np.eye(4), sigma_m=-1.0)
    with pytest.raises(ShapeError, match="ProbePoint"):
        best_fit([*pts[:-1], "C"], q, np.eye(4))  # type: ignore[list-item]
    res = best_fit(pts, q, np.eye(4))
    with pytest.raises(ShapeError, match="direction"):
        res.predicted_sigma(np.zeros(3), np.zeros(3))
    with pytest.raises(NonFiniteError, match="p_wobj"):
        res.predicted_error([np.nan, 0.0, 0.0])


def test_batched_fits_equal_single_fits() -> None:
    rng = np.random.default_rng(21)
    faces = random_face_layout(rng, (4, 3, 2), n_edge_points=1)
    cs = constraint_set(faces.points)
    T_true = random_transform(rng, 1.0, np.pi)
    k = 40
    q = transform_points(T_true, cs.positions_m) + rng.normal(scale=2e-4, size=(k, cs.n_points, 3))
    guesses = T_true @ np.stack([random_transform(rng, 0.02, np.deg2rad(3.0)) for _ in range(k)])
    batch = best_fit_many(cs, q, guesses)
    assert batch.T_base_wobj.shape == (k, 4, 4) and batch.converged.all()
    for i in (0, 17, k - 1):
        single = best_fit(cs, q[i], guesses[i])
        np.testing.assert_allclose(batch.T_base_wobj[i], single.T_base_wobj, atol=1e-12)
        assert batch.rms_m[i] == pytest.approx(single.rms_m, rel=1e-9)
    # one shared guess broadcasts over the batch
    shared = best_fit_many(faces.points, q, T_true)
    np.testing.assert_allclose(shared.T_base_wobj, batch.T_base_wobj, atol=1e-12)


def test_batched_fit_bad_input() -> None:
    pts = _stator_like_points()
    q = np.array([p.position_m for p in pts])
    with pytest.raises(ShapeError, match=r"measured_base must be \(K, 7, 3\)"):
        best_fit_many(pts, q, np.eye(4))
    with pytest.raises(ShapeError, match="T_base_wobj_guess"):
        best_fit_many(pts, np.stack([q, q]), np.stack([np.eye(4)] * 3))
    bad = np.stack([q, q])
    bad[1, 0, 0] = np.nan
    with pytest.raises(NonFiniteError, match="measured_base"):
        best_fit_many(pts, bad, np.eye(4))
    with pytest.raises(UnobservableError, match="translation along wobj y"):
        best_fit_many(pts[:-1], np.stack([q[:-1]]), np.eye(4))
