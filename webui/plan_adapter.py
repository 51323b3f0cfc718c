"""Between the plan file (:mod:`calib.plan.file`, ``wobjcal.plan/1``) and the UI's editable points.

The strict :class:`calib.plan.file.Plan` refuses a plan whose points do not fit its procedure (e.g.
the A-H procedure needs each role A-H exactly once), but a plan being edited is often incomplete.
So the UI edits a :class:`webui.plan_doc.UiPlan`; :func:`plan_from_ui` builds the strict plan for
downloads and exports (its error says what is missing), and :func:`autosave_bytes` writes the
same JSON layout without the procedure check so that no edit is ever lost.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import msgspec

from calib.errors import WobjcalError
from calib.plan.file import Plan, PlanError, PlanPoint, load_plan, plan_from_json, plan_to_json
from calib.plan.json_io import canonical_json
from calib.procedures import RolePoint, method_of, procedure_kind
from webui.plan_doc import (
    NO_ROLE,
    UiPlan,
    UiPoint,
    next_free_role,
    replace_point,
    role_refusal,
)


def roles_of(plan: Plan) -> tuple[str, ...]:
    """The point roles the plan's procedure allows."""
    return procedure_kind(plan.procedure).roles


def _procedure_fields(plan: Plan) -> dict[str, Any]:
    """The :class:`UiPlan` fields that come from the plan's procedure."""
    kind = procedure_kind(plan.procedure)
    return {
        "roles": kind.roles,
        "role_limits": tuple(kind.role_limits[r] for r in kind.roles),
        "method": method_of(plan.procedure),
    }


def ui_plan_from_plan(plan: Plan, name: str | None = None) -> UiPlan:
    """The editable points of ``plan`` (the plan itself rides along as ``source``)."""
    points = tuple(
        UiPoint(
            probe=p.to_probe_point(),
            role=p.role,
            speed_m_s=p.search.speed_m_s,
            vias=p.via_points,
        )
        for p in plan.points
    )
    return UiPlan(
        points=points, name=name or plan.name or "plan", source=plan, **_procedure_fields(plan)
    )


def plan_point(point: UiPoint) -> PlanPoint:
    """The plan-file form of one edited point (what :func:`planner.check.check_points` takes)."""
    return PlanPoint.from_probe_point(point.probe, point.role, point.speed_m_s, point.vias)


def _plan_points(ui: UiPlan) -> list[PlanPoint]:
    return [plan_point(p) for p in ui.points]


def plan_from_ui(ui: UiPlan) -> Plan:
    """The strict plan: ``ui.source`` with the edited points.

    Raises:
        PlanError: the points do not fit the procedure (the message names the points and says
            what is missing), or there is no source plan to take the cell and procedure from.
    """
    if not isinstance(ui.source, Plan):
        raise PlanError("no plan is loaded: load a plan or the demo first")
    refusal = role_refusal(ui)
    if refusal:
        raise PlanError(refusal)
    return msgspec.structs.replace(ui.source, points=_plan_points(ui))


def plan_as_edited(ui: UiPlan) -> Plan | None:
    """The loaded plan with the points as edited now, without the procedure's role rules (the
    check of one edited point needs all of them: their centroid is the pivot of the safe
    starts), or ``None`` when they do not make a plan (the session's plan is used then)."""
    if not isinstance(ui.source, Plan):
        return None
    try:
        return msgspec.structs.replace(ui.source, points=_plan_points(ui))
    except (WobjcalError, ValueError, TypeError):  # e.g. an edit that breaks a plan rule
        return None


def plan_json_from_ui(ui: UiPlan) -> str:
    """Canonical JSON text of :func:`plan_from_ui` (raises :class:`PlanError` when incomplete)."""
    return plan_to_json(plan_from_ui(ui))


def autosave_bytes(ui: UiPlan) -> bytes:
    """The plan JSON of ``ui``, written even when the points do not fit the procedure yet."""
    if not isinstance(ui.source, Plan):
        return b"{}\n"
    raw: dict[str, Any] = msgspec.to_builtins(ui.source)
    raw["points"] = msgspec.to_builtins(_plan_points(ui))
    return canonical_json(raw).encode("utf-8")


def ui_plan_from_bytes(data: bytes, source: str) -> UiPlan:
    """Parse an uploaded plan strictly (errors name ``source`` and the JSON path)."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise PlanError(f"{source}: not UTF-8 text, so not a plan JSON file") from None
    plan = plan_from_json(text, source=source)
    return ui_plan_from_plan(plan, name=Path(source).stem)


def ui_plan_from_file(path: Path) -> UiPlan:
    """Load a plan file strictly, checking the files it refers to."""
    return ui_plan_from_plan(load_plan(path), name=Path(path).stem)


def with_source(ui: UiPlan, plan: Plan) -> UiPlan:
    """``ui`` with another source plan (e.g. after a new work object was uploaded)."""
    return dataclasses.replace(ui, source=plan, **_procedure_fields(plan))


def with_procedure(ui: UiPlan, method: str) -> UiPlan:
    """``ui`` under another procedure (:data:`calib.procedures.PROCEDURES`, default settings).

    The points keep their roles when the new procedure has them and they fit its limits;
    otherwise the procedure assigns roles from the points' geometry (``assign``, e.g. the
    3-2-1's primary, secondary and tertiary faces), and when it cannot, each point takes the
    next free role in order (:func:`webui.plan_doc.next_free_role`), or none.

    Raises:
        PlanError: ``method`` is not a known procedure, or no plan is loaded.
    """
    if not isinstance(ui.source, Plan):
        raise PlanError("no plan is loaded: load a plan or the demo first")
    kind = procedure_kind(method)
    if method == ui.method:
        return ui
    source = msgspec.structs.replace(ui.source, points=[], procedure=kind.settings_type())
    empty = with_source(dataclasses.replace(ui, points=()), source)
    kept = dataclasses.replace(empty, points=ui.points)
    if not role_refusal(kept):
        return kept
    roles: dict[str, str] = {}
    try:
        assigned = kind.assign([RolePoint(p.role, p.probe) for p in ui.points])
        roles = {rp.point.id: rp.role for rp in assigned}
    except (PlanError, ValueError):
        roles = {}
    out = dataclasses.replace(  # the assigned roles first, then the rest in order
        empty,
        points=tuple(dataclasses.replace(p, role=roles.get(p.id, NO_ROLE)) for p in ui.points),
    )
    for p in out.points:
        if p.role == NO_ROLE:
            out = replace_point(out, dataclasses.replace(p, role=next_free_role(out)))
    return out
