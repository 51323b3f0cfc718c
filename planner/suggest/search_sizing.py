"""How long the searches a suggestion writes are: for the whole misplacement, or steered.

Every approach search a suggestion writes starts at least :data:`MIN_START_M` outside its
nominal face and runs at least :data:`MIN_OVERTRAVEL_M` past it, and as far as the program's
safe start needs (:mod:`planner.program.safety`):

- ``whole`` (``--objective accuracy``): for the whole misplacement, so the program of every
  controller runs the plan;
- ``steered`` (:func:`steered_plan`, the rows of ``--objective time`` that an adaptive
  controller runs): a search an adaptive program commands in the estimate of the points before
  it only for the shift that estimate leaves (:mod:`planner.program.steered_searches`); the
  plan says so (``search_sizing: "steered"``) and a program that cannot steer refuses it.
"""

from __future__ import annotations

import msgspec

from calib.plan.file import Plan, PlanPoint
from planner.program.build import safety_spec

#: The nearest a written approach search starts to its nominal face, m.
MIN_START_M = 0.015
#: The least a written approach search runs past its nominal face, m.
MIN_OVERTRAVEL_M = 0.010


def steered_plan(plan: Plan) -> Plan:
    """``plan`` with ``search_sizing: "steered"`` and every approach search started and run as
    far as its steered bound needs (never less than the floors above; the points measured
    before the program's first update keep the whole misplacement's)."""
    steered = msgspec.structs.replace(plan, search_sizing="steered")
    safety = safety_spec(steered)
    points: list[PlanPoint] = []
    for p in steered.points:
        if p.search.kind != "approach":
            points.append(p)
            continue
        search = msgspec.structs.replace(
            p.search,
            start_offset_m=max(MIN_START_M, safety.start_clearance_m(p.position_m, p.id)),
            overtravel_m=max(MIN_OVERTRAVEL_M, safety.overtravel_m(p.position_m, p.id)),
        )
        points.append(msgspec.structs.replace(p, search=search))
    return msgspec.structs.replace(steered, points=points)
