"""Between the files panel and :mod:`planner.export_plan.job`: robot programs of the session plan.

The program is made exactly as ``wobjcal export`` makes it
(:func:`planner.export_plan.job.export_program`: orientations and configurations from the plan
check in the session's cell). Call :func:`export_program` on the cell worker. The files are
named as ``wobjcal export -o DIR`` names them: after the session plan's name
(:func:`planner.export.export_file_stem`; KRL and FANUC after the program's name).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from calib.errors import InputError
from calib.plan.file import Plan
from calib.registry import lookup
from planner.export import FORMATS as EXPORT_FORMATS

if TYPE_CHECKING:
    from planner.cell.cell import Cell

#: Download button label -> export format name, from the export registry.
FORMATS: dict[str, str] = {f.label: f.name for f in EXPORT_FORMATS.values()}


@dataclass(frozen=True)
class ExportResult:
    """The files of one export.

    Attributes:
        files: ``(file name, content)`` pairs (KRL writes a ``.src`` and a ``.dat``).
        note: what the user should know (e.g. points not feasible, estimated tool mass).
        refusals: why ``wobjcal check --format`` refuses the plan for this program, one line
            each (``"P3: ..."``, ``"layout: ..."``, ``"error: ..."``); ``()`` when it passes.
            The files are made all the same, their headers saying it (``NOT CHECKED``); the
            files panel sends them only when the user asks again ("Export anyway").
    """

    files: tuple[tuple[str, bytes], ...]
    note: str = ""
    refusals: tuple[str, ...] = ()


def export_program(plan: Plan, fmt: str, plan_dir: Path, cell: Cell | None = None) -> ExportResult:
    """The robot program(s) of ``plan`` in ``fmt`` (a key of :data:`FORMATS`).

    Args:
        plan: the session plan.
        fmt: a download label of :data:`FORMATS`.
        plan_dir: folder the plan's relative file references resolve against.
        cell: the session's open cell of the plan (``None``: a cell is opened for the check).

    Raises:
        InputError: unknown format, or the plan cannot be exported (the message says why).
    """
    from planner.export_plan.job import export_program as make

    name = lookup(FORMATS, fmt, "export format (download)")
    result = make(plan, plan_dir, name, cell=cell)
    if not result.files:  # the controller has no program for the plan: nothing to force
        raise InputError(f"no {fmt} program for this plan: {result.layout}")
    stem = EXPORT_FORMATS[name].file_stem(plan.name)
    out = tuple((f"{stem}{suffix}", text.encode("utf-8")) for suffix, text in result.files.items())
    if result.check is not None:
        refusals = result.check.refusals()
    else:
        refusals = (f"layout: {result.layout}",) if result.layout else ()
    return ExportResult(out, "; ".join(result.notes), refusals)
