"""Pieces of the plan structs that only plans use: built-in references, mesh units, digests.

The strict base struct and the generic field checks are in :mod:`calib.structs`.
"""

from __future__ import annotations

import re
from typing import Literal

from calib.errors import PlanError

BUILTIN_PREFIX = "builtin:"
#: The plan's mesh units: exactly ``calib.units.MESH_UNITS`` (a test keeps them equal).
MeshUnits = Literal["m", "mm", "cm", "in", "auto"]
_SHA256_RE = re.compile(r"^[0-9a-f]{64}$")


def check_sha256(value: str | None, ref: str, field: str) -> None:
    """Raise :class:`PlanError` unless ``value`` is ``None`` or a sha256 hex digest of a file
    (never of a built-in)."""
    if value is None:
        return
    if ref.startswith(BUILTIN_PREFIX):
        raise PlanError(f"{field}: must be null for a built-in ({ref!r})")
    if not _SHA256_RE.match(value):
        raise PlanError(f"{field}: must be 64 lowercase hex digits, got {value!r}")
