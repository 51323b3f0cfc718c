"""The solver's fast path: OPW solutions within joint limits, wrist only where the arm fits.

:func:`opw_ik_within` gives the same solutions as :func:`planner.robot.kinematics.opw.opw_ik`
followed by the limit checks of :mod:`planner.robot.kinematics.packing`, bit for bit, but solves
the wrist (two thirds of the arithmetic: ``cos``/``sin`` of ``theta23``, the ZYZ angles) only
for the arm solutions whose axes 1-3 are within their limits (about 30 % of them on random
IRB 4400 poses: axes 2 and 3 have narrow ranges). Every value is computed by the same
operations, in the same order, as in :func:`~planner.robot.kinematics.opw.opw_ik`; only the
arrays are shorter.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from planner.robot.kinematics.opw import OPWParameters, flip_wrist, opw_arm, to_q, wrist_angles
from planner.robot.kinematics.packing import LIMIT_TOL, JointLimits, Selected, select_rows

FloatArray = NDArray[np.float64]


def opw_ik_within(
    p: OPWParameters, entries: FloatArray, limits: JointLimits, config_codes: bool = False
) -> Selected:
    """The solutions within joint limits (with 2*pi variants) of poses ``entries (16, N)``.

    Args:
        p: the OPW parameters.
        entries: the poses ``T_opw_ee`` entry-major (row ``4 i + j`` is ``T[:, i, j]``).
        limits: the robot's joint limits.
        config_codes: return configuration codes instead of OPW branch indices.
    """
    N = entries.shape[1]
    arm = opw_arm(p, entries)
    sc, off = p.sign_corrections, p.offsets
    q_arm = np.empty((3, 2, 2, N))  # robot values of axes 1-3: joint, shoulder, elbow, pose
    to_q(arm.t1[:, None], sc[0], off[0], q_arm[0, :, :1])
    q_arm[0, :, 1] = q_arm[0, :, 0]
    to_q(arm.t2, sc[1], off[1], q_arm[1])
    to_q(arm.t3, sc[2], off[2], q_arm[2])
    ok = np.empty((2, 2, N), dtype=bool)
    ok[:] = arm.ok[:, None]
    tmp = np.empty((2, 2, N), dtype=bool)
    checked = []
    for j, lo, hi in limits.simple:
        if j < 3:
            np.greater_equal(q_arm[j], lo - LIMIT_TOL, out=tmp)
            ok &= tmp
            np.less_equal(q_arm[j], hi + LIMIT_TOL, out=tmp)
            ok &= tmp
            checked.append(j)
    # the arm solutions left, pose-major: index 4 * pose + (2 * shoulder + elbow)
    cand = np.flatnonzero(ok.reshape(4, N).T)
    pose = cand >> 2
    arm_idx = cand & 3
    at = arm_idx * N
    at += pose  # into (4, N) arrays
    at_s = (arm_idx >> 1) * N
    at_s += pose  # into (2, N) arrays
    t1 = arm.t1.ravel().take(at_s)
    t23 = arm.t2.ravel().take(at)
    t23 += arm.t3.ravel().take(at)
    r = [[entries[4 * i + j].take(pose) for j in range(3)] for i in range(3)]
    t4, t5, t6 = wrist_angles(r, np.cos(t1), np.sin(t1), np.cos(t23), np.sin(t23))
    A = cand.size
    rows = np.empty((A, 2, 6))  # candidate, wrist (flip), joint
    for j in range(3):
        rows[:, :, j] = q_arm[j].reshape(4 * N).take(at)[:, None]
    tq = np.empty(A)
    for w in (0, 1):
        for j, t in zip((3, 4, 5), flip_wrist(t4, t5, t6) if w else (t4, t5, t6)):
            to_q(t, sc[j], off[j], tq)
            rows[:, w, j] = tq
    branch = np.empty((A, 2), dtype=np.intp)
    np.left_shift(arm_idx, 1, out=branch[:, 0])
    np.add(branch[:, 0], 1, out=branch[:, 1])
    return select_rows(
        limits,
        rows.reshape(2 * A, 6),
        np.ones(2 * A, dtype=bool),
        np.repeat(pose, 2),
        branch.reshape(2 * A),
        N,
        config_codes,
        checked=tuple(checked),
    )
