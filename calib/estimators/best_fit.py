"""Least-squares best fit of measured points to their nominal faces, with covariance.

Every constraint row (one per face a point lies on; two for an edge point) gives the residual
``r = n . (T_wobj_base q - p)``: the signed distance of the measured point ``q`` (base frame)
from the nominal face through ``p`` with unit normal ``n`` (wobj frame). The frame is found by
Gauss-Newton on a small motion ``delta`` of the current estimate,
``T_base_wobj <- T_base_wobj @ small_motion(delta)``, with Levenberg-Marquardt damping only if a
step fails to lower the cost. With ``J`` the ``(M, 6)`` Jacobian at the solution and isotropic
measurement noise of standard deviation ``sigma`` per coordinate, the covariance of ``delta`` is
``sigma^2 A J^T W J A`` with ``A = (J^T J)^-1`` and ``W`` block diagonal ``N N^T`` over each
point's constraint normals; it equals ``sigma^2 (J^T J)^-1`` when each point's normals are
orthogonal (always for single-face points).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.arguments import (
    as_float_array,
    check_finite,
    check_points,
    check_positive,
    check_vector3,
)
from calib.errors import ShapeError
from calib.estimators.layout import (
    ConstraintSet,
    constraint_jacobian,
    constraint_set,
    cross_rows,
    point_motion_jacobian,
    small_motion_matrix,
)
from calib.estimators.observability import analyze_layout, require_observable, unobservable_error
from calib.frames import check_transform, small_motion
from calib.probing import ProbePoint

FloatArray = NDArray[np.float64]

#: Smallest eigenvalue of the scaled normal matrix accepted (squared singular value).
RANK_TOL_SQ = 1e-12


@dataclass(frozen=True)
class BestFitResult:
    """The least-squares frame and its uncertainty.

    Attributes:
        T_base_wobj: ``(4, 4)`` the fitted work-object frame in the robot base frame.
        point_ids: ``(N,)`` ids of the fitted points.
        residual_ids: ``(M,)`` id of the point each residual belongs to.
        residuals_m: ``(M,)`` signed point-to-face distances at the solution, metres
            (positive outside the nominal face, along its outward normal).
        rms_m: root mean square of ``residuals_m``, metres.
        sigma_m: measurement standard deviation used for ``covariance``, metres: the one
            given, else the a-posteriori estimate ``sqrt(sum r^2 / (M - 6))`` (0 when
            ``M == 6``: no redundancy to estimate it from).
        unit_covariance: ``(6, 6)`` covariance of the frame for ``sigma = 1``, order
            ``(dx, dy, dz, rx, ry, rz)`` in the frame's own axes (m^2/m^2, rad^2/m^2).
        covariance: ``(6, 6)`` ``sigma_m**2 * unit_covariance`` (m^2, m rad, rad^2).
        iterations: Gauss-Newton iterations taken.
        converged: True when the last step was below the tolerance.
    """

    T_base_wobj: FloatArray
    point_ids: tuple[str, ...]
    residual_ids: tuple[str, ...]
    residuals_m: FloatArray
    rms_m: float
    sigma_m: float
    unit_covariance: FloatArray
    covariance: FloatArray
    iterations: int
    converged: bool

    def predicted_error(self, p_wobj: ArrayLike, sigma_m: float | None = None) -> FloatArray:
        """``(3, 3)`` covariance of the position error of a point fixed in the wobj frame.

        Args:
            p_wobj: ``(3,)`` the point in the wobj frame, metres, e.g. the paper's
                ``epsilon = (0, -1.0, -0.1)``.
            sigma_m: measurement standard deviation, metres (default: ``self.sigma_m``).

        Returns:
            The covariance (m^2) in the wobj frame's axes.
        """
        p = check_vector3(p_wobj, "p_wobj")
        s2 = (self.sigma_m if sigma_m is None else check_positive(sigma_m, "sigma_m", True)) ** 2
        Jp = point_motion_jacobian(p)
        return s2 * (Jp @ self.unit_covariance @ Jp.T)

    def predicted_sigma(
        self, p_wobj: ArrayLike, direction: ArrayLike, sigma_m: float | None = None
    ) -> float:
        """Standard deviation (m) of a wobj point's error along a wobj-frame ``direction``."""
        d = check_vector3(direction, "direction")
        nd = float(np.linalg.norm(d))
        if nd < 1e-12:
            raise ShapeError("direction must not be the zero vector")
        d = d / nd
        return float(np.sqrt(d @ self.predicted_error(p_wobj, sigma_m) @ d))


def best_fit(
    points: Sequence[ProbePoint] | ConstraintSet,
    measured_base: ArrayLike,
    T_base_wobj_guess: ArrayLike,
    *,
    sigma_m: float | None = None,
    max_iterations: int = 30,
    tol: float = 1e-12,
) -> BestFitResult:
    """Fit the wobj frame to measured points by point-to-plane least squares.

    Args:
        points: the nominal probe points (or a prepared :class:`ConstraintSet`, faster in loops).
        measured_base: ``(N, 3)`` measured points in the order of ``points``, base frame, metres.
        T_base_wobj_guess: ``(4, 4)`` start estimate, e.g. the nominal pose or a 3-2-1 result.
        sigma_m: measurement standard deviation per coordinate, metres; ``None`` estimates it
            from the residuals.
        max_iterations: largest number of Gauss-Newton iterations.
        tol: convergence threshold on the step (m, and rad times the layout size).

    Raises:
        ShapeError: ``measured_base`` does not have one row per point.
        NonFiniteError: NaN or infinity in the inputs.
        UnobservableError: the layout leaves a motion unconstrained (named in the message).
    """
    cs = constraint_set(points)
    q = check_points(measured_base, "measured_base")
    if q.shape[0] != cs.n_points:
        raise ShapeError(
            f"measured_base must have one row per point ({cs.n_points}), got {q.shape[0]}"
        )
    T = check_transform(T_base_wobj_guess, "T_base_wobj_guess").copy()
    if sigma_m is not None:
        sigma_m = check_positive(sigma_m, "sigma_m", allow_zero=True)
    qm = q[cs.point_index]
    L, c = cs.scale_m, cs.centroid_m

    def evaluate(T: FloatArray) -> tuple[FloatArray, FloatArray]:
        x = (qm - T[:3, 3]) @ T[:3, :3]
        return np.einsum("ij,ij->i", cs.normals, x - cs.nominal_m), x

    r, x = evaluate(T)
    cost = float(r @ r)
    lam = 0.0
    converged = False
    it = 0
    for it in range(1, max_iterations + 1):
        # rotations about the layout centroid, scaled by its size: a well conditioned system
        J = constraint_jacobian(cs.normals, x - c)
        J[:, 3:] /= L
        H = J.T @ J
        if it == 1 and np.linalg.eigvalsh(H)[0] < RANK_TOL_SQ * max(1.0, float(np.trace(H))):
            raise unobservable_error(analyze_layout(cs), "the best-fit point layout")
        g = J.T @ r
        while True:
            step = -np.linalg.solve(H + lam * np.diag(np.diag(H)) if lam else H, g)
            w = np.asarray(step[3:] / L, dtype=np.float64)
            move = small_motion_matrix(np.concatenate([step[:3] - cross_rows(w, c), w]))
            T_new = np.matmul(T, move)
            r_new, x_new = evaluate(T_new)
            cost_new = float(r_new @ r_new)
            if cost_new <= cost * (1.0 + 1e-9) + 1e-30 or lam > 1e8:
                break
            lam = max(1e-6, 10.0 * lam)
        T, r, x, cost = T_new, r_new, x_new, cost_new
        lam *= 0.1 if lam > 1e-6 else 0.0
        if float(np.max(np.abs(step))) < tol:
            converged = True
            break
    J = constraint_jacobian(cs.normals, x)
    unit_cov = _sandwich_covariance(J, cs)
    m = cs.n_constraints
    if sigma_m is None:
        sigma_m = float(np.sqrt(cost / (m - 6))) if m > 6 else 0.0
    return BestFitResult(
        T_base_wobj=T,
        point_ids=cs.point_ids,
        residual_ids=cs.constraint_ids,
        residuals_m=r,
        rms_m=float(np.sqrt(cost / m)),
        sigma_m=sigma_m,
        unit_covariance=unit_cov,
        covariance=sigma_m**2 * unit_cov,
        iterations=it,
        converged=converged,
    )


def _sandwich_covariance(J: FloatArray, cs: ConstraintSet) -> FloatArray:
    """``A J^T W J A`` with ``A = (J^T J)^-1`` and ``W = N N^T`` per point (isotropic noise)."""
    A = np.linalg.inv(J.T @ J)
    # noise on a point q enters each of its residuals through its normal: W_ij = n_i . n_j when
    # constraints i and j come from the same point, else 0
    same = cs.point_index[:, None] == cs.point_index[None, :]
    W = np.where(same, cs.normals @ cs.normals.T, 0.0)
    B = A @ J.T
    cov = B @ W @ B.T
    return 0.5 * (cov + cov.T)


@dataclass(frozen=True)
class BatchFitResult:
    """Best fits of many measurement sets of one layout (e.g. Monte Carlo runs).

    Attributes:
        T_base_wobj: ``(K, 4, 4)`` the fitted frames, base frame.
        rms_m: ``(K,)`` RMS of each fit's point-to-face residuals, metres.
        converged: ``(K,)`` True where the last Gauss-Newton step was below the tolerance.
        iterations: Gauss-Newton iterations run (the same for all fits).
    """

    T_base_wobj: FloatArray
    rms_m: FloatArray
    converged: NDArray[np.bool_]
    iterations: int


def best_fit_many(
    points: Sequence[ProbePoint] | ConstraintSet,
    measured_base: ArrayLike,
    T_base_wobj_guess: ArrayLike,
    *,
    max_iterations: int = 30,
    tol: float = 1e-12,
) -> BatchFitResult:
    """:func:`best_fit` for ``K`` measurement sets at once, vectorised over the sets.

    Plain Gauss-Newton (no damping), for guesses within a few centimetres and degrees of the
    truth; the covariance depends only on the layout and pose, so take it from one
    :func:`best_fit` call.

    Args:
        points: the nominal probe points (or a prepared :class:`ConstraintSet`).
        measured_base: ``(K, N, 3)`` measured points, base frame, metres.
        T_base_wobj_guess: ``(4, 4)`` or ``(K, 4, 4)`` start estimate(s).
        max_iterations: largest number of iterations.
        tol: convergence threshold on the step (m, and rad times the layout size).

    Raises:
        ShapeError: ``measured_base`` is not ``(K, N, 3)`` or the guesses do not match ``K``.
        NonFiniteError: NaN or infinity in the inputs.
        UnobservableError: the layout leaves a motion unconstrained.
    """
    cs = constraint_set(points)
    q = check_finite(as_float_array(measured_base, "measured_base"), "measured_base")
    if q.ndim != 3 or q.shape[1:] != (cs.n_points, 3):
        raise ShapeError(f"measured_base must be (K, {cs.n_points}, 3), got {q.shape}")
    k = q.shape[0]
    T0 = check_transform(T_base_wobj_guess, "T_base_wobj_guess")
    if T0.shape not in ((4, 4), (k, 4, 4)):
        raise ShapeError(f"T_base_wobj_guess must be (4, 4) or ({k}, 4, 4), got {T0.shape}")
    require_observable(cs)
    T = np.broadcast_to(T0, (k, 4, 4)).copy()
    qm = q[:, cs.point_index]
    L, c, n = cs.scale_m, cs.centroid_m, cs.normals
    step = np.full((k, 6), np.inf)
    it = 0
    for it in range(1, max_iterations + 1):  # noqa: B007
        x = np.einsum("kmj,kji->kmi", qm - T[:, None, :3, 3], T[:, :3, :3])
        r = np.einsum("mj,kmj->km", n, x - cs.nominal_m)
        J = np.empty((*r.shape, 6))
        J[..., :3] = -n
        J[..., 3:] = -cross_rows(x - c, n) / L
        H = np.einsum("kmi,kmj->kij", J, J)
        g = np.einsum("kmi,km->ki", J, r)
        step = -np.linalg.solve(H, g[..., None])[..., 0]
        w = step[:, 3:] / L
        T = T @ small_motion(np.concatenate([step[:, :3] - cross_rows(w, c), w], axis=1))
        if float(np.max(np.abs(step))) < tol:
            break
    x = np.einsum("kmj,kji->kmi", qm - T[:, None, :3, 3], T[:, :3, :3])
    r = np.einsum("mj,kmj->km", n, x - cs.nominal_m)
    return BatchFitResult(
        T_base_wobj=T,
        rms_m=np.sqrt(np.mean(r * r, axis=1)),
        converged=np.max(np.abs(step), axis=1) < tol,
        iterations=it,
    )
