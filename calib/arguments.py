"""Argument checks used at the public boundary of ``calib`` (and reused by ``planner``).

Each check converts its input to a float64 numpy array and raises a subclass of
:class:`calib.errors.InputError` that names the argument when the input is not usable.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.errors import DegenerateGeometryError, NonFiniteError, ShapeError

FloatArray = NDArray[np.float64]


def as_float_array(value: ArrayLike, name: str) -> FloatArray:
    """Convert ``value`` to a float64 array or raise :class:`ShapeError` naming ``name``."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ShapeError(f"{name} must be numeric, got {type(value).__name__}: {exc}") from None
    return arr


def check_finite(arr: FloatArray, name: str) -> FloatArray:
    """Raise :class:`NonFiniteError` when ``arr`` holds NaN or infinity."""
    if not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr))
        where = tuple(int(i) for i in bad[0]) if bad.size else ()
        raise NonFiniteError(f"{name} holds NaN or infinity (first at index {where})")
    return arr


def check_shape(value: ArrayLike, shape: tuple[int | None, ...], name: str) -> FloatArray:
    """Return ``value`` as a finite float64 array of ``shape`` (``None`` matches any length).

    Raises:
        ShapeError: wrong number of dimensions or wrong length along a fixed axis.
        NonFiniteError: the array holds NaN or infinity.
    """
    arr = as_float_array(value, name)
    want = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ")"
    if arr.ndim != len(shape) or any(
        s is not None and a != s for a, s in zip(arr.shape, shape, strict=True)
    ):
        raise ShapeError(f"{name} must be {want}, got {arr.shape}")
    return check_finite(arr, name)


def check_vector3(value: ArrayLike, name: str) -> FloatArray:
    """Return a finite ``(3,)`` float64 vector."""
    return check_shape(value, (3,), name)


def check_unit_vector3(value: ArrayLike, name: str, tol: float = 1e-6) -> FloatArray:
    """Return a finite ``(3,)`` vector of unit length (within ``tol``), normalised exactly.

    Raises:
        DegenerateGeometryError: the vector is (near) zero or not of unit length.
    """
    v = check_vector3(value, name)
    norm = float(np.linalg.norm(v))
    if norm < 1e-12:
        raise DegenerateGeometryError(f"{name} must be a unit vector, got the zero vector")
    if abs(norm - 1.0) > tol:
        raise DegenerateGeometryError(f"{name} must be a unit vector, got length {norm:.6g}")
    return v / norm


def check_points(value: ArrayLike, name: str, min_count: int = 1) -> FloatArray:
    """Return a finite ``(N, 3)`` float64 array with ``N >= min_count``."""
    pts = check_shape(value, (None, 3), name)
    if pts.shape[0] < min_count:
        raise ShapeError(f"{name} needs at least {min_count} points, got {pts.shape[0]}")
    return pts


def check_positive(value: Any, name: str, allow_zero: bool = False) -> float:
    """Return ``value`` as a finite float that is > 0 (or >= 0 with ``allow_zero``)."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ShapeError(f"{name} must be a number, got {value!r}") from None
    if not np.isfinite(x):
        raise NonFiniteError(f"{name} must be finite, got {x}")
    if x < 0 or (x == 0 and not allow_zero):
        raise ShapeError(f"{name} must be {'>= 0' if allow_zero else '> 0'}, got {x}")
    return x
