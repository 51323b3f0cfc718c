"""The files of a sweep: ``DIR/sweep.csv`` (one row per placement) and ``DIR/sweep.json``
(the arguments it was written with).

Rows are appended as they finish, each flushed and fsynced (a kill loses at most the row being
written, whose torn line is dropped on resume); when the sweep is complete the file is rewritten
in index order in one atomic replace (:mod:`calib.atomic_io`). ``sweep.json`` is written
atomically before the first row: a restart with the same arguments keeps the finished rows and
runs the missing placements only; one with other arguments is refused, naming them.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from calib.atomic_io import write_text_atomic
from calib.errors import InputError
from calib.plan.json_io import read_text_file
from planner.sweep.space import AXES, Placement, flag_of
from planner.sweep.task import SweepRow

SCHEMA = "wobjcal.sweep/1"
CSV_NAME, JSON_NAME, PNG_NAME = "sweep.csv", "sweep.json", "sweep.png"
#: The columns of ``sweep.csv``.
COLUMNS: tuple[str, ...] = (
    "index",
    *(a for a, _ in AXES),
    "status",
    "points_feasible",
    "points_total",
    "layout_status",
    "accuracy_mm",
    "cycle_s",
    "reason",
)
#: Largest ``sweep.csv`` read on resume, bytes (100,000 rows of ~200 bytes are 20 MB).
MAX_CSV_BYTES = 256 << 20
#: The sidecar keys that must match for a restart to resume, with the flag each comes from.
_IDENTITY = {"plan_digest": "PLAN", "seed": "--seed", "format": "--format"}


class SweepMismatch(InputError):
    """``DIR`` holds a sweep written with other arguments (the message names them)."""


def _num(x: float, digits: int) -> str:
    return "" if not math.isfinite(x) else f"{x:.{digits}f}"


def row_cells(row: SweepRow) -> list[str]:
    """The CSV cells of ``row`` in :data:`COLUMNS` order (mm to 1 um, deg to 1e-4, accuracy
    to 1 nm, cycle time to 1 ms; empty for NaN)."""
    p = row.placement
    poses = [
        _num(v, 4 if unit == "deg" else 3) for v, (_, unit) in zip(p.values(), AXES, strict=True)
    ]
    return [
        str(p.index),
        *poses,
        row.status,
        str(row.points_feasible),
        str(row.points_total),
        row.layout_status,
        _num(row.accuracy_mm, 6),
        _num(row.cycle_s, 3),
        row.reason,
    ]


def csv_text(rows: Iterable[list[str]]) -> str:
    """CSV text (``\\n`` line ends) of cell lists."""
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerows(rows)
    return buf.getvalue()


def sidecar(
    plan_path: str,
    plan_digest: str,
    seed: int,
    fmt: str,
    ranges: dict[str, list[float]],
    samples: int,
    accuracy: str,
) -> dict[str, Any]:
    """The content of ``sweep.json``: schema, plan (path and digest), seed, format, ranges
    (mm, deg), samples, the columns and what ``accuracy_mm`` means."""
    return {
        "schema": SCHEMA,
        "plan": plan_path,
        "plan_digest": plan_digest,
        "seed": seed,
        "format": fmt,
        "ranges": ranges,
        "samples": samples,
        "columns": list(COLUMNS),
        "accuracy_mm": accuracy,
    }


def _show_range(r: Any) -> str:
    return ":".join(f"{float(v):g}" for v in r) if isinstance(r, list) else repr(r)


def mismatches(old: dict[str, Any], new: dict[str, Any]) -> list[str]:
    """The arguments that differ between an existing sidecar ``old`` and this run's ``new``:
    ``"--seed 1 (now 2)"``; more samples than before is not a difference (the sweep grows)."""
    out = []
    for key, flag in _IDENTITY.items():
        if old.get(key) != new[key]:
            out.append(f"{flag} {old.get(key)} (now {new[key]})")
    old_ranges = old.get("ranges") or {}
    for axis, _ in AXES:
        if old_ranges.get(axis) != new["ranges"][axis]:
            out.append(
                f"{flag_of(axis)} {_show_range(old_ranges.get(axis))} "
                f"(now {_show_range(new['ranges'][axis])})"
            )
    if not isinstance(old.get("samples"), int) or old["samples"] > new["samples"]:
        out.append(f"--samples {old.get('samples')} (now {new['samples']}: fewer)")
    return out


def read_sidecar(path: Path) -> dict[str, Any]:
    """``sweep.json`` as a dict.

    Raises:
        InputError: not JSON of schema :data:`SCHEMA`.
    """
    text = read_text_file(path, InputError, "sweep sidecar")
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}: not JSON ({exc})") from None
    if not isinstance(data, dict) or data.get("schema") != SCHEMA:
        raise InputError(f"{path}: not a sweep sidecar (schema {SCHEMA!r})")
    return data


def write_sidecar(path: Path, data: dict[str, Any]) -> None:
    """Write ``sweep.json`` atomically (sorted keys, indent 2)."""
    write_text_atomic(path, json.dumps(data, indent=2, sort_keys=True) + "\n")


def read_rows(path: Path) -> dict[int, list[str]]:
    """The finished rows of ``sweep.csv`` by index; a torn last line (no line end: the process
    was killed while writing it) is dropped, so is a second row of an index.

    Raises:
        InputError: the header is not :data:`COLUMNS`, or a complete row is malformed.
    """
    text = read_text_file(path, InputError, "sweep CSV", limit=MAX_CSV_BYTES)
    if not text.endswith("\n"):
        text = text[: text.rfind("\n") + 1]
    lines = list(csv.reader(io.StringIO(text)))
    if not lines:
        return {}
    if tuple(lines[0]) != COLUMNS:
        raise InputError(f"{path}: not a sweep CSV of this version (header {lines[0][:3]}...)")
    rows: dict[int, list[str]] = {}
    for n, cells in enumerate(lines[1:], start=2):
        if len(cells) != len(COLUMNS) or not cells[0].isdigit():
            raise InputError(f"{path}: line {n}: malformed row; remove the line to resume")
        rows.setdefault(int(cells[0]), cells)
    return rows


def write_rows(path: Path, rows: dict[int, list[str]]) -> None:
    """Write the header and ``rows`` in index order, atomically."""
    write_text_atomic(path, csv_text([list(COLUMNS), *(rows[i] for i in sorted(rows))]))


def append_row(fd: int, cells: list[str]) -> None:
    """Append one row to the open ``sweep.csv`` (``O_APPEND``) and fsync it."""
    data = csv_text([cells]).encode("utf-8")
    while data:
        written = os.write(fd, data)
        data = data[written:]
    os.fsync(fd)


def placement_of(cells: list[str]) -> Placement:
    """The placement a CSV row names."""
    return Placement(int(cells[0]), *(float(v) for v in cells[1 : 1 + len(AXES)]))
