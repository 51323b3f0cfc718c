"""The built-in plan ``assets/plans/stator_section_ah.json``, made from :mod:`planner.demo_cell`.

``wobjcal demo --write-plan FILE`` writes it; ``tests/test_cli.py`` checks that the shipped file
equals :func:`stator_plan_text` byte for byte, so the demo cell stays the single source.
"""

from __future__ import annotations

import numpy as np

from calib.plan import (
    CellSpec,
    FixtureSpec,
    Plan,
    PlanPoint,
    Pose,
    WorkObjectSpec,
    plan_to_json,
)
from calib.plan_procedures import Hultman2013


def stator_plan() -> Plan:
    """The paper's A-H plan on the built-in stator-section cell (robot base = world)."""
    from planner import demo_cell
    from planner.stator import StatorGeometry

    g = StatorGeometry.full_section()
    T = demo_cell.nominal_T_base_wobj()
    points = [
        PlanPoint.from_probe_point(p, role=pid) for pid, p in demo_cell.stator_ah_points(g).items()
    ]
    # the table of make_demo_cell: top 0.1 m below the lowest corner of the inclined part
    low = T @ np.array([-g.depth_m, 0.0, -g.height_m, 1.0])
    centre = (float(low[0]) + 0.1, float(T[1, 3]) + g.length_m / 2, float(low[2]) - 0.125)
    table = FixtureSpec(
        name="table",
        box_size_m=(1.0, g.length_m + 0.2, 0.05),
        T_world_fixture=Pose(position_m=centre),
    )
    return Plan(
        name="stator_section_ah",
        description=(
            "Hultman & Leijon (2013) section 3.2: points A-H on the UU WEC stator section, "
            "inclined 15 deg on a table in front of an IRB 4400 with the cable-feeder tool."
        ),
        cell=CellSpec(fixtures=[table]),
        work_object=WorkObjectSpec(
            mesh="builtin:stator_section", units="m", T_world_wobj=Pose.from_matrix(T)
        ),
        points=points,
        procedure=Hultman2013(beta1_rad=demo_cell.BETA1_RAD),
    )


def stator_plan_text() -> str:
    """The canonical JSON of :func:`stator_plan`."""
    return plan_to_json(stator_plan())
