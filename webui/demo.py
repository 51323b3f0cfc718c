"""The built-in demo: the stator-section cell and its A-H plan (paper section 3.2)."""

from __future__ import annotations

import importlib
import logging
from pathlib import Path

from calib.plan import Plan, load_plan
from webui.backend import REPO_ASSETS, NotAvailableError
from webui.plan_adapter import ui_plan_from_plan
from webui.plan_doc import UiPlan

logger = logging.getLogger(__name__)

#: Names ``planner.demo_cell`` may give the function returning the demo plan.
_DEMO_FUNCTIONS = ("demo_plan", "make_demo_plan", "stator_demo_plan")
#: Bundled plan files tried when ``planner.demo_cell`` offers no plan function.
_DEMO_FILES = ("stator_section_ah.json",)


def demo_plan() -> tuple[Plan, Path]:
    """The demo plan and the folder its relative references are resolved against.

    Raises:
        NotAvailableError: neither ``planner.demo_cell`` nor a bundled demo plan is available.
    """
    try:
        mod = importlib.import_module("planner.demo_cell")
    except ImportError as exc:
        mod, why = None, f"planner.demo_cell: {exc}"
    else:
        why = "planner.demo_cell has no plan function"
        for name in _DEMO_FUNCTIONS:
            fn = getattr(mod, name, None)
            if callable(fn):
                plan = fn()
                if isinstance(plan, Plan):
                    return plan, REPO_ASSETS / "plans"
    for name in _DEMO_FILES:
        path = REPO_ASSETS / "plans" / name
        if path.is_file():
            return load_plan(path), path.parent
    raise NotAvailableError(f"the built-in stator demo is not available yet ({why})")


def demo_ui_plan() -> tuple[UiPlan, Path, str]:
    """The demo plan in editable form, its folder, and ``""``; or, when the demo is not
    available, an empty plan (no cell) and the message saying why."""
    try:
        plan, plan_dir = demo_plan()
    except NotAvailableError as exc:
        logger.warning("%s", exc)
        return UiPlan(name="empty", source=None), REPO_ASSETS / "plans", str(exc)
    return ui_plan_from_plan(plan, name=plan.name or "stator_demo"), plan_dir, ""
