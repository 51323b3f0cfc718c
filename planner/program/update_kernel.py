"""The frame update of a steered program, compiled (numba): the loop
:func:`calib.estimators.runners.min_norm_update` computes, for the simulation's hot path.

Every steered program's update runs here (:func:`planner.program.steering.steer`): the simulated
trials of ``wobjcal validate`` (ten updates a trial for the plate's best fit), the landing risk
of ``wobjcal check`` and the design of ``wobjcal suggest``. Written with numpy calls, as
``calib`` keeps it (pure numpy and scipy: the reference, and what ``wobjcal calibrate`` and
the procedures' own runs use), it spends about 0.4 ms an update in small-array overhead; this
loop takes about 30 us. The controller writers carry the same iteration in their languages
(:mod:`planner.export.rapid_steer` and the others); all of them are held to ``calib``'s.

The step of each iteration is the minimum-norm least-squares solution in the fixed motions
``V``: ``step = -V pinv(J V) r``, with the pseudo-inverse's cut-off at :data:`RCOND` of the
largest singular value (``numpy.linalg.pinv(..., rcond=RCOND)``). The singular values come from
a one-sided Jacobi SVD of the ``(M, r)`` matrix ``J V`` (``r <= 6``), written out here: it
compiles in a third of the time numba's LAPACK binding takes. Where the iteration converges the
frames agree with ``calib``'s to about 1e-15 (``tests/planner/program/test_update_kernel.py``
holds the two together over random layouts); where it does not (a misplacement far beyond the
layout's reach), neither frame means anything and the two may differ.

numba takes its cache directory when this module is imported, which
:func:`~planner.program.steering.steer` does at its first call (a process that has opened a
cell has pointed numba at wobjcal's cache by then, :mod:`planner.cell.kernels.kernel_cache`; a
validation's workers load it in their fork server, :mod:`planner.sim.worker_preload`), and
compiles the kernel, or loads it from that cache, at its first call.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

#: Relative cut-off of the pseudo-inverse's singular values (as ``numpy.linalg.pinv``'s
#: ``rcond``).
RCOND = 1e-9
#: An iteration whose step is below this (scaled motion, m) is the last: the estimate only
#: steers the next search, 1 nm is far below any sensor.
STEP_TOL_M = 1e-9
#: Jacobi sweeps at most (random full-rank, rank-deficient and wide matrices of up to 6
#: columns take at most 12: ``tests/planner/program/test_update_kernel.py``).
MAX_SWEEPS = 60
#: A pair of columns counts as orthogonal when ``|u_p . u_q| <= ORTHO_TOL |u_p| |u_q|``.
ORTHO_TOL = 1e-15
#: A column shorter than this part of the longest is left out of the rotations: its singular
#: value is cut anyway (far below :data:`RCOND`), and rounding would keep rotating it (and
#: another such column) until :data:`MAX_SWEEPS`.
NULL_COLUMN = 1e-12


@numba.njit(cache=True, nogil=True, error_model="numpy")
def min_norm_solve(A: Any, b: Any) -> tuple[Any, int]:  # pragma: no cover - compiled
    """``((r,) pinv(A, rcond=RCOND) @ b, sweeps)`` of an ``(M, r)`` matrix and ``(M,)``
    vector, by one-sided Jacobi (``sweeps``: how many it took, at most :data:`MAX_SWEEPS`)."""
    m, r = A.shape
    U = A.copy()
    W = np.eye(r)
    sweeps = 0
    for _ in range(MAX_SWEEPS):
        sweeps += 1
        rotated = False
        longest = 0.0  # the longest column's squared norm
        for k in range(r):
            acc = 0.0
            for i in range(m):
                acc += U[i, k] * U[i, k]
            longest = max(longest, acc)
        for p in range(r - 1):
            for q in range(p + 1, r):
                alpha = 0.0
                beta = 0.0
                gamma = 0.0
                for i in range(m):
                    alpha += U[i, p] * U[i, p]
                    beta += U[i, q] * U[i, q]
                    gamma += U[i, p] * U[i, q]
                if abs(gamma) <= ORTHO_TOL * math.sqrt(alpha * beta):
                    continue
                if min(alpha, beta) <= NULL_COLUMN * NULL_COLUMN * longest:
                    continue
                rotated = True
                zeta = (beta - alpha) / (2.0 * gamma)
                t = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + math.sqrt(1.0 + zeta * zeta))
                c = 1.0 / math.sqrt(1.0 + t * t)
                s = c * t
                for i in range(m):
                    up, uq = U[i, p], U[i, q]
                    U[i, p] = c * up - s * uq
                    U[i, q] = s * up + c * uq
                for i in range(r):
                    wp, wq = W[i, p], W[i, q]
                    W[i, p] = c * wp - s * wq
                    W[i, q] = s * wp + c * wq
        if not rotated:
            break
    sv = np.empty(r)
    largest = 0.0
    for k in range(r):
        acc = 0.0
        for i in range(m):
            acc += U[i, k] * U[i, k]
        sv[k] = math.sqrt(acc)
        largest = max(largest, sv[k])
    y = np.zeros(r)
    for k in range(r):
        if sv[k] > RCOND * largest:
            ub = 0.0
            for i in range(m):
                ub += U[i, k] * b[i]
            ub /= sv[k] * sv[k]  # U's columns are sigma_k u_k
            for j in range(r):
                y[j] += W[j, k] * ub
    return y, sweeps


@numba.njit(cache=True, nogil=True, error_model="numpy")
def gauss_newton(
    T0: Any,
    q: Any,
    normals: Any,
    nominal: Any,
    c: Any,
    L: float,
    V: Any,
    iterations: int,
) -> Any:  # pragma: no cover - compiled
    """``(4, 4)`` the estimate after up to ``iterations`` minimum-norm Gauss-Newton steps.

    Args:
        T0: ``(4, 4)`` the estimate to start from, base frame (checked by the caller).
        q: ``(M, 3)`` each constraint's measured point, base frame, m.
        normals: ``(M, 3)`` unit constraint normals, wobj frame.
        nominal: ``(M, 3)`` each constraint's nominal point, wobj frame, m.
        c: ``(3,)`` the pivot the rotations are taken about, wobj frame, m.
        L: the length that scales rotations to translations, m.
        V: ``(6, r)`` orthonormal basis of the scaled motions the step may take.
        iterations: at most this many steps.
    """
    T = T0.copy()
    m = q.shape[0]
    r = V.shape[1]
    A = np.empty((m, r))
    res = np.empty(m)
    J = np.empty(6)
    M = np.eye(4)
    for _ in range(iterations):
        for i in range(m):
            d0, d1, d2 = q[i, 0] - T[0, 3], q[i, 1] - T[1, 3], q[i, 2] - T[2, 3]
            x0 = d0 * T[0, 0] + d1 * T[1, 0] + d2 * T[2, 0]  # (q - t) R: the point in wobj
            x1 = d0 * T[0, 1] + d1 * T[1, 1] + d2 * T[2, 1]
            x2 = d0 * T[0, 2] + d1 * T[1, 2] + d2 * T[2, 2]
            n0, n1, n2 = normals[i, 0], normals[i, 1], normals[i, 2]
            res[i] = (n0 * (x0 - nominal[i, 0]) + n1 * (x1 - nominal[i, 1])) + n2 * (
                x2 - nominal[i, 2]
            )
            a0, a1, a2 = x0 - c[0], x1 - c[1], x2 - c[2]
            J[0], J[1], J[2] = -n0, -n1, -n2  # constraint_jacobian's row, rotations / L
            J[3] = -(a1 * n2 - a2 * n1) / L
            J[4] = -(a2 * n0 - a0 * n2) / L
            J[5] = -(a0 * n1 - a1 * n0) / L
            for j in range(r):
                acc = 0.0
                for k in range(6):
                    acc += J[k] * V[k, j]
                A[i, j] = acc
        y, _ = min_norm_solve(A, res)
        step = np.empty(6)
        big = 0.0
        for k in range(6):
            acc = 0.0
            for j in range(r):
                acc += V[k, j] * y[j]
            step[k] = -acc
            big = max(big, abs(step[k]))
        w0, w1, w2 = step[3] / L, step[4] / L, step[5] / L
        # small_motion_matrix of (step[:3] - w x c, w): Rodrigues' formula
        theta = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        if theta < 1e-8:
            sa, ca = 1.0 - theta * theta / 6.0, 0.5 - theta * theta / 24.0
        else:
            sa, ca = math.sin(theta) / theta, (1.0 - math.cos(theta)) / (theta * theta)
        K = np.array([[0.0, -w2, w1], [w2, 0.0, -w0], [-w1, w0, 0.0]])
        for i in range(3):
            for j in range(3):
                kk = K[i, 0] * K[0, j] + K[i, 1] * K[1, j] + K[i, 2] * K[2, j]
                M[i, j] = (1.0 if i == j else 0.0) + sa * K[i, j] + ca * kk
        M[0, 3] = step[0] - (w1 * c[2] - w2 * c[1])
        M[1, 3] = step[1] - (w2 * c[0] - w0 * c[2])
        M[2, 3] = step[2] - (w0 * c[1] - w1 * c[0])
        Tn = np.empty((4, 4))
        for i in range(4):
            for j in range(4):
                Tn[i, j] = (T[i, 0] * M[0, j] + T[i, 1] * M[1, j]) + (
                    T[i, 2] * M[2, j] + T[i, 3] * M[3, j]
                )
        T = Tn
        if big < STEP_TOL_M:
            break
    return T


def load_kernel() -> None:
    """Load (or compile) the kernel now, for the argument types
    :func:`~planner.program.steering.steer` passes: a fork server does it once for all its
    workers (:mod:`planner.sim.worker_preload`)."""
    V = np.eye(6)[:, :3].copy()
    gauss_newton(np.eye(4), np.zeros((3, 3)), np.eye(3), np.zeros((3, 3)), np.zeros(3), 1.0, V, 1)
