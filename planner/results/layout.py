"""Where each controller's program keeps which point: its slots, from the plan, as the writer
of that program lays them out (no cell needed: the layout depends on the plan and the
controller only)."""

from __future__ import annotations

import numpy as np

from calib.plan.file import Plan
from planner.export.job import ExportJob, ToolData, build_job
from planner.export.krl_adaptive import krl_job, measured_slots
from planner.plan_cell import nominal_T_base_wobj

#: A slot: ``(point id, is a retake)``.
Slot = tuple[str, bool]


def _job(plan: Plan) -> ExportJob:
    return build_job(plan, nominal_T_base_wobj(plan), ToolData(T_flange_tcp=np.eye(4)))


def krl_slots(plan: Plan) -> list[Slot]:
    """The slots of ``xMeas``/``nFail`` of the plan's KRL program, in order (1-based on the
    controller): the points in plan order, then the A-H retakes of C and D."""
    return measured_slots(krl_job(_job(plan))[0])


def plan_order(plan: Plan) -> list[str]:
    """The point ids in the order every program numbers them (FANUC ``PR[10 + i]``)."""
    return [t.point_id for t in _job(plan).targets]
