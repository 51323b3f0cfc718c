"""Frames, transforms and angle conventions: written once here, used everywhere.

Conventions
-----------
Units
    SI inside the code: metres and radians. Humans see millimetres and degrees (UI, reports,
    robot programs); convert only where text is read or written.
Transforms
    ``T_a_b`` is a 4x4 float64 homogeneous transform: the pose of frame ``b`` expressed in frame
    ``a``. So ``p_a = T_a_b @ p_b`` (homogeneous) and ``T_a_c = T_a_b @ T_b_c``: chain transforms
    when the inner names meet. ``R_a_b`` is the 3x3 rotation part, ``p_a_b`` (or ``origin``) the
    position of b's origin in a.
Frames
    ``world``  the cell.
    ``base``   the robot base; the paper's Robot Base Coordinate System (RBCS).
    ``wobj``   the work object; the paper's Work Object Coordinate System (WOCS).
    ``flange`` the robot flange (URDF ``tool0``).
    ``sensor`` the proximity-sensor TCP, at the sensing distance in front of the sensor face;
               its +z axis is the sensor axis, pointing from the sensor into the surface.
    Other tool TCPs are frames named after the TCP.
Quaternions
    The component order is part of the name: ``quat_xyzw`` (PyBullet, scipy) or ``quat_wxyz``
    (viser, ABB RAPID). Convert only at the edges, with :func:`quat_wxyz_to_xyzw` and
    :func:`quat_xyzw_to_wxyz`.
Euler angles
    Tait-Bryan z-y'-x'' angles ``(alpha, beta, gamma)`` as in Hultman & Leijon (2013), eq. 7-9:
    ``R = Rz(alpha) @ Ry(beta) @ Rx(gamma)``. This equals scipy's
    ``Rotation.from_euler("ZYX", [alpha, beta, gamma])`` and KUKA's A, B, C.
Small motions
    A 6-vector ``delta = (dx, dy, dz, rx, ry, rz)`` (metres, radians) is a small rigid motion of a
    frame expressed in that frame's own axes: ``T_perturbed = T @ exp(delta)`` with the rotation
    given as a rotation vector. Covariances of a frame (e.g. ``T_base_wobj``) use this order.
Randomness
    Every stochastic function takes ``rng: numpy.random.Generator``; there is no global seed.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from calib.arguments import as_float_array, check_finite
from calib.errors import DegenerateGeometryError, ShapeError

FloatArray = NDArray[np.float64]

_LAST_ROW = np.array([0.0, 0.0, 0.0, 1.0])
_EYE3 = np.eye(3)

#: Below this |cos(beta)| the Tait-Bryan decomposition is at gimbal lock and gamma is set to 0.
GIMBAL_LOCK_COS = 1e-9


def check_transform(value: ArrayLike, name: str = "T", tol: float = 1e-6) -> FloatArray:
    """Return ``value`` as a valid ``(..., 4, 4)`` rigid transform.

    Args:
        value: homogeneous transform(s).
        name: argument name used in error messages.
        tol: allowed deviation of ``R.T @ R`` from identity and of the last row from (0, 0, 0, 1).

    Raises:
        ShapeError: not ``(..., 4, 4)``, or the last row is not ``(0, 0, 0, 1)``.
        NonFiniteError: NaN or infinity.
        DegenerateGeometryError: the rotation part is not orthonormal with determinant +1.
    """
    T = as_float_array(value, name)
    if T.shape == (4, 4):  # one transform (per search and update): in plain floats
        return _check_one_transform(T, name, tol)
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise ShapeError(f"{name} must be a (4, 4) homogeneous transform, got shape {T.shape}")
    check_finite(T, name)
    # np.allclose's rule (|a - b| <= tol + 1e-5 |b|) without its overhead: called per search
    if not np.all(np.abs(T[..., 3, :] - _LAST_ROW) <= tol + 1e-5 * _LAST_ROW):
        raise ShapeError(f"{name} last row must be (0, 0, 0, 1)")
    R = T[..., :3, :3]
    ortho = np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max() if R.size else 0.0
    if ortho > tol:
        raise DegenerateGeometryError(
            f"{name} rotation part is not orthonormal (max |R^T R - I| = {ortho:.3g})"
        )
    if R.size and np.any(np.linalg.det(R) < 0):
        raise DegenerateGeometryError(f"{name} rotation part is a reflection (det < 0)")
    return T


def _check_one_transform(T: FloatArray, name: str, tol: float) -> FloatArray:
    """:func:`check_transform` of one ``(4, 4)`` array: the same tests and messages, without
    the batch's numpy passes (about 6 us instead of 18: it runs per search and per update)."""
    if not np.isfinite(T).all():
        check_finite(T, name)  # raises, naming the first bad entry
    w0, w1, w2, w3 = T[3].tolist()
    if not (abs(w0) <= tol and abs(w1) <= tol and abs(w2) <= tol and abs(w3 - 1.0) <= tol + 1e-5):
        raise ShapeError(f"{name} last row must be (0, 0, 0, 1)")
    R = T[:3, :3]
    ortho = float(np.abs(R.T @ R - _EYE3).max())
    if ortho > tol:
        raise DegenerateGeometryError(
            f"{name} rotation part is not orthonormal (max |R^T R - I| = {ortho:.3g})"
        )
    (a0, a1, a2), (b0, b1, b2), (c0, c1, c2) = R.tolist()
    if a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0) < 0.0:
        raise DegenerateGeometryError(f"{name} rotation part is a reflection (det < 0)")
    return T


def make_transform(R: ArrayLike | None = None, p: ArrayLike | None = None) -> FloatArray:
    """Build ``T`` from a rotation ``R`` (3x3, default identity) and a translation ``p`` (m).

    Broadcasts over leading dimensions: ``R (..., 3, 3)`` and ``p (..., 3)``.
    """
    R_arr = np.eye(3) if R is None else np.asarray(R, dtype=np.float64)
    p_arr = np.zeros(3) if p is None else np.asarray(p, dtype=np.float64)
    lead = np.broadcast_shapes(R_arr.shape[:-2], p_arr.shape[:-1])
    T = np.zeros((*lead, 4, 4))
    T[..., :3, :3] = R_arr
    T[..., :3, 3] = p_arr
    T[..., 3, 3] = 1.0
    return T


def invert_transform(T: ArrayLike) -> FloatArray:
    """Return ``T^-1`` of rigid transform(s) ``(..., 4, 4)`` exactly (``R^T``, ``-R^T p``)."""
    T_arr = np.asarray(T, dtype=np.float64)
    R_t = np.swapaxes(T_arr[..., :3, :3], -1, -2)
    out = np.zeros_like(T_arr)
    out[..., :3, :3] = R_t
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", R_t, T_arr[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def transform_points(T_a_b: ArrayLike, p_b: ArrayLike) -> FloatArray:
    """Map points ``p_b (..., 3)`` given in frame b to frame a: ``p_a = R p_b + t``."""
    T = np.asarray(T_a_b, dtype=np.float64)
    p = np.asarray(p_b, dtype=np.float64)
    return np.einsum("...ij,...j->...i", T[..., :3, :3], p) + T[..., :3, 3]


def transform_directions(T_a_b: ArrayLike, v_b: ArrayLike) -> FloatArray:
    """Rotate directions ``v_b (..., 3)`` from frame b to frame a (no translation)."""
    T = np.asarray(T_a_b, dtype=np.float64)
    return np.einsum("...ij,...j->...i", T[..., :3, :3], np.asarray(v_b, dtype=np.float64))


def matrix_from_tait_bryan_zyx(alpha: ArrayLike, beta: ArrayLike, gamma: ArrayLike) -> FloatArray:
    """Rotation ``Rz(alpha) @ Ry(beta) @ Rx(gamma)`` (radians), shape ``(..., 3, 3)``.

    The inverse of :func:`tait_bryan_zyx_from_matrix`; same as scipy's ``from_euler("ZYX")``.
    """
    a, b, g = np.broadcast_arrays(
        np.asarray(alpha, float), np.asarray(beta, float), np.asarray(gamma, float)
    )
    ca, sa, cb, sb, cg, sg = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(g), np.sin(g)
    R = np.empty((*a.shape, 3, 3))
    R[..., 0, 0] = ca * cb
    R[..., 0, 1] = ca * sb * sg - sa * cg
    R[..., 0, 2] = ca * sb * cg + sa * sg
    R[..., 1, 0] = sa * cb
    R[..., 1, 1] = sa * sb * sg + ca * cg
    R[..., 1, 2] = sa * sb * cg - ca * sg
    R[..., 2, 0] = -sb
    R[..., 2, 1] = cb * sg
    R[..., 2, 2] = cb * cg
    return R


def tait_bryan_zyx_from_matrix(R: ArrayLike) -> FloatArray:
    """Tait-Bryan z-y'-x'' angles ``(alpha, beta, gamma)`` in radians, paper eq. 7-9.

    ``beta = atan2(-R31, sqrt(R11^2 + R21^2))`` lies in [-pi/2, pi/2];
    ``alpha = atan2(R21 / cos(beta), R11 / cos(beta))``;
    ``gamma = atan2(R32 / cos(beta), R33 / cos(beta))``.
    At gimbal lock (``|cos(beta)| < GIMBAL_LOCK_COS``) only ``alpha -+ gamma`` is defined; then
    ``gamma = 0`` and ``alpha = atan2(-R12, R22)``, which still reproduces ``R`` exactly.

    Args:
        R: rotation matrix or matrices, ``(..., 3, 3)``.

    Returns:
        ``(..., 3)`` array of ``(alpha, beta, gamma)``.
    """
    Rm = as_float_array(R, "R")
    if Rm.ndim < 2 or Rm.shape[-2:] != (3, 3):
        raise ShapeError(f"R must be (..., 3, 3), got {Rm.shape}")
    check_finite(Rm, "R")
    cb = np.sqrt(Rm[..., 0, 0] ** 2 + Rm[..., 1, 0] ** 2)
    beta = np.arctan2(-Rm[..., 2, 0], cb)
    locked = cb < GIMBAL_LOCK_COS
    # cos(beta) = cb >= 0, so dividing both atan2 arguments by it does not change the angle
    alpha = np.where(
        locked, np.arctan2(-Rm[..., 0, 1], Rm[..., 1, 1]), np.arctan2(Rm[..., 1, 0], Rm[..., 0, 0])
    )
    gamma = np.where(locked, 0.0, np.arctan2(Rm[..., 2, 1], Rm[..., 2, 2]))
    return np.stack([alpha, beta, gamma], axis=-1)


def quat_xyzw_to_wxyz(q_xyzw: ArrayLike) -> FloatArray:
    """Reorder quaternion(s) from (x, y, z, w) to (w, x, y, z)."""
    return np.roll(np.asarray(q_xyzw, dtype=np.float64), 1, axis=-1)


def quat_wxyz_to_xyzw(q_wxyz: ArrayLike) -> FloatArray:
    """Reorder quaternion(s) from (w, x, y, z) to (x, y, z, w)."""
    return np.roll(np.asarray(q_wxyz, dtype=np.float64), -1, axis=-1)


def quat_wxyz_from_matrix(R: ArrayLike) -> FloatArray:
    """Unit quaternion(s) ``(..., 4)`` in (w, x, y, z) order with ``w >= 0``."""
    q = quat_xyzw_to_wxyz(Rotation.from_matrix(np.asarray(R, float)).as_quat())
    return np.where(q[..., :1] < 0, -q, q)


def quat_xyzw_from_matrix(R: ArrayLike) -> FloatArray:
    """Unit quaternion(s) ``(..., 4)`` in (x, y, z, w) order with ``w >= 0``."""
    return quat_wxyz_to_xyzw(quat_wxyz_from_matrix(R))


def matrix_from_quat_wxyz(q_wxyz: ArrayLike) -> FloatArray:
    """Rotation matrix ``(..., 3, 3)`` from quaternion(s) in (w, x, y, z) order (normalised)."""
    q = check_finite(as_float_array(q_wxyz, "q_wxyz"), "q_wxyz")
    if q.shape[-1:] != (4,):
        raise ShapeError(f"q_wxyz must be (..., 4), got {q.shape}")
    if np.any(np.linalg.norm(q, axis=-1) < 1e-12):
        raise DegenerateGeometryError("q_wxyz must not be the zero quaternion")
    return Rotation.from_quat(quat_wxyz_to_xyzw(q)).as_matrix()


def matrix_from_quat_xyzw(q_xyzw: ArrayLike) -> FloatArray:
    """Rotation matrix ``(..., 3, 3)`` from quaternion(s) in (x, y, z, w) order (normalised)."""
    return matrix_from_quat_wxyz(quat_xyzw_to_wxyz(q_xyzw))


def transform_from_pos_quat_xyzw(p: ArrayLike, q_xyzw: ArrayLike) -> FloatArray:
    """``T`` from a position (m) and an (x, y, z, w) quaternion, e.g. PyBullet link states."""
    return make_transform(matrix_from_quat_xyzw(q_xyzw), p)


def rotvec_from_matrix(R: ArrayLike) -> FloatArray:
    """Rotation vector(s) ``(..., 3)`` (axis times angle, radians) of rotation matrices."""
    return Rotation.from_matrix(np.asarray(R, float)).as_rotvec()


def matrix_from_rotvec(rotvec: ArrayLike) -> FloatArray:
    """Rotation matrices ``(..., 3, 3)`` from rotation vector(s) (axis times angle, radians)."""
    return Rotation.from_rotvec(np.asarray(rotvec, float)).as_matrix()


def small_motion(delta: ArrayLike) -> FloatArray:
    """Transform of a small motion ``delta = (dx, dy, dz, rx, ry, rz)`` (m, rad), ``(..., 4, 4)``.

    The rotation is the rotation vector ``(rx, ry, rz)``; the translation is ``(dx, dy, dz)``.
    ``T @ small_motion(delta)`` moves frame T by ``delta`` expressed in T's own axes.
    """
    d = np.asarray(delta, dtype=np.float64)
    if d.shape[-1:] != (6,):
        raise ShapeError(f"delta must be (..., 6), got {d.shape}")
    return make_transform(matrix_from_rotvec(d[..., 3:]), d[..., :3])


def motion_between(T_a_b: ArrayLike, T_a_c: ArrayLike) -> FloatArray:
    """The 6-vector ``delta`` with ``T_a_c = T_a_b @ small_motion(delta)`` (inverse of above).

    Useful for errors of an estimated frame against the truth, in the truth's own axes.
    """
    T_b_c = invert_transform(T_a_b) @ np.asarray(T_a_c, dtype=np.float64)
    if T_b_c.shape == (4, 4):  # one pair (a simulated trial asks for two): in plain floats
        rv = _small_rotvec(T_b_c[:3, :3].tolist())
        if rv is not None:
            return np.array([*T_b_c[:3, 3].tolist(), *rv])
    return np.concatenate([T_b_c[..., :3, 3], rotvec_from_matrix(T_b_c[..., :3, :3])], axis=-1)


def _small_rotvec(R: list[list[float]]) -> tuple[float, float, float] | None:
    """The rotation vector of one rotation matrix of less than 90 degrees (rad), from its
    antisymmetric part ``sin(angle) * axis`` and ``cos(angle) = (trace - 1) / 2``, in plain
    floats (about 2 us against scipy's 45); ``None`` for larger rotations, a trace above 3
    and NaN: left to scipy, which orthogonalises or refuses it. A scaled rotation with a
    trace below 3 is read as a rotation (no orthonormality test: trials pass rigid frames).
    Within a few units in the last place of :func:`rotvec_from_matrix` (tested):
    a threshold on a motion's size (an iterative procedure's convergence test) can move by
    that much, no more."""
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = R
    c = 0.5 * (r00 + r11 + r22 - 1.0)
    if not 0.0 < c <= 1.0 + 1e-9:  # 90 degrees or more, no rotation, NaN: scipy's path
        return None
    x, y, z = 0.5 * (r21 - r12), 0.5 * (r02 - r20), 0.5 * (r10 - r01)
    s = math.sqrt(x * x + y * y + z * z)
    if s == 0.0:
        return 0.0, 0.0, 0.0
    k = math.atan2(s, c) / s
    return x * k, y * k, z * k


def random_transform(
    rng: np.random.Generator, max_translation_m: float, max_angle_rad: float
) -> FloatArray:
    """A random rigid motion: translation uniform in a ball, rotation about a random axis.

    Args:
        rng: the random generator.
        max_translation_m: largest translation, metres.
        max_angle_rad: largest rotation angle, radians.
    """
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    t = direction * max_translation_m * rng.uniform() ** (1.0 / 3.0)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    angle = rng.uniform(-max_angle_rad, max_angle_rad)
    return make_transform(matrix_from_rotvec(axis * angle), t)
