"""Derive OPW parameters from a URDF chain, or say precisely why the arm is not OPW.

The joint axes are read as lines in the base frame in the reference pose ``q = 0``. The chain
qualifies when it has 6 revolute joints, axis 2 is perpendicular to axis 1, axes 2 and 3 are
parallel, axis 4 is perpendicular to them, and axes 4, 5, 6 meet in one point (the wrist centre)
with 4 perpendicular to 5 and 5 perpendicular to 6. Then:

* the OPW frame has its origin on axis 1 (closest to the base origin), ``z`` along axis 1
  (pointing towards axis 2, so that ``c1 >= 0``) and ``y`` along axis 2 (flipped if needed so
  that the shoulder offset ``a1`` points along ``+x``, the robot's "front");
* ``a1, c1`` are the coordinates of axis 2, ``c2`` the distance from axis 2 to axis 3; the
  forearm direction (axis 4, pointing from axis 3 to the wrist centre ``C``) gives ``c3`` (along
  it) and ``a2`` (across it), ``b`` is ``C``'s ``y``; ``c4`` is the flange origin's distance from
  ``C`` along axis 6;
* sign corrections compare each URDF axis with the OPW model's axis; offsets are minus the OPW
  angles of the reference pose (``theta = s * q - offset``); ``theta6`` of the reference pose is
  absorbed in the constant tip transform ``T_ee_tip``.

The result is verified: OPW forward kinematics must reproduce the chain's at random poses within
:data:`VERIFY_TOL_M`, else the chain is refused with the error found.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from calib.errors import WobjcalError
from calib.frames import invert_transform
from planner.robot.kinematics.chain import KinematicChain
from planner.robot.kinematics.opw import OPWParameters, opw_fk
from planner.robot.kinematics.opw_robot import OPWRobot

FloatArray = NDArray[np.float64]

#: Tolerance of the geometric tests: metres for distances, radians (as sines) for angles.
GEOM_TOL = 1e-7
#: Largest disagreement (m, and 1 for rotation-matrix entries) between OPW FK and chain FK.
VERIFY_TOL_M = 1e-9


class NotOPWError(WobjcalError):
    """The chain is not an ortho-parallel arm with a spherical wrist; the message says why."""


def _line_distance(p1: FloatArray, u1: FloatArray, p2: FloatArray, u2: FloatArray) -> float:
    """Shortest distance between two lines (point, unit direction)."""
    n = np.cross(u1, u2)
    d = p2 - p1
    if np.linalg.norm(n) < 1e-12:  # parallel
        return float(np.linalg.norm(d - (d @ u1) * u1))
    return float(abs(d @ n) / np.linalg.norm(n))


def _angle_deg(u: FloatArray, v: FloatArray) -> float:
    return float(np.degrees(np.arccos(np.clip(abs(u @ v), 0.0, 1.0))))


def opw_from_chain(
    chain: KinematicChain,
    rng: np.random.Generator | None = None,
    tol: float = GEOM_TOL,
    verify_tol: float = VERIFY_TOL_M,
) -> OPWRobot:
    """The OPW model of ``chain`` (``T_base_tip`` identical to ``chain.fk`` within 1e-9).

    Args:
        chain: a 6-axis chain, tip at the flange.
        rng: generator of the verification poses (default: a fixed seed).
        tol: tolerance of the geometric tests (m, or sine of an angle).
        verify_tol: largest FK disagreement accepted (m, and 1 for rotation entries). Looser
            values give an *approximate* model of a nearly-OPW arm (e.g. a URDF with rpy
            rounded to ``1.5708``) whose solutions the solver then polishes numerically.

    Raises:
        NotOPWError: the chain does not qualify; the message names the failing condition and
            its size, e.g. ``"axes 4-6 do not meet in one point: axes 4 and 6 are 0.0947 m
            apart (offset wrist, UR-style)"``.
    """
    types = chain.joint_types
    if chain.n_joints != 6:
        raise NotOPWError(f"OPW needs 6 revolute joints; the chain has {chain.n_joints}")
    if "prismatic" in types:
        raise NotOPWError(
            f"OPW needs revolute joints; {chain.joint_names[types.index('prismatic')]!r} "
            "is prismatic"
        )
    F = chain.joint_frames(np.zeros(6))[0]
    u = np.einsum("kij,kj->ki", F[:, :3, :3], chain.axes)
    P = F[:, :3, 3]
    if abs(u[0] @ u[1]) > tol:
        raise NotOPWError(
            f"axis 2 is not perpendicular to axis 1 (angle {90 - _angle_deg(u[0], u[1]):.4g} deg)"
        )
    if np.linalg.norm(np.cross(u[1], u[2])) > tol:
        raise NotOPWError(f"axes 2 and 3 are not parallel (angle {_angle_deg(u[1], u[2]):.4g} deg)")
    d45 = _line_distance(P[3], u[3], P[4], u[4])
    d56 = _line_distance(P[4], u[4], P[5], u[5])
    d46 = _line_distance(P[3], u[3], P[5], u[5])
    worst = max((d45, "4 and 5"), (d56, "5 and 6"), (d46, "4 and 6"))
    if worst[0] > tol:
        raise NotOPWError(
            f"axes 4-6 do not meet in one point: axes {worst[1]} are {worst[0]:.4g} m apart "
            "(offset wrist, UR-style)"
        )
    for i, j in ((3, 4), (4, 5), (3, 1)):
        if abs(u[i] @ u[j]) > tol:
            raise NotOPWError(
                f"axis {i + 1} is not perpendicular to axis {j + 1} "
                f"(angle {90 - _angle_deg(u[i], u[j]):.4g} deg off)"
            )
    # wrist centre: least-squares point of lines 4, 5, 6
    A = sum(np.eye(3) - np.outer(v, v) for v in u[3:])
    C = np.linalg.solve(A, sum((np.eye(3) - np.outer(v, v)) @ p for v, p in zip(u[3:], P[3:])))
    tip = chain.fk(np.zeros(6))[0]

    O = P[0] - (P[0] @ u[0]) * u[0]  # axis-1 point closest to the base origin
    z0 = -u[0] if (P[1] - O) @ u[0] < -GEOM_TOL else u[0]  # "up": axis 2 above the origin
    for flip in (1.0, -1.0):
        y_perp = u[1] - (u[1] @ z0) * z0  # exactly perpendicular (nearly-OPW arms)
        y0 = flip * y_perp / np.linalg.norm(y_perp)
        x0 = np.cross(y0, z0)
        T_base_opw = np.eye(4)
        T_base_opw[:3, 0], T_base_opw[:3, 1], T_base_opw[:3, 2], T_base_opw[:3, 3] = x0, y0, z0, O
        R0 = T_base_opw[:3, :3]
        p2, p3, c, f_tip = (R0.T @ (v - O) for v in (P[1], P[2], C, tip[:3, 3]))
        a1 = p2[0]
        if a1 > GEOM_TOL or (abs(a1) <= GEOM_TOL and c[0] >= 0):
            break
    c1 = p2[2]
    dx, dz = p3[0] - a1, p3[2] - c1
    c2 = float(np.hypot(dx, dz))
    th2 = np.arctan2(dx, dz)
    d = np.array([c[0] - p3[0], c[2] - p3[2]])
    u4 = R0.T @ u[3]
    along = d @ u4[[0, 2]]
    if c2 < GEOM_TOL or abs(along) < GEOM_TOL:
        raise NotOPWError(
            f"degenerate arm: upper arm {c2:.4g} m, forearm along axis 4 {along:.4g} m"
        )
    s4 = 1.0 if along > 0 else -1.0
    f = s4 * u4
    phi = np.arctan2(f[0], f[2])  # theta2 + theta3 of the reference pose
    c3 = abs(along)
    a2 = d @ np.array([np.cos(phi), -np.sin(phi)])
    b = c[1]
    Ry_phi = _ry(phi)
    v5 = Ry_phi.T @ (R0.T @ u[4])
    s5 = -1.0 if v5[1] < 0 else 1.0  # keeps |theta4| <= 90 deg in the reference pose
    th4 = np.arctan2(-s5 * v5[0], s5 * v5[1])
    c4_signed = (f_tip - c) @ (R0.T @ u[5])
    s6 = -1.0 if c4_signed < -GEOM_TOL else 1.0
    w = _rz(th4).T @ Ry_phi.T @ (s6 * (R0.T @ u[5]))
    th5 = np.arctan2(w[0], w[2])
    c4 = abs(c4_signed)
    signs = (_sign(u[0] @ z0), _sign(u[1] @ y0), _sign(u[2] @ y0), _sign(s4), _sign(s5), _sign(s6))
    theta_ref = np.array([0.0, th2, phi - th2, th4, th5, 0.0])
    L = {
        k: _snap(float(v), 1e-9)
        for k, v in zip(("a1", "a2", "b", "c1", "c2", "c3", "c4"), (a1, a2, b, c1, c2, c3, c4))
    }
    o1, o2, o3, o4, o5, o6 = (_snap(float(-t), np.pi / 2) for t in theta_ref)
    params = OPWParameters(**L, offsets=(o1, o2, o3, o4, o5, o6), sign_corrections=signs)
    T_ee_tip = invert_transform(opw_fk(params, np.zeros(6))) @ invert_transform(T_base_opw) @ tip
    T_ee_tip[np.abs(T_ee_tip) < 1e-15] = 0.0  # exact identity when it is one (fast path)
    T_ee_tip[np.abs(T_ee_tip - 1.0) < 1e-15] = 1.0
    robot = OPWRobot(params, T_base_opw, T_ee_tip, chain.lower.copy(), chain.upper.copy())
    _verify(chain, robot, rng or np.random.default_rng(6), verify_tol)
    return robot


def _verify(
    chain: KinematicChain, robot: OPWRobot, rng: np.random.Generator, verify_tol: float
) -> None:
    q = rng.uniform(-np.pi, np.pi, (64, 6))
    err = np.abs(robot.fk(q) - chain.fk(q)).max()
    if not err <= verify_tol:
        raise NotOPWError(
            f"the derived OPW model does not reproduce the chain's forward kinematics "
            f"(max error {err:.3g}); the axes are only nearly ortho-parallel"
        )


def _snap(x: float, grid: float) -> float:
    """``x`` rounded to a multiple of ``grid`` when within 1e-12 of it (cosmetic; FK unchanged)."""
    r = round(x, 9) if grid == 1e-9 else round(x / grid) * grid
    return float(r) + 0.0 if abs(x - r) < 1e-12 else x


def _sign(x: float) -> int:
    return -1 if x < 0 else 1


def _rz(t: float) -> FloatArray:
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _ry(t: float) -> FloatArray:
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def why_not_opw(chain: KinematicChain) -> str | None:
    """``None`` when ``chain`` is an OPW arm, else the reason it is not."""
    try:
        opw_from_chain(chain)
    except NotOPWError as exc:
        return str(exc)
    return None
