"""The simulated error over the part: how far off each surface point is placed, at a level.

For surface points ``p`` of the part (wobj) and the trials' frame errors ``delta``, the error
of ``p`` placed with a calibrated frame is ``T_true^-1 T_calibrated p - p``
(:func:`planner.sim.rows.point_errors`); the map gives, per point, the radius that the given
share of calibrations keep that error within (the empirical quantile of its length, bias
included: the distance from the true point, not the scatter). ``--plots`` draws it
(``error_map.png``) and the UI paints it on the mesh.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import trimesh
from numpy.typing import NDArray

from planner.sim.report_points import surface_samples
from planner.sim.rows import error_motion, point_errors

FloatArray = NDArray[np.float64]

#: Surface samples of the map.
N_MAP_POINTS = 2000
#: At most this many trials enter the map (a subsample keeps it fast and small).
MAX_MAP_TRIALS = 2000


@dataclass(frozen=True)
class ErrorMap:
    """The error over the part.

    Attributes:
        points_wobj: ``(M, 3)`` surface points, wobj frame, metres.
        error_m: ``(M,)`` the ``level_percent`` quantile of each point's error length, m.
        level_percent: the share of calibrations within ``error_m``, percent.
    """

    points_wobj: FloatArray = field(repr=False)
    error_m: FloatArray = field(repr=False)
    level_percent: float


def error_quantiles(delta: FloatArray, points_wobj: FloatArray, level_percent: float) -> FloatArray:
    """``(M,)`` the ``level_percent`` quantile of the error length of each point, m.

    Args:
        delta: ``(n, 6)`` frame errors of the trials (m, rad); at most
            :data:`MAX_MAP_TRIALS` evenly spaced ones are used.
        points_wobj: ``(M, 3)`` points, wobj frame, metres.
        level_percent: the quantile, percent.
    """
    d = np.asarray(delta, dtype=np.float64)
    if len(d) > MAX_MAP_TRIALS:
        d = d[np.linspace(0, len(d) - 1, MAX_MAP_TRIALS).astype(int)]
    P = np.asarray(points_wobj, dtype=np.float64)
    out = np.full(len(P), np.nan)
    if len(d) == 0:
        return out
    motion = error_motion(d)
    for i in range(0, len(P), 500):
        length = np.linalg.norm(point_errors(d, P[i : i + 500], motion), axis=2)  # (n, m)
        out[i : i + 500] = np.quantile(length, level_percent / 100.0, axis=0)
    return out


def error_map(delta: FloatArray, mesh: trimesh.Trimesh, level_percent: float = 95.5) -> ErrorMap:
    """The error at :data:`N_MAP_POINTS` surface points of ``mesh`` (fixed seed)."""
    pts = surface_samples(mesh, N_MAP_POINTS)
    return ErrorMap(pts, error_quantiles(delta, pts, level_percent), level_percent)
