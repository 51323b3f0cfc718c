"""The strict, immutable struct every file-backed model derives from, and its field checks.

Plan files, measurement files and the physical models they hold (sensor, robot error,
misplacement, procedure settings) are ``msgspec`` structs: typed, frozen, unknown fields
rejected. A check in ``__post_init__`` raises :class:`calib.errors.PlanError` with
``"field: message"``; when msgspec decodes a file it adds the JSON path of the struct (see
:func:`calib.plan.json_io.reword_validation_error`).
"""

from __future__ import annotations

import math
from collections.abc import Sized

import msgspec

from calib.errors import PlanError
from calib.limits import MAX_SEARCH_LENGTH_M
from calib.tolerances import COORDINATE_LIMIT_M

Vec3 = tuple[float, float, float]
#: Tolerance on the length of a unit vector given in a file.
UNIT_TOL = 1e-6


class Strict(msgspec.Struct, frozen=True, forbid_unknown_fields=True, kw_only=True):
    """Base of the file-backed structs: immutable, unknown fields rejected."""


def check_finite(values: tuple[float, ...] | None, field: str) -> None:
    """Raise :class:`PlanError` unless every value is finite (``None`` passes)."""
    if values is not None and not all(math.isfinite(v) for v in values):
        raise PlanError(f"{field}: must hold finite numbers, got {list(values)}")


def check_coordinates(
    values: tuple[float, ...] | None, field: str, limit_m: float = COORDINATE_LIMIT_M
) -> None:
    """Raise :class:`PlanError` unless every value is finite and at most ``limit_m`` in size
    (a position in metres: 1e308 is a typo, refused before any arithmetic sees it)."""
    check_finite(values, field)
    if values is not None:
        big = [v for v in values if abs(v) > limit_m]
        if big:
            raise PlanError(
                f"{field}: {big[0]:g} m is not a plausible coordinate (limit +-{limit_m:g} m; "
                "a value in mm given as metres?)"
            )


def check_unit(values: tuple[float, ...] | None, field: str) -> None:
    """Raise :class:`PlanError` unless ``values`` is a unit vector (``None`` passes)."""
    if values is None:
        return
    check_finite(values, field)
    norm = math.sqrt(sum(v * v for v in values))
    if abs(norm - 1.0) > UNIT_TOL:
        raise PlanError(f"{field}: must be a unit vector, got length {norm:.6g}")


def check_positive(value: float, field: str, allow_zero: bool = False) -> None:
    """Raise :class:`PlanError` unless ``value`` is finite and ``> 0`` (``>= 0`` with
    ``allow_zero``)."""
    if not math.isfinite(value) or value < 0 or (value == 0 and not allow_zero):
        raise PlanError(f"{field}: must be {'>= 0' if allow_zero else '> 0'}, got {value}")


def check_count(
    value: int, field: str, minimum: int = 1, maximum: int | None = None, why: str = ""
) -> None:
    """Raise :class:`PlanError` unless ``value`` is an integer ``>= minimum`` (and
    ``<= maximum`` when given: a count that would allocate without bound is refused here,
    naming the field, not met later as an overflow; ``why`` says why the bound, see
    :mod:`calib.limits`)."""
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise PlanError(f"{field}: must be an integer >= {minimum}, got {value!r}")
    if maximum is not None and value > maximum:
        shown = f"{value:,}" if value < 10**15 else f"{value:.3g}"
        reason = f" ({why})" if why else ""
        raise PlanError(f"{field}: must be at most {maximum:,}, got {shown}{reason}")


def check_length(items: Sized, field: str, maximum: int, what: str, why: str) -> None:
    """Raise :class:`PlanError` when ``items`` holds more than ``maximum`` ``what``
    (``"points: 10,000 points, at most 500 (why)"``), before any of them is used."""
    if len(items) > maximum:
        raise PlanError(f"{field}: {len(items):,} {what}, at most {maximum:,} ({why})")


def check_search_lengths(start_offset_m: float, overtravel_m: float) -> None:
    """Raise :class:`PlanError` when a search starts or overtravels more than
    :data:`calib.limits.MAX_SEARCH_LENGTH_M` (a search is centimetres; its scan steps 2.5 mm)."""
    for field, value in (("start_offset_m", start_offset_m), ("overtravel_m", overtravel_m)):
        if value > MAX_SEARCH_LENGTH_M:
            raise PlanError(
                f"{field}: {value:g} m, at most {MAX_SEARCH_LENGTH_M:g} m (a search runs "
                "centimetres within a robot's reach of 1-3 m, and a simulated edge scan casts "
                "its rays every 2.5 mm of it; a value in mm given as metres?)"
            )
