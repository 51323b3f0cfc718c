"""Between the files panel and ``planner.export``: robot programs of the session plan."""

from __future__ import annotations

import importlib
import inspect
from pathlib import Path
from typing import Any

from calib.plan import Plan
from webui.backend import NotAvailableError

#: UI name -> (exporter module, file suffix).
FORMATS: dict[str, tuple[str, str]] = {
    "RAPID": ("planner.export.rapid", ".mod"),
    "KRL": ("planner.export.krl", ".src"),
    "URScript": ("planner.export.urscript", ".script"),
}


def _call_exporter(mod: Any, plan: Plan, plan_dir: Path) -> Any:
    for name in ("export_plan", "export", "render_plan", "render"):
        fn = getattr(mod, name, None)
        if not callable(fn):
            continue
        params = inspect.signature(fn).parameters
        kwargs = {"plan_dir": plan_dir} if "plan_dir" in params else {}
        return fn(plan, **kwargs)
    raise NotAvailableError(f"{mod.__name__} has no export function yet")


def export_program(plan: Plan, fmt: str, plan_dir: Path) -> tuple[str, bytes]:
    """The robot program of ``plan`` in ``fmt`` (a key of :data:`FORMATS`): file name and bytes.

    Raises:
        NotAvailableError: the exporter is not available.
        InputError: the plan cannot be exported (the message says why).
    """
    if fmt not in FORMATS:
        raise NotAvailableError(f"unknown export format {fmt!r}; known: {', '.join(FORMATS)}")
    module, suffix = FORMATS[fmt]
    try:
        mod = importlib.import_module(module)
    except ImportError as exc:
        raise NotAvailableError(f"{fmt} export is not available yet ({module}: {exc})") from None
    out = _call_exporter(mod, plan, plan_dir)
    text = getattr(out, "text", out)
    name = getattr(out, "filename", None) or f"{plan.name or 'wobjcal_plan'}{suffix}"
    data = text if isinstance(text, bytes) else str(text).encode("utf-8")
    return str(name), data
