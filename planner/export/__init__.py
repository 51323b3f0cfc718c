"""Export a plan to robot programs: ABB RAPID, KUKA KRL, URScript (and plan JSON).

Each exporter formats an :class:`planner.export.job.ExportJob`; :func:`export_text` picks one
by name and returns ``{file name suffix: text}`` (KRL writes a ``.src`` and a ``.dat``).
"""

from __future__ import annotations

from planner.export.job import ExportJob, TargetPair, ToolData, build_job

FORMATS = ("rapid", "krl", "urscript", "json")

__all__ = ["FORMATS", "ExportJob", "TargetPair", "ToolData", "build_job", "export_files"]


def export_files(job: ExportJob, fmt: str) -> dict[str, str]:
    """The program files of ``job`` in format ``fmt`` (``rapid``, ``krl`` or ``urscript``).

    Returns:
        ``{suffix: text}``, e.g. ``{".mod": ...}`` or ``{".src": ..., ".dat": ...}``.
    """
    if fmt == "rapid":
        from planner.export.rapid import export_rapid

        return {".mod": export_rapid(job)}
    if fmt == "krl":
        from planner.export.krl import export_krl

        return export_krl(job)
    if fmt == "urscript":
        from planner.export.urscript import export_urscript

        return {".script": export_urscript(job)}
    raise ValueError(f"format must be one of {FORMATS[:3]}, got {fmt!r}")
