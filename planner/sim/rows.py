"""The report's rows: what each one measures, its samples, and its predicted spread.

A row is a quantity of the calibrated frame's error (:class:`RowSpec`): a frame component
(origin x/y/z in metres, rotation about x/y/z in radians, the rotation vector of
``T_true^-1 T_calibrated``), or the error of points fixed on the part (a point of interest, or
a region pooled over many points) measured by ``components`` (see
:mod:`calib.plan.report_spec`: one signed axis, or a length signed by the remaining axis).

From simulated frame errors ``delta`` ``(n, 6)`` a row's samples are taken about their mean
(each point's error centred on its own mean, then pooled), so the interval is the scatter
``+- z sigma`` and the mean goes to the bias column, as the paper took the mean of its
calibrations as the truth (:func:`samples_and_bias`). The *predicted* spread applies the same
measure to a Gaussian frame error with the covariance the procedure's linearisation gives
(:func:`predicted_sigma`): exact for frame rows and single axes, and for lengths from a fixed
set of standard normal draws for the (small) mean of the signed length.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from calib.estimators.layout import point_motion_jacobian
from calib.frames import small_motion

FloatArray = NDArray[np.float64]

#: Frame rows: key, label, index into ``delta``, unit.
FRAME_ROWS: tuple[tuple[str, str, int, str], ...] = (
    ("origin_x", "WOCS origin x-axis", 0, "mm"),
    ("origin_y", "WOCS origin y-axis", 1, "mm"),
    ("origin_z", "WOCS origin z-axis", 2, "mm"),
    ("rot_x", "WOCS rotation x-axis", 3, "deg"),
    ("rot_y", "WOCS rotation y-axis", 4, "deg"),
    ("rot_z", "WOCS rotation z-axis", 5, "deg"),
)
#: SI -> display unit.
SCALE = {"mm": 1e3, "deg": float(np.degrees(1.0))}
_AXIS = {"x": 0, "y": 1, "z": 2}
#: Standard normal draws for the mean of a signed length (fixed: the prediction is exact
#: up to this sample's error, about 0.7 % of sigma in the mean, far less in the spread).
_NORMALS = np.random.default_rng(20131023).standard_normal((20000, 3))


@dataclass(frozen=True)
class RowSpec:
    """One quantity of the report.

    Attributes:
        key: row key, e.g. ``"origin_x"``, ``"yz_epsilon"``.
        label: the row's name for humans.
        unit: display unit, ``"mm"`` or ``"deg"``.
        levels_percent: confidence levels, percent.
        frame_index: index into ``delta`` for a frame row, else ``None``.
        points_wobj: ``(M, 3)`` points fixed on the part, wobj frame, metres (point rows).
        components: how a point's error is measured (point rows).
        offset_m: ``(M, 3)`` subtracted from each point's error (a known deviation of the
            true part from the targets, e.g. the stator's bulge at the slot holes), or None.
    """

    key: str
    label: str
    unit: str
    levels_percent: tuple[float, ...]
    frame_index: int | None = None
    points_wobj: FloatArray | None = field(default=None, repr=False)
    components: str = "xyz"
    offset_m: FloatArray | None = field(default=None, repr=False)


def _points(spec: RowSpec) -> FloatArray:
    if spec.points_wobj is None:
        raise ValueError(f"row {spec.key!r} is neither a frame row nor a point row")
    return spec.points_wobj


def frame_rows(levels_percent: tuple[float, ...]) -> list[RowSpec]:
    """The six frame rows at ``levels_percent``."""
    return [RowSpec(k, lab, unit, levels_percent, frame_index=i) for k, lab, i, unit in FRAME_ROWS]


def measure(errors: FloatArray, components: str) -> FloatArray:
    """The signed error measure of error vectors ``(..., 3)`` (see :mod:`calib.plan.report_spec`).

    One axis: that component. A plane (two axes): the length in it, signed by the remaining
    axis (zero counts as positive). ``"xyz"``: the full length, signed by x.
    """
    if len(components) == 1:
        return errors[..., _AXIS[components]]
    axes = [_AXIS[c] for c in components]
    sign_axis = 0 if components == "xyz" else next(i for i in range(3) if i not in axes)
    length = _length(errors, axes)
    return np.where(errors[..., sign_axis] >= 0.0, length, -length)


def _length(errors: FloatArray, axes: list[int]) -> FloatArray:
    """The length of error vectors ``(..., 3)`` in ``axes``: ``numpy.linalg.norm`` of them,
    summed in its order, without its reduction over a short last axis (the slow part of a
    report row's millions of samples)."""
    total = errors[..., axes[0]] * errors[..., axes[0]]
    for k in axes[1:]:
        total += errors[..., k] * errors[..., k]
    return np.sqrt(total)


def _unsigned(errors: FloatArray, components: str) -> FloatArray:
    if len(components) == 1:
        return errors[..., _AXIS[components]]
    return _length(errors, [_AXIS[c] for c in components])


#: Samples (trials x points) whose error vectors one step of :func:`samples_and_bias` holds at
#: once: the row's transients stay ~100 MB whatever its trials and points (issue 27).
CHUNK_SAMPLES = 500_000


#: ``(R - I, t)`` of frame errors: ``(n, 3, 3)`` and ``(n, 3)`` (:func:`error_motion`).
ErrorMotion = tuple[FloatArray, FloatArray]


def error_motion(delta: FloatArray) -> ErrorMotion:
    """``(R - I, t)`` of the motions ``T_true_est = small_motion(delta)`` of frame errors
    ``(n, 6)`` (m, rad): what :func:`point_errors` applies, computed once for many points (a
    point's error ``(R - I) p + t``: one matmul, no ``R p - p`` of two near-equal arrays)."""
    T = small_motion(delta)  # T_true_est, (n, 4, 4)
    return T[:, :3, :3] - np.eye(3), T[:, :3, 3].copy()


def point_errors(
    delta: FloatArray, p_wobj: FloatArray, motion: ErrorMotion | None = None
) -> FloatArray:
    """Errors ``(n, M, 3)`` of wobj points ``(M, 3)`` under frame errors ``(n, 6)`` (exact):
    ``(R - I) p + t`` of each trial's error motion (``motion``: :func:`error_motion` of
    ``delta`` when the caller has it), metres."""
    R_minus_I, t = error_motion(delta) if motion is None else motion
    return np.matmul(p_wobj, R_minus_I.transpose(0, 2, 1)) + t[:, None, :]


def samples_and_bias(
    spec: RowSpec, delta: FloatArray, point_err: FloatArray | None = None
) -> tuple[FloatArray, float]:
    """A row's centred samples (SI) and its bias (SI) from frame errors ``(n, 6)``.

    Args:
        spec: the row.
        delta: ``(n, 6)`` frame errors of the trials (m, rad).
        point_err: ``(n, M, 3)`` the point errors when they are not those of ``delta`` at
            ``spec.points_wobj`` (e.g. targets corrected by the x-offset matrix), or None.

    Returns:
        ``(samples, bias)``: frame rows: the component about its mean and the mean; point rows:
        each point's error centred on its mean, measured and pooled, and the mean over the
        points of the measure of each point's mean error (a length without sign for planes).
    """
    if spec.frame_index is not None:
        x = delta[:, spec.frame_index]
        return x - x.mean(), float(x.mean())
    pts = _points(spec) if point_err is None else np.zeros((0, 3))
    n, m = (len(delta), len(pts)) if point_err is None else point_err.shape[:2]
    samples = np.empty((n, m))
    means = np.empty((m, 3))
    step = max(1, CHUNK_SAMPLES // max(n, 1))  # a few points at a time: bounded transients
    motion = error_motion(delta) if point_err is None and m else None
    for i in range(0, m, step):
        j = min(i + step, m)
        e = point_errors(delta, pts[i:j], motion) if point_err is None else point_err[:, i:j]
        if spec.offset_m is not None:
            e = e - spec.offset_m[i:j]
        means[i:j] = e.mean(axis=0)
        samples[:, i:j] = measure(e - means[i:j], spec.components)
    return samples.ravel(), float(np.mean(_unsigned(means, spec.components)))


def predicted_sigma(spec: RowSpec, cov: FloatArray) -> float:
    """The row's predicted standard deviation (SI) for a Gaussian frame error of covariance
    ``cov`` ``(6, 6)`` (point rows: pooled over the points as the samples are)."""
    if spec.frame_index is not None:
        return float(np.sqrt(max(float(cov[spec.frame_index, spec.frame_index]), 0.0)))
    J = point_motion_jacobian(_points(spec))  # (M, 3, 6)
    S = np.einsum("mik,kl,mjl->mij", J, cov, J)  # (M, 3, 3)
    return point_sigma(S, spec.components)


def z_values(levels_percent: tuple[float, ...]) -> FloatArray:
    """``z = Phi^-1(0.5 + P / 2)`` of each level ``P`` (percent): a row's half-width is
    ``z * sigma``."""
    from scipy.special import ndtri

    return np.asarray(ndtri(0.5 + np.asarray(levels_percent) / 200.0), dtype=np.float64)


def point_sigma(S: FloatArray, components: str) -> float:
    """Pooled standard deviation of the measure of Gaussian errors with covariances
    ``(M, 3, 3)`` (SI)."""
    if len(components) == 1:
        k = _AXIS[components]
        return float(np.sqrt(max(float(np.mean(S[:, k, k])), 0.0)))
    axes = [_AXIS[c] for c in components]
    second = np.trace(S[:, axes][:, :, axes], axis1=1, axis2=2)  # E[s^2] per point
    w, V = np.linalg.eigh(0.5 * (S + np.transpose(S, (0, 2, 1))))
    L = V * np.sqrt(np.maximum(w, 0.0))[:, None, :]  # S = L L^T
    # E[s] per point from the fixed draws, fewer of them for many points (a pooled mean)
    normals = _NORMALS[: max(200, len(_NORMALS) // len(S))]
    first = np.concatenate(
        [
            measure(np.einsum("mij,nj->mni", L[i : i + 50], normals), components).mean(axis=1)
            for i in range(0, len(S), 50)
        ]
    )
    var = float(np.mean(second)) - float(np.mean(first)) ** 2
    return float(np.sqrt(max(var, 0.0)))
