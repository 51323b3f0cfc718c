"""Confidence intervals as in Table 1 of Hultman & Leijon (2013), and the paper's error conventions.

For samples ``x`` of an error (e.g. 400 calibrations of the WOCS origin's y coordinate) the
normal-distribution interval at confidence level ``P`` is ``mean +- z sigma`` with
``z = Phi^-1(0.5 + P / 2)`` (``scipy.stats.norm.ppf``) and ``sigma`` the sample standard deviation
(ddof = 1). Beside it stands the empirical ``P`` quantile of ``|x - mean|``, which needs at
least ``1 / (1 - P)`` samples to mean anything (flagged as unresolved otherwise).

Section 4 of the paper measures the positioning error in the WOCS yz-plane and in xyz-space as
a signed distance: "the displacement is defined as positive if the displacement is positive in
the x-axis of the WOCS". :func:`signed_radial_error` implements that convention.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.arguments import as_float_array, check_finite, check_vector3
from calib.errors import ShapeError
from calib.frames import check_transform, invert_transform, motion_between, transform_points

FloatArray = NDArray[np.float64]
Unit = Literal["m", "rad"]

#: The confidence levels of the paper's Table 1, as fractions.
CONFIDENCE_LEVELS: tuple[float, ...] = (0.955, 0.99, 0.999, 0.9999, 0.99999, 0.999999)
_HUMAN = {"m": (1e3, "mm"), "rad": (float(np.rad2deg(1.0)), "deg")}


@dataclass(frozen=True)
class ConfidenceRow:
    """One quantity at one confidence level.

    Attributes:
        quantity: what was sampled, e.g. ``"WOCS yz-plane at epsilon"``.
        unit: ``"m"`` or ``"rad"``: the SI unit of every value in this row.
        level: confidence level as a fraction, e.g. ``0.9999``.
        n_samples: number of samples.
        mean: sample mean.
        std: sample standard deviation (ddof = 1).
        z: ``norm.ppf(0.5 + level / 2)``.
        half_width: ``z * std``: the interval is ``mean +- half_width``.
        empirical_half_width: the ``level`` quantile of ``|x - mean|``.
        empirical_resolved: True when ``n_samples * (1 - level) >= 1``, i.e. at least one
            sample is expected outside the interval; otherwise the empirical value is just
            (close to) the sample maximum.
    """

    quantity: str
    unit: Unit
    level: float
    n_samples: int
    mean: float
    std: float
    z: float
    half_width: float
    empirical_half_width: float
    empirical_resolved: bool

    @property
    def lower(self) -> float:
        """``mean - half_width``."""
        return self.mean - self.half_width

    @property
    def upper(self) -> float:
        """``mean + half_width``."""
        return self.mean + self.half_width


@dataclass(frozen=True)
class ConfidenceTable:
    """Rows of confidence intervals, quantity by quantity (like the paper's Table 1).

    Attributes:
        rows: the rows, in the order they were computed.
    """

    rows: tuple[ConfidenceRow, ...]

    def __add__(self, other: ConfidenceTable) -> ConfidenceTable:
        """Concatenate two tables."""
        return ConfidenceTable(self.rows + other.rows)

    def row(self, quantity: str, level: float) -> ConfidenceRow:
        """The row for ``quantity`` at ``level``.

        Raises:
            ShapeError: no such row (the message lists the quantities present).
        """
        for r in self.rows:
            if r.quantity == quantity and abs(r.level - level) < 1e-12:
                return r
        have = sorted({r.quantity for r in self.rows})
        raise ShapeError(f"no row for {quantity!r} at level {level}; quantities: {have}")

    def to_markdown(self, events_per_year: Mapping[str, float] | float | None = None) -> str:
        """See :func:`to_markdown`."""
        return to_markdown(self, events_per_year)


def _normal(x: FloatArray, lv: FloatArray) -> tuple[float, float, FloatArray]:
    """``(mean, std (ddof 1), z (L,))`` of samples ``x`` at levels ``lv`` (fractions)."""
    from scipy.special import ndtri  # lighter than scipy.stats (about 0.8 s to import)

    z: FloatArray = ndtri(0.5 + lv / 2.0)
    return float(x.mean()), float(x.std(ddof=1)), z


def normal_half_widths(samples: FloatArray, levels: Sequence[float]) -> list[float]:
    """The normal intervals' half-widths ``z * std`` of :func:`confidence_intervals` (the same
    numbers, SI), without its checks and its empirical quantiles (a partition of every
    sample: most of its time on a report row's millions of samples).

    Args:
        samples: ``(N,)`` finite sampled errors in SI units, ``N >= 2`` (the caller checks).
        levels: confidence levels as fractions in (0, 1).
    """
    _, std, z = _normal(samples, np.asarray(levels, dtype=np.float64))
    return [float(zi * std) for zi in z]


def confidence_intervals(
    samples: ArrayLike,
    quantity: str,
    unit: Unit = "m",
    levels: Sequence[float] = CONFIDENCE_LEVELS,
) -> ConfidenceTable:
    """Normal-distribution and empirical intervals of ``samples`` at each level.

    Args:
        samples: ``(N,)`` sampled errors in SI units (``N >= 2``).
        quantity: name shown in the table.
        unit: ``"m"`` or ``"rad"``.
        levels: confidence levels as fractions in (0, 1).

    Raises:
        ShapeError: not 1-D, fewer than 2 samples, an unknown unit or a level outside (0, 1).
        NonFiniteError: NaN or infinity in the samples.
    """
    x = check_finite(as_float_array(samples, "samples"), "samples")
    if x.ndim != 1 or x.size < 2:
        raise ShapeError(f"samples must be (N,) with N >= 2, got shape {x.shape}")
    if unit not in _HUMAN:
        raise ShapeError(f"unit must be 'm' or 'rad', got {unit!r}")
    lv = np.asarray(levels, dtype=np.float64)
    if lv.ndim != 1 or np.any(~np.isfinite(lv)) or np.any((lv <= 0) | (lv >= 1)):
        raise ShapeError(f"levels must be fractions in (0, 1), got {list(levels)}")
    mean, std, z = _normal(x, lv)
    emp = np.quantile(np.abs(x - mean), lv)
    rows = tuple(
        ConfidenceRow(
            quantity=quantity,
            unit=unit,
            level=float(p),
            n_samples=int(x.size),
            mean=mean,
            std=std,
            z=float(zi),
            half_width=float(zi * std),
            empirical_half_width=float(e),
            empirical_resolved=bool(x.size * (1.0 - p) >= 1.0),
        )
        for p, zi, e in zip(lv, z, emp)
    )
    return ConfidenceTable(rows)


def to_markdown(
    table: ConfidenceTable, events_per_year: Mapping[str, float] | float | None = None
) -> str:
    """Render a table as Markdown in millimetres and degrees.

    Args:
        table: the intervals.
        events_per_year: how many positionings a year each quantity stands for (one number for
            all, or per quantity); adds the paper's "Frequency [times/year]" column,
            ``(1 - level) * events_per_year``.
    """
    freq = events_per_year is not None
    head = ["Quantity", "Confidence level [%]"]
    head += ["Frequency [times/year]"] if freq else []
    head += ["Normal interval", "Empirical \\|x - mean\\| quantile", "Samples"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in table.rows:
        k, u = _HUMAN[r.unit]
        cells = [r.quantity, f"{r.level * 100:.6g}"]
        if freq:
            per = (
                events_per_year.get(r.quantity)
                if isinstance(events_per_year, Mapping)
                else events_per_year
            )
            cells.append("" if per is None else f"{(1.0 - r.level) * float(per):.3g}")
        cells.append(f"{r.mean * k:.4g} ± {r.half_width * k:.4g} {u}")
        cells.append(f"± {r.empirical_half_width * k:.4g} {u}" if r.empirical_resolved else "—")
        cells.append(str(r.n_samples))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def signed_radial_error(errors_wobj: ArrayLike, plane: Literal["yz", "xyz"] = "yz") -> FloatArray:
    """The paper's signed positioning error: length in the wobj yz-plane (or xyz-space),
    positive when the x component of the displacement is positive (zero x counts as positive).

    Args:
        errors_wobj: ``(..., 3)`` displacements in the wobj frame's axes, metres.
        plane: ``"yz"`` for the yz-plane error, ``"xyz"`` for the full 3-D error.

    Returns:
        ``(...)`` signed errors, metres.
    """
    e = check_finite(as_float_array(errors_wobj, "errors_wobj"), "errors_wobj")
    if e.shape[-1:] != (3,):
        raise ShapeError(f"errors_wobj must be (..., 3), got {e.shape}")
    if plane not in ("yz", "xyz"):
        raise ShapeError(f"plane must be 'yz' or 'xyz', got {plane!r}")
    length = np.linalg.norm(e[..., 1:] if plane == "yz" else e, axis=-1)
    return np.where(e[..., 0] >= 0.0, length, -length)


def point_errors_wobj(
    T_base_wobj_true: ArrayLike, T_base_wobj_est: ArrayLike, p_wobj: ArrayLike
) -> FloatArray:
    """Where the estimated frames put a wobj point, relative to the truth, in the true wobj axes.

    Args:
        T_base_wobj_true: ``(4, 4)`` the true frame.
        T_base_wobj_est: ``(N, 4, 4)`` or ``(4, 4)`` estimated frames.
        p_wobj: ``(3,)`` the point, wobj frame, metres (e.g. ``epsilon = (0, -1.0, -0.1)``).

    Returns:
        ``(N, 3)`` (or ``(3,)``) errors ``T_true^-1 T_est p - p``, metres.
    """
    T_true = check_transform(T_base_wobj_true, "T_base_wobj_true")
    T_est = check_transform(T_base_wobj_est, "T_base_wobj_est")
    p = check_vector3(p_wobj, "p_wobj")
    return transform_points(invert_transform(T_true) @ T_est, p) - p


def frame_errors(T_base_wobj_true: ArrayLike, T_base_wobj_est: ArrayLike) -> FloatArray:
    """``(N, 6)`` errors ``(dx, dy, dz, rx, ry, rz)`` of estimated frames in the true frame's
    axes (m, rad): origin displacement and rotation vector, as :func:`calib.frames.motion_between`.
    """
    T_true = check_transform(T_base_wobj_true, "T_base_wobj_true")
    T_est = check_transform(T_base_wobj_est, "T_base_wobj_est")
    return motion_between(T_true, T_est)
