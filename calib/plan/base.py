"""Pieces of the plan structs that only plans use: built-in references, mesh units, digests,
what a point id and a plan name may hold (safe in every robot language), file references.

The strict base struct and the generic field checks are in :mod:`calib.structs`.
"""

from __future__ import annotations

import hashlib
import re
from pathlib import Path
from typing import Annotated, Literal

import msgspec

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


#: A point id: what every robot language can hold in an identifier and a string (letters,
#: digits, ``_``, ``.``, ``-``; at most 32), so no id can end a comment or a string in a program.
POINT_ID_PATTERN = r"^[A-Za-z0-9_][A-Za-z0-9_.-]{0,31}$"
#: A plan name (written into program comments): printable ASCII without quotes, ``\\``, ``!``,
#: ``;`` or line breaks, at most 80 characters.
PLAN_NAME_PATTERN = r"^[A-Za-z0-9 _.,:+()/-]{0,80}$"
PointId = Annotated[str, msgspec.Meta(pattern=POINT_ID_PATTERN)]
PlanName = Annotated[str, msgspec.Meta(pattern=PLAN_NAME_PATTERN)]


def check_pattern(value: str, pattern: str, field: str, what: str) -> None:
    """Raise :class:`PlanError` unless ``value`` matches ``pattern`` (for structs built in code;
    files are checked by msgspec from the same pattern, reworded in :mod:`calib.plan.json_io`)."""
    if not isinstance(value, str) or not re.fullmatch(pattern, value):
        raise PlanError(f"{field}: {value!r} is not {what} ({PATTERN_WORDS[pattern]})")


#: The patterns in words, for error messages.
PATTERN_WORDS = {
    POINT_ID_PATTERN: "letters, digits, _ . -, starting with a letter, digit or _, at most 32",
    PLAN_NAME_PATTERN: "letters, digits, spaces and _ . , : + ( ) / -, at most 80",
}


def file_sha256(path: str | Path) -> str:
    """Hex SHA-256 digest of a file's bytes."""
    digest = hashlib.sha256()
    with Path(path).open("rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def resolve_ref(ref: str, plan_dir: str | Path) -> str | Path:
    """A file reference of the plan: ``builtin:NAME`` unchanged, else a path under ``plan_dir``."""
    if ref.startswith(BUILTIN_PREFIX):
        return ref
    path = Path(ref)
    return path if path.is_absolute() else Path(plan_dir) / path
