"""Strict, canonical JSON for wobjcal's versioned files (plans and measurements).

Reading goes in three steps, each with an error that names the JSON path in the style
``points[3].normal: must have length 3``:

1. :func:`json.loads` with hooks that reject duplicate keys and record ``NaN``/``Infinity``
   (plain JSON has neither; Python writes them), so they can be reported with their path;
2. the top-level ``"schema"`` tag is checked against the supported versions;
3. :func:`msgspec.convert` (strict: no string-to-number coercion) builds the typed structs, and
   its :class:`msgspec.ValidationError` (path ``$.points[3].normal``) is reworded.

Writing is canonical: ``json.dumps(msgspec.to_builtins(obj), sort_keys=True, indent=2,
ensure_ascii=False, allow_nan=False) + "\\n"``, so load-then-save is byte-identical.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, TypeVar

import msgspec

from calib.errors import InputError
from calib.reading import MAX_JSON_BYTES, read_bytes_capped

T = TypeVar("T")

_PATH_RE = re.compile(r"^(?P<msg>.*?)(?: - at `\$(?P<path>[^`]*)`)?$", re.DOTALL)

_REWORDS: tuple[tuple[re.Pattern[str], str], ...] = (
    (re.compile(r"^Expected `array` of length (\d+), got (\d+)$"), r"must have length \1, got \2"),
    (re.compile(r"^Expected `array` of length >= (\d+), got (\d+)$"), r"needs at least \1 items"),
    (re.compile(r"^Expected `array` of length >= (\d+)$"), r"needs at least \1 items"),
    (re.compile(r"^Expected `array` of length <= (\d+)$"), r"holds at most \1 items"),
    (re.compile(r"^Expected `float`, got `(\w+)`$"), r"must be a number, got \1"),
    (re.compile(r"^Expected `int`, got `(\w+)`$"), r"must be an integer, got \1"),
    (re.compile(r"^Expected `str`, got `(\w+)`$"), r"must be a string, got \1"),
    (re.compile(r"^Expected `array`, got `(\w+)`$"), r"must be a list, got \1"),
    (re.compile(r"^Expected `object`, got `(\w+)`$"), r"must be an object, got \1"),
    (re.compile(r"^Expected `(.+)`, got `(\w+)`$"), r"must be \1, got \2"),
    (
        re.compile(r"^Expected `str` matching regex '(.+)'$"),
        r"must be a name matching \1 (no quotes, line breaks or other punctuation)",
    ),
    (re.compile(r"^Expected `str` of length <= (\d+)$"), r"must be at most \1 characters"),
)


class _NonFinite:
    """Placeholder for a ``NaN``/``Infinity`` literal met while parsing."""

    def __init__(self, literal: str) -> None:
        self.literal = literal


def _reject_duplicates(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in pairs:
        if key in out:
            raise _DuplicateKey(key)
        out[key] = value
    return out


class _DuplicateKey(Exception):
    def __init__(self, key: str) -> None:
        super().__init__(key)
        self.key = key


def join_path(path: str, key: str | int) -> str:
    """Extend a display path: ``join_path("points", 3) == "points[3]"``."""
    if isinstance(key, int):
        return f"{path}[{key}]"
    return f"{path}.{key}" if path else key


def _find_non_finite(value: Any, path: str) -> tuple[str, str] | None:
    if isinstance(value, _NonFinite):
        return path, value.literal
    if isinstance(value, float) and not math.isfinite(value):
        return path, repr(value)
    if isinstance(value, dict):
        items: Sequence[tuple[str | int, Any]] = list(value.items())
    elif isinstance(value, list):
        items = list(enumerate(value))
    else:
        return None
    for key, item in items:
        found = _find_non_finite(item, join_path(path, key))
        if found:
            return found
    return None


def read_text_file(
    path: Path, error: type[InputError], what: str = "JSON file", limit: int = MAX_JSON_BYTES
) -> str:
    """Read a UTF-8 text file, or raise ``error`` naming it when it is binary or not UTF-8.

    The file must be a regular file of at most ``limit`` bytes (:mod:`calib.reading`): a path
    to a directory, ``/dev/zero`` or a pipe is refused before anything is read.

    Raises:
        OSError: the file cannot be read (missing, permissions).
        error: not a regular file, too large, or not UTF-8.
    """
    data = read_bytes_capped(path, limit, what, error)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise error(
            f"{path}: not a UTF-8 text file (byte {exc.start}): expected a JSON document, "
            "got a binary file (a mesh or an archive?)"
        ) from None


def parse_json_text(text: str, error: type[InputError], source: str) -> Any:
    """Parse JSON text strictly: no duplicate keys, no NaN/Infinity.

    Args:
        text: the JSON document.
        error: the exception class to raise (a subclass of :class:`InputError`).
        source: name of the file or argument, used as the message prefix.
    """
    try:
        raw = json.loads(text, object_pairs_hook=_reject_duplicates, parse_constant=_NonFinite)
    except _DuplicateKey as exc:
        raise error(f"{source}: duplicate key {exc.key!r} in a JSON object") from None
    except json.JSONDecodeError as exc:
        raise error(
            f"{source}: not valid JSON (line {exc.lineno}, column {exc.colno}): {exc.msg}"
        ) from None
    except RecursionError:
        raise error(
            f"{source}: JSON nested too deeply (arrays or objects within each other more than "
            "about a thousand levels): not a plan or measurements file"
        ) from None
    found = _find_non_finite(raw, "")
    if found:
        where, literal = found
        raise error(f"{source}: {where or '(top level)'}: must be a finite number, got {literal}")
    return raw


def check_schema_tag(
    raw: Any, supported: Sequence[str], error: type[InputError], source: str
) -> None:
    """Require ``raw["schema"]`` to be one of ``supported``; the message lists them."""
    want = ", ".join(repr(s) for s in supported)
    if not isinstance(raw, dict):
        raise error(f'{source}: the top level must be a JSON object with "schema": {want}')
    if "schema" not in raw:
        raise error(f"{source}: schema: required field missing (supported: {want})")
    if raw["schema"] not in supported:
        raise error(f"{source}: schema: unsupported version {raw['schema']!r} (supported: {want})")


def reword_validation_error(
    exc: msgspec.ValidationError, choices: Mapping[str, Sequence[str]] | None = None
) -> str:
    """``"Expected `array` of length 3, got 2 - at `$.points[3].normal`"`` becomes
    ``"points[3].normal: must have length 3, got 2"``.

    ``choices`` maps a field name (the last path component, e.g. ``units``, or the last two,
    e.g. ``sensor.kind``, which win) to its valid values, listed in the message of an invalid
    value.
    """
    match = _PATH_RE.match(str(exc))
    msg = match.group("msg") if match else str(exc)
    path = (match.group("path") or "") if match else ""
    path = path.lstrip(".")
    unknown = re.match(r"^Object contains unknown field `(.+)`$", msg)
    missing = re.match(r"^Object missing required field `(.+)`$", msg)
    enum = re.match(r"^Invalid (?:enum )?value (.+)$", msg)
    field_msg = re.match(r"^([A-Za-z_][\w.\[\]]*): (.*)$", msg, re.DOTALL)
    if unknown:
        path, msg = join_path(path, unknown.group(1)), "unknown field"
    elif missing:
        path, msg = join_path(path, missing.group(1)), "required field missing"
    elif enum:
        msg = f"invalid value {enum.group(1)}"
        parts = re.split(r"[.\[]", path)  # "sensor.kind" before "kind": names are reused
        table = choices or {}
        allowed = table.get(".".join(parts[-2:])) or table.get(parts[-1])
        if allowed:
            msg += f" (valid: {', '.join(repr(a) for a in allowed)})"
    elif field_msg:  # raised by a __post_init__ as "field: message"
        path, msg = join_path(path, field_msg.group(1)), field_msg.group(2)
    else:
        for pattern, repl in _REWORDS:
            if pattern.match(msg):
                msg = pattern.sub(repl, msg)
                break
    return f"{path or '(top level)'}: {msg}"


def convert_strict(
    raw: Any,
    type_: type[T],
    error: type[InputError],
    source: str,
    choices: Mapping[str, Sequence[str]] | None = None,
) -> T:
    """:func:`msgspec.convert` with strict types; errors become ``error`` naming the path."""
    try:
        return msgspec.convert(raw, type_, strict=True)
    except msgspec.ValidationError as exc:
        raise error(f"{source}: {reword_validation_error(exc, choices)}") from None


def canonical_json(obj: Any) -> str:
    """The canonical text of a struct: sorted keys, indent 2, trailing newline, every ``-0.0``
    written ``0.0`` (a file is the same whichever arithmetic made its zeros; floats otherwise
    as Python's shortest round-trip ``repr``)."""
    return (
        json.dumps(
            unsigned_zeros(msgspec.to_builtins(obj)),
            sort_keys=True,
            indent=2,
            ensure_ascii=False,
            allow_nan=False,
        )
        + "\n"
    )


def unsigned_zeros(value: Any) -> Any:
    """``value`` (JSON builtins) with every float ``-0.0`` replaced by ``0.0``."""
    if isinstance(value, float):
        return 0.0 if value == 0.0 else value
    if isinstance(value, dict):
        return {k: unsigned_zeros(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [unsigned_zeros(v) for v in value]
    return value


def json_schema(type_: Any) -> str:
    """The JSON Schema of ``type_`` (msgspec-generated), as canonical text."""
    return json.dumps(msgspec.json.schema(type_), sort_keys=True, indent=2) + "\n"
