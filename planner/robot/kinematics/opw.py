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
    :mod:`planner.robot.kinematics.branches`). Written out element by element (no batched 3x3
    products): well under a microsecond per pose for all 8 branches.

    Returns:
        ``q (N, 8, 6)`` robot joint values wrapped to ``[-pi, pi]`` (NaN where not reachable)
        (a view of a branch-major array) and ``reachable (N, 8)``: the branch exists (joint
        limits are not checked here). At a wrist singularity
        (``theta5 = 0``) ``theta4 = 0`` and ``theta6`` takes the whole rotation.
    """
    T = np.asarray(T_opw_ee, dtype=np.float64)
    N = T.shape[0]
    q, ok8 = opw_ik_entries(p, np.ascontiguousarray(T.reshape(N, 16).T))
    np.copyto(q, np.nan, where=~ok8[..., None])
    return q.transpose(1, 0, 2), np.ascontiguousarray(ok8.T)


def opw_ik_entries(p: OPWParameters, entries: FloatArray) -> tuple[FloatArray, BoolArray]:
    """:func:`opw_ik` of poses given entry-major: ``entries[4 i + j]`` is ``T[:, i, j]``, (16, N).

    The layout the arithmetic wants (each matrix entry contiguous). Bit for bit the same joint
    values as :func:`opw_ik`.

    Returns:
        ``q (8, N, 6)``: branch-major rows of joint values (branch
        ``4 * shoulder + 2 * elbow + wrist``), any finite value where not reachable, and
        ``reachable (8, N)``.
    """
    arm = opw_arm(p, entries)
    N = entries.shape[1]
    c1, s1 = np.cos(arm.t1)[:, None], np.sin(arm.t1)[:, None]
    t23 = arm.t2 + arm.t3
    r = [[entries[4 * i + j] for j in range(3)] for i in range(3)]
    t4, t5, t6 = wrist_angles(r, c1, s1, np.cos(t23), np.sin(t23))
    sc, off = p.sign_corrections, p.offsets
    out = np.empty((2, 2, 2, N, 6))  # shoulder, elbow, wrist, pose, joint
    tmp = np.empty((2, 2, N))
    to_q(arm.t1[:, None], sc[0], off[0], tmp[:, :1])
    out[..., 0] = tmp[:, :1, None]
    for j, t in ((1, arm.t2), (2, arm.t3)):
        to_q(t, sc[j], off[j], tmp)
        out[..., j] = tmp[:, :, None]
    for w in (0, 1):
        for j, t in zip((3, 4, 5), flip_wrist(t4, t5, t6) if w else (t4, t5, t6)):
            to_q(t, sc[j], off[j], tmp)
            out[:, :, w, :, j] = tmp
    ok8 = np.empty((2, 2, 2, N), dtype=bool)
    ok8[:] = arm.ok[:, None, None, :]
    return out.reshape(8, N, 6), ok8.reshape(8, N)


@dataclass(frozen=True)
class ArmAngles:
    """Model angles of the arm (axes 1-3) of ``N`` poses, all 4 arm solutions.

    Attributes:
        t1: ``(2, N)`` theta1, rad: shoulder front, back.
        t2, t3: ``(2, 2, N)`` theta2, theta3, rad: shoulder, elbow (+acos, -acos).
        ok: ``(2, N)`` the wrist centre is reachable with that shoulder (both elbows).
    """

    t1: FloatArray
    t2: FloatArray
    t3: FloatArray
    ok: BoolArray


def opw_arm(p: OPWParameters, entries: FloatArray) -> ArmAngles:
    """The arm part of the IK: axes 1-3 from the wrist centre, entries ``(16, N)`` as in
    :func:`opw_ik_entries`."""
    N = entries.shape[1]
    Cx, Cy, Cz = (entries[4 * i + 3] - p.c4 * entries[4 * i + 2] for i in range(3))
    r2 = Cx * Cx
    r2 += Cy * Cy
    rho = np.maximum(r2 - p.b**2, 0.0)
    np.sqrt(rho, out=rho)  # |x1| of the wrist centre in the arm plane
    phi = np.arctan2(Cy, Cx)
    # shoulder front (row 0) and back (row 1): theta1, arm-plane x and z of the wrist centre
    t1 = np.empty((2, N))
    if p.b == 0.0:  # atan2(0, rho >= 0) is 0: skip it, same values
        t1[0] = phi
        np.subtract(phi, np.pi, out=t1[1])
    else:
        lam = np.arctan2(p.b, rho)
        np.subtract(phi, lam, out=t1[0])
        np.add(phi, lam, out=t1[1])
        t1[1] -= np.pi
    x = np.empty((2, N))
    np.subtract(rho, p.a1, out=x[0])
    np.negative(rho, out=x[1])
    x[1] -= p.a1
    z = Cz - p.c1
    k2 = p.a2**2 + p.c3**2
    k, psi3 = np.sqrt(k2), np.arctan2(p.a2, p.c3)
    D = x * x
    D += z * z
    D -= p.c2**2
    D -= k2
    D /= 2.0 * p.c2 * k  # cos(theta3 + psi3), (2, N)
    # clipping |D| <= 1 + 1e-14 moves the wrist centre by < 1e-11 m, so no round trip is needed
    ok2 = np.abs(D) <= 1.0 + 1e-14
    ok2 &= r2 - p.b**2 >= -1e-18
    Dc = np.clip(D, -1.0, 1.0, out=D)
    acos_d = np.arccos(Dc)
    sin_b = Dc * Dc
    np.subtract(1.0, sin_b, out=sin_b)
    np.sqrt(sin_b, out=sin_b)
    sin_b *= k
    # arm solutions (2, 2, N): shoulder (front, back) x elbow (+acos, -acos)
    den = Dc * k
    den += p.c2
    t2 = np.empty((2, 2, N))
    np.arctan2(sin_b, den, out=t2[:, 0])
    np.negative(sin_b, out=sin_b)
    np.arctan2(sin_b, den, out=t2[:, 1])
    np.subtract(np.arctan2(x, z)[:, None], t2, out=t2)  # gamma - atan2(+-k sin b, c2 + k cos b)
    t3 = np.empty((2, 2, N))
    np.subtract(acos_d, psi3, out=t3[:, 0])
    np.negative(acos_d, out=t3[:, 1])
    t3[:, 1] -= psi3
    return ArmAngles(t1, t2, t3, ok2)


def flip_wrist(
    t4: FloatArray, t5: FloatArray, t6: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The other wrist solution ``(t4 + pi, -t5, t6 + pi)``, computed in the arrays given."""
    t4 += np.pi
    np.negative(t5, out=t5)
    t6 += np.pi
    return t4, t5, t6


def to_q(theta: FloatArray, sign: float, offset: float, out: FloatArray) -> None:
    """``out[...] = wrap_angle(sign * (theta + offset))``, computed in ``out``."""
    np.add(theta, offset, out=out)
    out *= sign
    tmp = out * (0.5 / np.pi)
    np.rint(tmp, out=tmp)
    tmp *= 2.0 * np.pi
    out -= tmp


def wrist_angles(
    r: list[list[FloatArray]], c1: FloatArray, s1: FloatArray, c23: FloatArray, s23: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """ZYZ angles ``(theta4, theta5 >= 0, theta6)`` of ``M = (Rz(t1) Ry(t23))^T R``.

    ``r[i][j]`` are the entries of ``R``; columns of ``Rz(t1) Ry(t23)`` are
    ``(c1 c23, s1 c23, -s23)``, ``(-s1, c1, 0)``, ``(c1 s23, s1 s23, c23)``. ``c1, s1`` are
    ``(2, 1, N)`` (shoulder), ``c23, s23`` ``(2, 2, N)``: row 1 of ``M`` is computed per
    shoulder only. The returned arrays are new and may be modified.
    """
    c1c23, s1c23, c1s23, s1s23 = c1 * c23, s1 * c23, c1 * s23, s1 * s23
    neg_s1 = -s1
    tmp = np.empty_like(c23)

    def row(i: int, j: int) -> FloatArray:
        # the same operations, in the same order, as c1c23 * r0 + s1c23 * r1 - s23 * r2 etc.
        if i == 1:
            m = neg_s1 * r[0][j]
            m += c1 * r[1][j]
            return m
        a, b, c = (c1c23, s1c23, s23) if i == 0 else (c1s23, s1s23, c23)
        m = a * r[0][j]
        np.multiply(b, r[1][j], out=tmp)
        m += tmp
        np.multiply(c, r[2][j], out=tmp)
        if i == 0:
            m -= tmp
        else:
            m += tmp
        return m

    m02, m12, m22 = row(0, 2), row(1, 2), row(2, 2)
    s5 = np.hypot(m02, m12)
    t5 = np.arctan2(s5, m22)
    singular = s5 < WRIST_SINGULAR_SIN
    t4 = np.arctan2(m12, m02)
    m20 = row(2, 0)
    np.negative(m20, out=m20)
    t6 = np.arctan2(row(2, 1), m20)
    if np.any(singular):
        # theta5 = 0: M = Rz(t4 + t6); theta5 = pi: M = Rz(t4) Ry(pi) Rz(t6), t6 - t4 from M01, M11
        t4[singular] = 0.0
        t6_sing = np.where(
            m22 > 0,
            np.arctan2(row(1, 0), row(0, 0)),
            np.arctan2(row(0, 1), row(1, 1)),
        )
        t6 = np.where(singular, t6_sing, t6)
    return t4, t5, t6
