"""Where a search lands on its face when it is commanded in the estimate of the searches before it.

A best fit measured step by step (:func:`calib.estimators.runners.run_best_fit`, progressive)
commands each search in the frame estimated from the points measured so far: after each
measurement the estimate moves by the smallest motion that puts the measured points on their
faces (:func:`~calib.estimators.runners.min_norm_update`: translations at the layout's centroid
``c``, rotations scaled by its RMS size ``L``). Linearised, in the scaled coordinates
``z = (t_c, L w)`` that update is a projection: after the first ``k`` searches (rows
``J_k = [n, (x - c) x n / L]``) the estimate's error is ``(I - pinv(J_k) J_k) z`` (nested row
spaces make the sequence of updates one projection). A point ``p`` of a face with normal ``n``
is then searched off its nominal spot by the in-plane part of that error's motion at ``p``:
``s = E^T [I, -[p - c]x / L] (I - pinv(J_k) J_k) S delta`` for the part's misplacement
``delta = (t, w)`` (``|t| <= a`` about the misplacement pivot, ``|w| <= b``; ``S`` converts it
to the scaled coordinates), with ``E`` ``(3, 2)`` the face's in-plane basis.

:func:`normal_shift_maps` gives the same error's part along the normal, ``n^T [I, -[p - c]x / L]
(I - pinv(J_k) J_k) S delta``: how far from its nominal height the face lies in the frame the
search is commanded in, which an adaptive program's later searches are sized by
(:mod:`planner.program.steered_searches`).

:func:`inplane_shift_maps` gives the two ``(2, 3)`` maps of ``t`` and ``w``; :func:`shift_outline`
the outline of every shift they allow (support points of ``G_t a B + G_w b B``, exact for
balls), which the footprint check grows the footprint by. With ``k = 0`` it is the whole
misplacement: ``|s| <= a + b |p - pivot|``. The model is first order in the misplacement (the
second-order term is ``b^2 |p - pivot| / 2``, 0.05 mm at 1 deg and 0.3 m) and ignores the
measurement noise of the earlier points (micrometres): callers add a floor and a safety factor.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.errors import ShapeError
from calib.estimators.runners import FIXED_RCOND

FloatArray = NDArray[np.float64]

#: Smallest layout size used to scale rotations (as the runners' ``MIN_SCALE_M``), metres.
MIN_SCALE_M = 1e-3


def plane_basis(normal: ArrayLike) -> FloatArray:
    """``(3, 2)`` orthonormal in-plane basis ``E`` of a face with unit ``normal`` ``(3,)``
    (deterministic: the same normal gives the same basis)."""
    n = np.asarray(normal, dtype=np.float64).reshape(3)
    n = n / np.linalg.norm(n)
    helper = np.eye(3)[int(np.argmin(np.abs(n)))]
    e1 = np.cross(n, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    return np.stack([e1, e2], axis=1)


def _skew(v: FloatArray) -> FloatArray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


@dataclass(frozen=True)
class EarlierUpdate:
    """The step-by-step update after ``K`` earlier searches, the same for every later point
    (computed once by :func:`earlier_update`, read by the single-point functions here and by
    the batched ones of :mod:`calib.estimators.steering_many`).

    Attributes:
        centroid_m: ``(3,)`` the centroid ``c`` the update turns about, wobj frame, metres.
        scale_m: the RMS size ``L`` rotations are scaled by (at least :data:`MIN_SCALE_M`),
            metres.
        residual: ``(6, 6)`` ``I - pinv(J_k) J_k`` in the scaled coordinates ``(t_c, L w)``
            (the identity with no earlier search).
        pinv: ``(6, K)`` ``pinv(J_k)``: the scaled update per metre of each earlier event.
        to_scaled: ``(6, 6)`` ``S``: a misplacement ``(t, w)`` about the pivot (m, rad) in the
            scaled coordinates.
    """

    centroid_m: FloatArray
    scale_m: float
    residual: FloatArray
    pinv: FloatArray
    to_scaled: FloatArray

    @property
    def count(self) -> int:
        """``K``, the number of earlier searches."""
        return int(self.pinv.shape[1])


def earlier_update(
    earlier_m: ArrayLike,
    earlier_normals: ArrayLike,
    centroid_m: ArrayLike,
    scale_m: float,
    pivot_m: ArrayLike,
) -> EarlierUpdate:
    """The update after the ``earlier`` searches (``(K, 3)`` points and their faces' normals,
    wobj frame; ``K`` may be 0), with the centroid, scale and pivot of
    :func:`inplane_shift_maps`."""
    X = np.asarray(earlier_m, dtype=np.float64).reshape(-1, 3)
    Nn = np.asarray(earlier_normals, dtype=np.float64).reshape(-1, 3)
    if X.shape != Nn.shape:
        raise ShapeError(f"earlier points {X.shape} and normals {Nn.shape} differ")
    c = np.asarray(centroid_m, dtype=np.float64).reshape(3)
    m = np.asarray(pivot_m, dtype=np.float64).reshape(3)
    L = max(float(scale_m), MIN_SCALE_M)
    S = np.eye(6)
    S[:3, 3:] = -_skew(c - m)
    S[3:, 3:] *= L
    if len(X):
        J = np.hstack([Nn, np.cross(X - c, Nn) / L])
        pinv = np.linalg.pinv(J, rcond=FIXED_RCOND)
        residual = np.eye(6) - pinv @ J
    else:
        pinv = np.zeros((6, 0))
        residual = np.eye(6)
    return EarlierUpdate(c, L, residual, pinv, S)


def _motion(point_m: ArrayLike, update: EarlierUpdate) -> FloatArray:
    """``(3, 6)`` ``[I, -[p - c]x / L]``: the displacement at ``point_m`` of a scaled motion."""
    p = np.asarray(point_m, dtype=np.float64).reshape(3)
    return np.hstack([np.eye(3), -_skew(p - update.centroid_m) / update.scale_m])


def _residual_motion(
    point_m: ArrayLike,
    earlier_m: ArrayLike,
    earlier_normals: ArrayLike,
    centroid_m: ArrayLike,
    scale_m: float,
    pivot_m: ArrayLike,
) -> FloatArray:
    """``(3, 6)``: the displacement at ``point_m`` of the estimate's error after the
    ``earlier`` searches, for a misplacement ``(t, w)`` about ``pivot_m`` (module docstring)."""
    u = earlier_update(earlier_m, earlier_normals, centroid_m, scale_m, pivot_m)
    out: FloatArray = _motion(point_m, u) @ u.residual @ u.to_scaled
    return out


def inplane_shift_maps(
    point_m: ArrayLike,
    normal: ArrayLike,
    earlier_m: ArrayLike,
    earlier_normals: ArrayLike,
    centroid_m: ArrayLike,
    scale_m: float,
    pivot_m: ArrayLike,
) -> tuple[FloatArray, FloatArray]:
    """The in-plane shift of a search at ``point_m`` after the ``earlier`` searches.

    Args:
        point_m: ``(3,)`` the search's nominal point, wobj frame, metres.
        normal: ``(3,)`` its face's unit outward normal.
        earlier_m: ``(K, 3)`` the approach searches measured before it (``K`` may be 0).
        earlier_normals: ``(K, 3)`` their faces' normals.
        centroid_m: ``(3,)`` the centroid the step-by-step update turns about (the whole
            layout's, as :func:`calib.estimators.runners.run_best_fit` uses).
        scale_m: the RMS size the update scales rotations by, metres.
        pivot_m: ``(3,)`` the misplacement's pivot, wobj frame, metres.

    Returns:
        ``(G_t, G_w)``, each ``(2, 3)``: the shift in the basis :func:`plane_basis` of
        ``normal`` is ``G_t @ t + G_w @ w`` for a misplacement translation ``t`` (m) and
        rotation vector ``w`` (rad) about ``pivot_m``.
    """
    M = _residual_motion(point_m, earlier_m, earlier_normals, centroid_m, scale_m, pivot_m)
    G = plane_basis(normal).T @ M
    return G[:, :3], G[:, 3:]


def normal_shift_maps(
    point_m: ArrayLike,
    normal: ArrayLike,
    earlier_m: ArrayLike,
    earlier_normals: ArrayLike,
    centroid_m: ArrayLike,
    scale_m: float,
    pivot_m: ArrayLike,
) -> tuple[FloatArray, FloatArray]:
    """The shift along the face normal of a search at ``point_m`` after the ``earlier``
    searches: how far from its nominal height the face lies in the frame the search is
    commanded in (the arguments as :func:`inplane_shift_maps`).

    Returns:
        ``(g_t, g_w)``, each ``(3,)``: the shift along ``normal`` is ``g_t @ t + g_w @ w``
        (m) for a misplacement translation ``t`` (m) and rotation vector ``w`` (rad) about
        ``pivot_m``; its largest size is ``a |g_t| + b |g_w|`` (:func:`normal_shift_bound`).
        With no earlier search it is the whole misplacement's shift of the face.
    """
    n = np.asarray(normal, dtype=np.float64).reshape(3)
    g = (n / np.linalg.norm(n)) @ _residual_motion(
        point_m, earlier_m, earlier_normals, centroid_m, scale_m, pivot_m
    )
    return g[:3], g[3:]


def normal_shift_bound(g_t: FloatArray, g_w: FloatArray, a: float, b: float) -> float:
    """The largest shift along the normal, metres: ``a |g_t| + b |g_w|`` for ``|t| <= a``,
    ``|w| <= b`` (exact: the two balls are independent)."""
    return float(a * np.linalg.norm(g_t) + b * np.linalg.norm(g_w))


def _noise_gain(
    point_m: ArrayLike,
    earlier_m: ArrayLike,
    earlier_normals: ArrayLike,
    centroid_m: ArrayLike,
    scale_m: float,
) -> FloatArray:
    """``(3, K)``: the displacement at ``point_m`` of the estimate per metre of error in each
    of the ``K`` earlier searches (the min-norm update's gain)."""
    u = earlier_update(earlier_m, earlier_normals, centroid_m, scale_m, centroid_m)
    out: FloatArray = _motion(point_m, u) @ u.pinv
    return out


def _variances(var_m2: ArrayLike, k: int) -> FloatArray:
    v = np.asarray(var_m2, dtype=np.float64).reshape(-1)
    if v.shape != (k,):
        raise ShapeError(f"var_m2 must be ({k},), got {v.shape}")
    return v


def normal_noise_var(
    point_m: ArrayLike,
    normal: ArrayLike,
    earlier_m: ArrayLike,
    earlier_normals: ArrayLike,
    centroid_m: ArrayLike,
    scale_m: float,
    var_m2: ArrayLike,
) -> float:
    """Variance, m^2, of the shift along the normal that the earlier searches' errors
    (variances ``var_m2`` ``(K,)``, m^2) leave through the min-norm estimate (0 with none)."""
    X = np.asarray(earlier_m, dtype=np.float64).reshape(-1, 3)
    if len(X) == 0:
        return 0.0
    v = _variances(var_m2, len(X))
    n = np.asarray(normal, dtype=np.float64).reshape(3)
    k = (n / np.linalg.norm(n)) @ _noise_gain(point_m, X, earlier_normals, centroid_m, scale_m)
    return float(np.sum(k * k * v))


def inplane_noise_cov(
    point_m: ArrayLike,
    normal: ArrayLike,
    earlier_m: ArrayLike,
    earlier_normals: ArrayLike,
    centroid_m: ArrayLike,
    scale_m: float,
    var_m2: ArrayLike,
) -> FloatArray:
    """``(2, 2)`` covariance of the in-plane shift, m^2, that the earlier searches' noise
    (variances ``var_m2`` ``(K,)``, m^2) leaves through the min-norm estimate: what a weak set
    of earlier points (two points close together fixing a rotation) amplifies."""
    X = np.asarray(earlier_m, dtype=np.float64).reshape(-1, 3)
    if len(X) == 0:
        return np.zeros((2, 2))
    v = _variances(var_m2, len(X))
    K = plane_basis(normal).T @ _noise_gain(point_m, X, earlier_normals, centroid_m, scale_m)
    return (K * v[None, :]) @ K.T


def ellipse_support(cov: FloatArray, k: float, directions: int = 32) -> FloatArray:
    """``(directions, 2)`` support points of the ``k``-sigma ellipse of ``cov`` ``(2, 2)`` in
    the directions :func:`shift_outline` uses (added to its points: the Minkowski sum)."""
    ang = np.linspace(0.0, 2.0 * np.pi, directions, endpoint=False)
    D = np.stack([np.cos(ang), np.sin(ang)], axis=1)
    CD = D @ np.asarray(cov, dtype=np.float64)
    h = np.sqrt(np.maximum(np.einsum("ij,ij->i", CD, D), 0.0))
    return k * np.divide(CD, h[:, None], out=np.zeros_like(CD), where=h[:, None] > 1e-30)


def shift_outline(
    G_t: FloatArray,
    G_w: FloatArray,
    max_translation_m: float,
    max_angle_rad: float,
    directions: int = 32,
) -> FloatArray:
    """``(directions, 2)`` points on the boundary of every in-plane shift, metres: the support
    points of ``{G_t t + G_w w : |t| <= a, |w| <= b}`` in ``directions`` spread directions
    (their convex hull lies inside the set and within ``1 - cos(pi / directions)`` of it)."""
    ang = np.linspace(0.0, 2.0 * np.pi, directions, endpoint=False)
    D = np.stack([np.cos(ang), np.sin(ang)], axis=1)  # (M, 2)
    out = np.zeros((directions, 2))
    for G, r in ((G_t, max_translation_m), (G_w, max_angle_rad)):
        U = D @ G  # (M, 3): G^T d
        norm = np.linalg.norm(U, axis=1, keepdims=True)
        U = np.divide(U, norm, out=np.zeros_like(U), where=norm > 1e-15)
        out += r * (U @ G.T)
    return out


def shift_radius(G_t: FloatArray, G_w: FloatArray, a: float, b: float) -> float:
    """The largest in-plane shift, metres: ``a ||G_t|| + b ||G_w||`` (spectral norms)."""
    return float(a * np.linalg.norm(G_t, 2) + b * np.linalg.norm(G_w, 2))
