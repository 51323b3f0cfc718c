"""The covariance of any procedure's frame, by propagating measurement noise through it.

A procedure's :meth:`~calib.procedures.base.ProcedureKind.estimate` is a smooth function of the
measured points. Its Jacobian, taken by central differences (each coordinate of each
measurement, retakes included, moved by ``+-step_m``), maps the measurement noise to the frame:
``cov = sigma^2 J J^T`` for isotropic noise ``sigma`` per coordinate. The frame's error is the
small motion ``delta = (dx, dy, dz, rx, ry, rz)`` with ``T = T_est @ small_motion(delta)``, in
the estimated frame's own axes (:func:`calib.frames.motion_between`), so the covariance is
comparable with :attr:`calib.estimators.best_fit.BestFitResult.covariance`, which the same
propagation reproduces for ``best_fit`` (a test checks it).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from calib.arguments import check_positive
from calib.frames import motion_between
from calib.procedures.base import ProcedureKind, RolePoint

FloatArray = NDArray[np.float64]

#: Step of the central differences, metres (the estimates are exact to ~1e-12 m).
STEP_M = 1e-6


def propagated_covariance(
    kind: ProcedureKind,
    points: Sequence[RolePoint],
    measured: Mapping[str, FloatArray],
    T_base_wobj_nominal: FloatArray,
    settings: object,
    sigma_m: float,
    step_m: float = STEP_M,
) -> FloatArray:
    """``(6, 6)`` covariance of ``kind.estimate`` for isotropic noise ``sigma_m`` per coordinate.

    Args:
        kind: the procedure.
        points: the plan's points with roles.
        measured: ``{id: (k, 3)}`` every measurement of each measured point, base frame, m.
        T_base_wobj_nominal: ``(4, 4)`` the nominal frame.
        settings: the procedure's settings (as for ``estimate``).
        sigma_m: noise of each measured coordinate, metres.
        step_m: central-difference step, metres.

    Returns:
        Order ``(dx, dy, dz, rx, ry, rz)`` in the estimated frame's axes (m^2, m rad, rad^2).
    """
    sigma = check_positive(sigma_m, "sigma_m", allow_zero=True)
    base = {k: np.asarray(v, dtype=np.float64).reshape(-1, 3) for k, v in measured.items()}
    T0 = kind.estimate(points, base, T_base_wobj_nominal, settings).T_base_wobj
    columns = []
    for pid, rows in base.items():
        for r in range(rows.shape[0]):
            for c in range(3):
                d = []
                for s in (step_m, -step_m):
                    moved = {k: v.copy() for k, v in base.items()}
                    moved[pid][r, c] += s
                    T = kind.estimate(points, moved, T_base_wobj_nominal, settings).T_base_wobj
                    d.append(motion_between(T0, T))
                columns.append((d[0] - d[1]) / (2.0 * step_m))
    J = np.array(columns, dtype=np.float64).T.reshape(6, -1)
    cov = sigma**2 * (J @ J.T)
    return 0.5 * (cov + cov.T)


__all__ = ["STEP_M", "propagated_covariance"]
