"""Shared pieces of the plan structs: the error, the strict base struct and field checks.

Checks raise :class:`PlanError` with ``"field: message"``; when msgspec decodes a file, it adds
the JSON path of the struct (see :func:`calib.plan.json_io.reword_validation_error`).
"""

from __future__ import annotations

import math
import re
from typing import Literal

import msgspec

from calib.errors import InputError

BUILTIN_PREFIX = "builtin:"
#: The plan's mesh units: exactly ``calib.units.MESH_UNITS`` (a test keeps them equal).
MeshUnits = Literal["m", "mm", "cm", "in", "auto"]
Vec3 = tuple[float, float, float]
UNIT_TOL = 1e-6
_SHA256_RE = re.compile(r"^[0-9a-f]{64}$")


class PlanError(InputError):
    """A plan file or plan object is malformed; the message names the file and JSON path."""


class Strict(msgspec.Struct, frozen=True, forbid_unknown_fields=True, kw_only=True):
    """Base of the plan structs: immutable, unknown fields rejected."""


def check_finite(values: tuple[float, ...] | None, field: str) -> None:
    if values is not None and not all(math.isfinite(v) for v in values):
        raise PlanError(f"{field}: must hold finite numbers, got {list(values)}")


def check_unit(values: tuple[float, ...] | None, field: str) -> None:
    if values is None:
        return
    check_finite(values, field)
    norm = math.sqrt(sum(v * v for v in values))
    if abs(norm - 1.0) > UNIT_TOL:
        raise PlanError(f"{field}: must be a unit vector, got length {norm:.6g}")


def check_positive(value: float, field: str, allow_zero: bool = False) -> None:
    if not math.isfinite(value) or value < 0 or (value == 0 and not allow_zero):
        raise PlanError(f"{field}: must be {'>= 0' if allow_zero else '> 0'}, got {value}")


def check_sha256(value: str | None, ref: str, field: str) -> None:
    if value is None:
        return
    if ref.startswith(BUILTIN_PREFIX):
        raise PlanError(f"{field}: must be null for a built-in ({ref!r})")
    if not _SHA256_RE.match(value):
        raise PlanError(f"{field}: must be 64 lowercase hex digits, got {value!r}")
