"""The built-in demo: the stator-section cell and its A-H plan (paper section 3.2)."""

from __future__ import annotations

from pathlib import Path

from calib.plan.file import Plan, load_plan
from planner.demo import DEMO_PLAN
from webui.plan_adapter import ui_plan_from_plan
from webui.plan_doc import UiPlan


def demo_plan() -> tuple[Plan, Path]:
    """The shipped demo plan (``assets/plans/stator_section_ah.json``) and its folder."""
    return load_plan(DEMO_PLAN), DEMO_PLAN.parent


def demo_ui_plan() -> tuple[UiPlan, Path]:
    """The demo plan in editable form and the folder its references resolve against."""
    plan, plan_dir = demo_plan()
    return ui_plan_from_plan(plan, name=plan.name or "stator_demo"), plan_dir
