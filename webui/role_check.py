"""Which points break their procedure's roles or layout, said at once while editing.

:func:`role_flags` runs the procedure's own preconditions on the edited points (the naming
role check of :func:`webui.plan_doc.role_refusal`, then :func:`planner.check.job.layout_problem`,
the dry run ``wobjcal check`` and ``calibrate`` do) and names the points the message is about,
so that, e.g., the A-H procedure's point B moved onto the top face is flagged on its row and
marker when it is moved, not when a validation is started.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from calib.errors import InputError
from webui.plan_doc import NO_ROLE, UiPlan, role_refusal


@dataclass(frozen=True)
class RoleFlags:
    """The layout's problem and the points it is about.

    Attributes:
        layout: why the procedure would refuse the points (``""``: it would not).
        by_point: ``{point id: message}`` for the points the problem names.
    """

    layout: str = ""
    by_point: dict[str, str] = field(default_factory=dict)


def _named_points(doc: UiPlan, message: str) -> list[str]:
    """The points a message is about: named by id, or by role (not in count messages)."""
    tokens = set(re.findall(r"[A-Za-z0-9_]+", message))
    counts_only = message.startswith("points:") or "has no plan" in message
    out = []
    for p in doc.points:
        if p.id in tokens or (not counts_only and p.role != NO_ROLE and p.role in tokens):
            out.append(p.id)
    return out


def _role_conflicts(doc: UiPlan) -> dict[str, str]:
    """``{point id: why}`` for points without a role, on a role taken too often, or on a role
    the procedure does not have."""
    out = {}
    for p in doc.points:
        if p.role == NO_ROLE:
            out[p.id] = f"point {p.id} has no role"
            continue
        limit = doc.limit_of(p.role)
        holders = [q.id for q in doc.points if q.role == p.role]
        if limit == 0:
            out[p.id] = f"{doc.method} has no role {p.role!r}"
        elif limit is not None and len(holders) > limit:
            out[p.id] = f"role {p.role} is taken by points {', '.join(holders)}"
    return out


def role_flags(doc: UiPlan) -> RoleFlags:
    """The procedure's objection to the edited points and the points it names."""
    from planner.check.job import layout_problem
    from webui.plan_adapter import plan_from_ui

    refusal = role_refusal(doc)
    if refusal:
        return RoleFlags(refusal, _role_conflicts(doc))
    if doc.source is None:
        return RoleFlags()
    try:
        message = layout_problem(plan_from_ui(doc))
    except InputError as exc:
        message = str(exc)
    if not message:
        return RoleFlags()
    return RoleFlags(message, dict.fromkeys(_named_points(doc, message), message))
