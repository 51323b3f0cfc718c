"""The batched in-plane shifts (:mod:`calib.estimators.steering_many`) equal the single-point
functions of :mod:`calib.estimators.steering` to the bit, for every point of a batch."""

from __future__ import annotations

import numpy as np
import pytest

from calib.errors import ShapeError
from calib.estimators import steering as st
from calib.estimators import steering_many as sm


def _layout(rng: np.random.Generator, k: int) -> tuple[np.ndarray, np.ndarray]:
    X = rng.uniform(-0.2, 0.2, (k, 3))
    N = rng.normal(size=(k, 3))
    return X, N / np.linalg.norm(N, axis=1, keepdims=True)


@pytest.mark.parametrize("k", [0, 1, 3, 6, 9])
def test_batched_maps_and_outlines_are_the_single_ones_to_the_bit(k: int) -> None:
    rng = np.random.default_rng(k)
    X, Nx = _layout(rng, k)
    P, N = _layout(rng, 25)
    c, pivot, L = rng.uniform(-0.05, 0.05, 3), rng.uniform(-0.05, 0.05, 3), 0.12
    var = rng.uniform(1e-10, 1e-8, k)
    u = st.earlier_update(X, Nx, c, L, pivot)
    assert u.count == k
    B = np.stack([st.plane_basis(n) for n in N])
    G_t, G_w = sm.inplane_shift_maps_many(P, B, u)
    u_noise = st.earlier_update(X, Nx, c, L, c)  # the noise does not depend on the pivot
    cov = sm.inplane_noise_cov_many(P, B, u_noise, var)
    outline = sm.shift_outline_many(G_t, G_w, 3e-3, 0.02)
    ellipse = sm.ellipse_support_many(cov, 4.0)
    for j in range(len(P)):
        g_t, g_w = st.inplane_shift_maps(P[j], N[j], X, Nx, c, L, pivot)
        assert np.array_equal(g_t, G_t[j]) and np.array_equal(g_w, G_w[j])
        one = st.inplane_noise_cov(P[j], N[j], X, Nx, c, L, var)
        assert np.array_equal(one, cov[j])
        assert np.array_equal(st.shift_outline(g_t, g_w, 3e-3, 0.02), outline[j])
        assert np.array_equal(st.ellipse_support(one, 4.0), ellipse[j])


def test_one_update_serves_the_single_point_functions() -> None:
    """The single-point maps are the update's residual applied at the point (one definition)."""
    rng = np.random.default_rng(7)
    X, Nx = _layout(rng, 4)
    p, c = np.array([0.1, -0.05, 0.02]), X.mean(axis=0)
    u = st.earlier_update(X, Nx, c, 0.2, c)
    motion = np.hstack([np.eye(3), -st._skew(p - c) / 0.2])
    g_t, g_w = st.normal_shift_maps(p, [0.0, 0.0, 1.0], X, Nx, c, 0.2, c)
    want = np.array([0.0, 0.0, 1.0]) @ (motion @ u.residual @ u.to_scaled)
    assert np.array_equal(np.concatenate([g_t, g_w]), want)
    # an update with no earlier search leaves the whole misplacement
    assert np.array_equal(st.earlier_update(X[:0], Nx[:0], c, 0.2, c).residual, np.eye(6))


def test_shapes_are_checked() -> None:
    u = st.earlier_update(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(3), 0.1, np.zeros(3))
    with pytest.raises(ShapeError, match="bases"):
        sm.inplane_shift_maps_many(np.zeros((2, 3)), np.zeros((3, 3, 2)), u)
    with pytest.raises(ShapeError, match="points"):
        sm.inplane_shift_maps_many(np.zeros((2, 2)), np.zeros((2, 3, 2)), u)
    with pytest.raises(ShapeError, match="differ"):
        st.earlier_update(np.zeros((2, 3)), np.zeros((1, 3)), np.zeros(3), 0.1, np.zeros(3))
    u1 = st.earlier_update(np.ones((1, 3)), [[0.0, 0.0, 1.0]], np.zeros(3), 0.1, np.zeros(3))
    with pytest.raises(ShapeError, match="var_m2"):
        sm.inplane_noise_cov_many(np.zeros((1, 3)), np.zeros((1, 3, 2)), u1, [1.0, 2.0])
