"""Analytic inverse kinematics of ortho-parallel arms with a spherical wrist (OPW).

After Brandstötter, Kritzinger and Hofbaur (2014), "An analytical solution of the inverse
kinematics problem of industrial serial manipulators with an ortho-parallel basis and a spherical
wrist". The arm is described in its *OPW frame* by seven lengths (metres):

    a1  shoulder offset: axis 2 from axis 1, along x          c1  height of axis 2 above the frame
    a2  forearm offset: wrist centre from axis 3, across       c2  upper arm: axis 2 to axis 3
    b   lateral offset of the arm plane, along y               c3  forearm: axis 3 to wrist centre
                                                               c4  wrist centre to the end frame

In the OPW zero pose the upper arm and forearm point up (+z), axes 2, 3, 5 are along +y and axes
1, 4, 6 along +z; ``theta`` are the joint angles in that model. Robot joint values ``q`` relate to
them as in ROS-Industrial's ``opw_kinematics``::

    theta = sign_corrections * q - offsets        q = sign_corrections * (theta + offsets)

Forward kinematics, with ``theta23 = theta2 + theta3``::

    cx1 = a1 + c2 sin t2 + c3 sin t23 + a2 cos t23
    cz1 = c1 + c2 cos t2 + c3 cos t23 - a2 sin t23
    C   = Rz(t1) @ (cx1, b, cz1)                       (wrist centre)
    R   = Rz(t1) Ry(t23) Rz(t4) Ry(t5) Rz(t6)          p = C + c4 * R[:, 2]

The inverse gives up to 8 branches per pose: shoulder front/back (``theta1``), two elbow
solutions of the planar 2R problem (``theta2``, ``theta3``), and two wrist solutions (ZYZ Euler
angles of the wrist rotation, ``theta5 >= 0`` or its flip).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: Below this sin(theta5) the wrist is taken as singular and theta4 is set to 0.
WRIST_SINGULAR_SIN = 1e-10


@dataclass(frozen=True)
class OPWParameters:
    """The OPW parametrisation of a 6-axis arm.

    Attributes:
        a1, a2, b, c1, c2, c3, c4: lengths in metres (see the module docstring).
        offsets: ``(6,)`` joint offsets, rad: ``theta = sign_corrections * q - offsets``.
        sign_corrections: ``(6,)`` of +1/-1: the direction of each robot joint relative to the
            OPW model's joint.
    """

    a1: float
    a2: float
    b: float
    c1: float
    c2: float
    c3: float
    c4: float
    offsets: tuple[float, float, float, float, float, float] = (0.0,) * 6
    sign_corrections: tuple[int, int, int, int, int, int] = (1,) * 6

    def to_theta(self, q: ArrayLike) -> FloatArray:
        """OPW model angles ``(..., 6)`` of robot joint values ``q (..., 6)``, rad."""
        s = np.asarray(self.sign_corrections, dtype=float)
        return s * np.asarray(q, dtype=float) - np.asarray(self.offsets)

    def to_q(self, theta: ArrayLike) -> FloatArray:
        """Robot joint values ``(..., 6)`` of OPW model angles ``theta (..., 6)``, rad."""
        s = np.asarray(self.sign_corrections, dtype=float)
        return s * (np.asarray(theta, dtype=float) + np.asarray(self.offsets))


def _rz(t: FloatArray) -> FloatArray:
    c, s = np.cos(t), np.sin(t)
    R = np.zeros((*t.shape, 3, 3))
    R[..., 0, 0], R[..., 0, 1], R[..., 1, 0], R[..., 1, 1], R[..., 2, 2] = c, -s, s, c, 1.0
    return R


def _ry(t: FloatArray) -> FloatArray:
    c, s = np.cos(t), np.sin(t)
    R = np.zeros((*t.shape, 3, 3))
    R[..., 0, 0], R[..., 0, 2], R[..., 2, 0], R[..., 2, 2], R[..., 1, 1] = c, s, -s, c, 1.0
    return R


def wrist_centre(p: OPWParameters, theta: FloatArray) -> FloatArray:
    """Wrist centre ``(..., 3)`` in the OPW frame for model angles ``theta (..., 6)``."""
    t1, t2, t23 = theta[..., 0], theta[..., 1], theta[..., 1] + theta[..., 2]
    cx1 = p.a1 + p.c2 * np.sin(t2) + p.c3 * np.sin(t23) + p.a2 * np.cos(t23)
    cz1 = p.c1 + p.c2 * np.cos(t2) + p.c3 * np.cos(t23) - p.a2 * np.sin(t23)
    c1, s1 = np.cos(t1), np.sin(t1)
    return np.stack([cx1 * c1 - p.b * s1, cx1 * s1 + p.b * c1, cz1], axis=-1)


def opw_fk(p: OPWParameters, q: ArrayLike) -> FloatArray:
    """End-frame poses ``T_opw_ee (..., 4, 4)`` of robot joint values ``q (..., 6)``."""
    theta = p.to_theta(q)
    R = (
        _rz(theta[..., 0])
        @ _ry(theta[..., 1] + theta[..., 2])
        @ _rz(theta[..., 3])
        @ _ry(theta[..., 4])
        @ _rz(theta[..., 5])
    )
    T = np.zeros((*theta.shape[:-1], 4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = wrist_centre(p, theta) + p.c4 * R[..., :, 2]
    T[..., 3, 3] = 1.0
    return T


def wrap_angle(x: FloatArray) -> FloatArray:
    """Angles wrapped to ``[-pi, pi]`` (``x - 2 pi round(x / 2 pi)``; faster than ``%``)."""
    return x - (2.0 * np.pi) * np.rint(x * (0.5 / np.pi))


def opw_ik(p: OPWParameters, T_opw_ee: FloatArray) -> tuple[FloatArray, BoolArray]:
    """All 8 branches of the inverse kinematics of ``N`` end-frame poses ``(N, 4, 4)``.

    Branch ``k`` has bits ``4 = shoulder back``, ``2 = second elbow solution``,
    ``1 = flipped wrist`` (the geometric meaning of each is in
    :mod:`planner.kinematics.branches`). Written out element by element (no batched 3x3
    products): about a microsecond per pose for all 8 branches.

    Returns:
        ``q (N, 8, 6)`` robot joint values wrapped to ``[-pi, pi]`` (NaN where not reachable)
        (a view of a joint-major array) and ``reachable (N, 8)``: the branch exists (joint limits
        are not checked here). At a wrist singularity
        (``theta5 = 0``) ``theta4 = 0`` and ``theta6`` takes the whole rotation.
    """
    T = np.asarray(T_opw_ee, dtype=np.float64)
    N = T.shape[0]
    flat = np.ascontiguousarray(T.reshape(N, 16).T)  # (16, N): contiguous rows per entry
    r = [[flat[4 * i + j] for j in range(3)] for i in range(3)]  # R entries, (N,) each
    Cx, Cy, Cz = (flat[4 * i + 3] - p.c4 * r[i][2] for i in range(3))  # wrist centre
    r2 = Cx * Cx + Cy * Cy
    rho = np.sqrt(np.maximum(r2 - p.b**2, 0.0))  # |x1| of the wrist centre in the arm plane
    phi, lam = np.arctan2(Cy, Cx), np.arctan2(p.b, rho)
    # shoulder front (row 0) and back (row 1): theta1, arm-plane x and z of the wrist centre
    t1 = np.stack([phi - lam, phi + lam - np.pi])  # (2, N)
    x = np.stack([rho - p.a1, -rho - p.a1])
    z = Cz - p.c1
    k2 = p.a2**2 + p.c3**2
    k, psi3 = np.sqrt(k2), np.arctan2(p.a2, p.c3)
    D = (x * x + z * z - p.c2**2 - k2) / (2.0 * p.c2 * k)  # cos(theta3 + psi3)
    # clipping |D| <= 1 + 1e-14 moves the wrist centre by < 1e-11 m, so no round trip is needed
    ok2 = (r2 - p.b**2 >= -1e-18) & (np.abs(D) <= 1.0 + 1e-14)
    Dc = np.clip(D, -1.0, 1.0)
    acos_d = np.arccos(Dc)
    sin_b = np.sqrt(1.0 - Dc * Dc)
    gamma = np.arctan2(x, z)
    # arm solutions (4, N): (front, elbow 0), (front, elbow 1), (back, elbow 0), (back, elbow 1)
    beta = np.stack([acos_d[0], -acos_d[0], acos_d[1], -acos_d[1]])  # theta3 + psi3
    t2 = np.repeat(gamma, 2, axis=0) - np.arctan2(
        k * sin_b[[0, 0, 1, 1]] * np.array([1.0, -1.0, 1.0, -1.0])[:, None],
        p.c2 + k * Dc[[0, 0, 1, 1]],
    )
    t3 = beta - psi3
    t23 = t2 + t3
    t1_4 = t1[[0, 0, 1, 1]]
    ok = ok2[[0, 0, 1, 1]]
    c1, s1 = np.cos(t1), np.sin(t1)
    t4, t5, t6 = _wrist(r, c1[[0, 0, 1, 1]], s1[[0, 0, 1, 1]], np.cos(t23), np.sin(t23))
    sc, off = p.sign_corrections, p.offsets
    out = np.empty((6, 4, 2, N))  # joint-major: contiguous writes
    for j, t in enumerate((t1_4, t2, t3)):
        out[j] = wrap_angle(sc[j] * (t + off[j]))[:, None, :]
    for j, t, t_flip in ((3, t4, t4 + np.pi), (4, t5, -t5), (5, t6, t6 + np.pi)):
        out[j, :, 0] = wrap_angle(sc[j] * (t + off[j]))
        out[j, :, 1] = wrap_angle(sc[j] * (t_flip + off[j]))
    ok8 = np.repeat(ok, 2, axis=0)  # (8, N)
    q = out.reshape(6, 8, N)
    np.copyto(q, np.nan, where=~ok8[None])
    return q.transpose(2, 1, 0), np.ascontiguousarray(ok8.T)


def _wrist(
    r: list[list[FloatArray]], c1: FloatArray, s1: FloatArray, c23: FloatArray, s23: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """ZYZ angles ``(theta4, theta5 >= 0, theta6)`` of ``M = (Rz(t1) Ry(t23))^T R``.

    ``r[i][j]`` are the entries of ``R``; columns of ``Rz(t1) Ry(t23)`` are
    ``(c1 c23, s1 c23, -s23)``, ``(-s1, c1, 0)``, ``(c1 s23, s1 s23, c23)``.
    """
    c1c23, s1c23, c1s23, s1s23 = c1 * c23, s1 * c23, c1 * s23, s1 * s23

    def row(i: int, j: int) -> FloatArray:
        if i == 0:
            return c1c23 * r[0][j] + s1c23 * r[1][j] - s23 * r[2][j]
        if i == 1:
            return -s1 * r[0][j] + c1 * r[1][j]
        return c1s23 * r[0][j] + s1s23 * r[1][j] + c23 * r[2][j]

    m02, m12, m22 = row(0, 2), row(1, 2), row(2, 2)
    s5 = np.hypot(m02, m12)
    t5 = np.arctan2(s5, m22)
    singular = s5 < WRIST_SINGULAR_SIN
    t4 = np.where(singular, 0.0, np.arctan2(m12, m02))
    t6 = np.arctan2(row(2, 1), -row(2, 0))
    if np.any(singular):
        # theta5 = 0: M = Rz(t4 + t6); theta5 = pi: M = Rz(t4) Ry(pi) Rz(t6), t6 - t4 from M01, M11
        t6_sing = np.where(
            m22 > 0,
            np.arctan2(row(1, 0), row(0, 0)),
            np.arctan2(row(0, 1), row(1, 1)),
        )
        t6 = np.where(singular, t6_sing, t6)
    return t4, t5, t6
