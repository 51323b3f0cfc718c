"""Between the files panel and ``planner.export``: robot programs of the session plan.

The job is built exactly as ``wobjcal export`` builds it (``planner.cli.check.export_job_for``:
orientations and configurations from the cell check when it can run), then formatted by
``planner.export.export_files``. Call :func:`export_program` on the cell worker: the check opens
a PyBullet client.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from calib.errors import InputError
from calib.plan.file import Plan
from planner.cli.check import export_job_for
from planner.export import FORMATS as EXPORT_FORMATS
from planner.export import export_files

#: UI name -> ``planner.export`` format name.
#: Download button label -> export format name, from the export registry.
FORMATS: dict[str, str] = {f.label: f.name for f in EXPORT_FORMATS.values()}


@dataclass(frozen=True)
class ExportResult:
    """The files of one export.

    Attributes:
        files: ``(file name, content)`` pairs (KRL writes a ``.src`` and a ``.dat``).
        note: what the user should know (e.g. points not feasible, estimated tool mass).
    """

    files: tuple[tuple[str, bytes], ...]
    note: str = ""


def export_program(plan: Plan, fmt: str, plan_dir: Path) -> ExportResult:
    """The robot program(s) of ``plan`` in ``fmt`` (a key of :data:`FORMATS`).

    Raises:
        InputError: unknown format, or the plan cannot be exported (the message says why).
    """
    if fmt not in FORMATS:
        raise InputError(f"unknown export format {fmt!r}; known: {', '.join(FORMATS)}")
    job, note = export_job_for(plan, plan_dir, run_check=True)
    files = export_files(job, FORMATS[fmt])
    stem = job.name or plan.name or "wobjcal_plan"
    out = tuple((f"{stem}{suffix}", text.encode("utf-8")) for suffix, text in files.items())
    return ExportResult(out, note)
