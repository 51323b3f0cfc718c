"""Between the files panel and ``planner.export``: robot programs of the session plan.

The job is built exactly as ``wobjcal export`` builds it (``planner.cli_check.export_job_for``:
orientations and configurations from the cell check when it can run), then formatted by
``planner.export.export_files``. Call :func:`export_program` on the cell worker: the check opens
a PyBullet client.
"""

from __future__ import annotations

import importlib
import logging
from dataclasses import dataclass
from pathlib import Path

from calib.plan import Plan
from webui.backend import NotAvailableError, optional_import

logger = logging.getLogger(__name__)

#: UI name -> ``planner.export`` format name.
FORMATS: dict[str, str] = {"RAPID": "rapid", "KRL": "krl", "URScript": "urscript"}


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
        NotAvailableError: the exporter is not available.
        InputError: the plan cannot be exported (the message says why).
    """
    if fmt not in FORMATS:
        raise NotAvailableError(f"unknown export format {fmt!r}; known: {', '.join(FORMATS)}")
    cli_check = optional_import("planner.cli_check", f"{fmt} export")
    export = optional_import("planner.export", f"{fmt} export")
    plan_io = importlib.import_module("planner.plan_io")
    try:
        job, note = cli_check.export_job_for(plan, plan_dir, run_check=True)
    except (ImportError, plan_io.FeatureUnavailableError) as exc:
        logger.info("export without the check: %s", exc)
        job, note = cli_check.export_job_for(plan, plan_dir, run_check=False)
    files = export.export_files(job, FORMATS[fmt])
    stem = job.name or plan.name or "wobjcal_plan"
    out = tuple((f"{stem}{suffix}", text.encode("utf-8")) for suffix, text in files.items())
    return ExportResult(out, note)
