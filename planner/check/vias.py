"""Via points for a plan's colliding moves between points (``wobjcal check --add-vias``).

:func:`plan_with_vias` checks the plan's points and the moves between them, and for every
point whose move in collides (:func:`planner.check.job.check_via_moves`) and that has no vias yet,
asks :func:`planner.cell.moves.suggest_vias` for vias clearing the moves from every point a
program may come from (:func:`planner.program.build.predecessors`), and returns the plan with
them. Vias the engineer taught are never replaced; a point the search cannot clear is named.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec

from calib.plan.file import Plan, ViaPoint
from planner.cell.moves import suggest_vias
from planner.check.job import check_points, check_via_moves
from planner.program.build import predecessors

if TYPE_CHECKING:
    from planner.cell.cell import Cell


def plan_with_vias(plan: Plan, cell: Cell) -> tuple[Plan, dict[str, str]]:
    """``plan`` with vias added where a move into a point collides (module docstring).

    Args:
        plan: the plan.
        cell: the plan's open cell.

    Returns:
        The plan (unchanged when nothing was added) and ``{point id: what was done}`` for every
        point whose move in collided.
    """
    checks = check_via_moves(cell, plan, check_points(cell, plan, plan.points))
    before = predecessors(plan)
    tcp = plan.cell.tool.tcp
    points = list(plan.points)
    done: dict[str, str] = {}
    for i, (p, c) in enumerate(zip(plan.points, checks, strict=True)):
        if not c.via_reason:
            continue
        if p.via_points:
            done[p.id] = "has taught vias: left as they are (edit them in the Teach tab)"
            continue
        froms = [
            checks[k].q_safe
            for k in before.get(i, [])
            if k is not None and checks[k].pose_status != "infeasible"
        ]
        if c.q_safe is None or c.pose_status == "infeasible":
            done[p.id] = "no pose to move to: fix the point first"
            continue
        vias = suggest_vias(cell, [q for q in froms if q is not None], c.q_safe, tcp)
        if not vias:
            done[p.id] = "no retract or joint turn clears it: teach a via in the Teach tab"
            continue
        # rounded to 1e-6 rad (0.2 arc seconds): a plan file that reads the same everywhere
        new = [ViaPoint(q_rad=[round(float(v), 6) for v in q]) for q in vias]
        points[i] = msgspec.structs.replace(p, vias=new)
        done[p.id] = f"{len(new)} via point{'s' if len(new) > 1 else ''} added"
    if not any(a is not b for a, b in zip(points, plan.points, strict=True)):
        return plan, done
    return msgspec.structs.replace(plan, points=points), done
