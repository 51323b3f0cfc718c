"""The in-plane shift of many searches after the same earlier searches, in one call.

The batched form of :func:`calib.estimators.steering.inplane_shift_maps`,
:func:`~calib.estimators.steering.inplane_noise_cov`,
:func:`~calib.estimators.steering.shift_outline` and
:func:`~calib.estimators.steering.ellipse_support` (the model and its symbols are in
:mod:`calib.estimators.steering`): the update of the earlier searches
(:func:`~calib.estimators.steering.earlier_update`, one pseudo-inverse) is computed once and
every point's maps are stacked. Each point's result is the single-point function's to the
bit: the same operations in the same order, numpy's stacked products over the leading axis
(``tests/calib/estimators/test_steering_many.py`` compares them).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.errors import ShapeError
from calib.estimators.steering import EarlierUpdate

FloatArray = NDArray[np.float64]


def _points(points_m: ArrayLike, bases: ArrayLike) -> tuple[FloatArray, FloatArray]:
    P = np.asarray(points_m, dtype=np.float64)
    B = np.asarray(bases, dtype=np.float64)
    if P.ndim != 2 or P.shape[1] != 3:
        raise ShapeError(f"points must be (C, 3), got {P.shape}")
    if B.shape != (len(P), 3, 2):
        raise ShapeError(f"bases must be ({len(P)}, 3, 2), got {B.shape}")
    return P, B


def _motions(P: FloatArray, update: EarlierUpdate) -> FloatArray:
    """``(C, 3, 6)``: ``[I, -[p - c]x / L]`` of every point (``steering._motion`` stacked)."""
    v = P - update.centroid_m
    skew = np.zeros((len(P), 3, 3))
    skew[:, 0, 1], skew[:, 0, 2] = -v[:, 2], v[:, 1]
    skew[:, 1, 0], skew[:, 1, 2] = v[:, 2], -v[:, 0]
    skew[:, 2, 0], skew[:, 2, 1] = -v[:, 1], v[:, 0]
    eye = np.broadcast_to(np.eye(3), (len(P), 3, 3))
    return np.concatenate([eye, -skew / update.scale_m], axis=2)


def inplane_shift_maps_many(
    points_m: ArrayLike, bases: ArrayLike, update: EarlierUpdate
) -> tuple[FloatArray, FloatArray]:
    """The in-plane shift maps of searches at ``points_m`` after ``update``'s searches.

    Args:
        points_m: ``(C, 3)`` the searches' nominal points, wobj frame, metres.
        bases: ``(C, 3, 2)`` their faces' in-plane bases
            (:func:`calib.estimators.steering.plane_basis` of each normal).
        update: the earlier searches' update (with the misplacement's pivot).

    Returns:
        ``(G_t, G_w)``, each ``(C, 2, 3)``: point ``k``'s in-plane shift is
        ``G_t[k] @ t + G_w[k] @ w`` for a misplacement ``t`` (m), ``w`` (rad).
    """
    P, B = _points(points_m, bases)
    M = _motions(P, update) @ update.residual @ update.to_scaled
    G = np.swapaxes(B, 1, 2) @ M
    return G[:, :, :3], G[:, :, 3:]


def inplane_noise_cov_many(
    points_m: ArrayLike, bases: ArrayLike, update: EarlierUpdate, var_m2: ArrayLike
) -> FloatArray:
    """``(C, 2, 2)`` covariances of the in-plane shift, m^2, that the earlier searches' noise
    (variances ``var_m2`` ``(K,)``, m^2) leaves at each point (zeros with no earlier search);
    arguments as :func:`inplane_shift_maps_many`."""
    P, B = _points(points_m, bases)
    if update.count == 0:
        return np.zeros((len(P), 2, 2))
    v = np.asarray(var_m2, dtype=np.float64).reshape(-1)
    if v.shape != (update.count,):
        raise ShapeError(f"var_m2 must be ({update.count},), got {v.shape}")
    K = np.swapaxes(B, 1, 2) @ (_motions(P, update) @ update.pinv)
    out: FloatArray = (K * v[None, None, :]) @ np.swapaxes(K, 1, 2)
    return out


def _directions(directions: int) -> FloatArray:
    ang = np.linspace(0.0, 2.0 * np.pi, directions, endpoint=False)
    return np.stack([np.cos(ang), np.sin(ang)], axis=1)


def shift_outline_many(
    G_t: FloatArray,
    G_w: FloatArray,
    max_translation_m: float,
    max_angle_rad: float,
    directions: int = 32,
) -> FloatArray:
    """``(C, directions, 2)``: :func:`calib.estimators.steering.shift_outline` of each
    ``(G_t[k], G_w[k])`` (``(C, 2, 3)`` each), metres."""
    D = _directions(directions)
    out = np.zeros((len(G_t), directions, 2))
    for G, r in ((G_t, max_translation_m), (G_w, max_angle_rad)):
        U = D @ G  # (C, M, 3)
        norm = np.linalg.norm(U, axis=2, keepdims=True)
        U = np.divide(U, norm, out=np.zeros_like(U), where=norm > 1e-15)
        out += r * (U @ np.swapaxes(G, 1, 2))
    return out


def ellipse_support_many(cov: FloatArray, k: float, directions: int = 32) -> FloatArray:
    """``(C, directions, 2)``: :func:`calib.estimators.steering.ellipse_support` of each
    ``cov[i]`` (``(C, 2, 2)``, m^2), metres."""
    D = _directions(directions)
    CD = D @ np.asarray(cov, dtype=np.float64)  # (C, M, 2)
    h = np.sqrt(np.maximum(np.einsum("cij,ij->ci", CD, D), 0.0))
    return k * np.divide(CD, h[..., None], out=np.zeros_like(CD), where=h[..., None] > 1e-30)
