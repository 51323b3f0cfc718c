"""The built-in plan ``assets/plans/stator_section_ah.json``, made from
:mod:`planner.parts.stator_demo`.

``wobjcal demo --write-plan FILE`` writes it; ``tests/test_cli.py`` checks that the shipped file
equals :func:`stator_plan_text` byte for byte, so the demo cell stays the single source.
"""

from __future__ import annotations

from calib.plan.file import (
    CellSpec,
    FixtureSpec,
    Plan,
    PlanPoint,
    Pose,
    WorkObjectSpec,
    plan_to_json,
)
from calib.procedures import Hultman2013


def stator_plan() -> Plan:
    """The paper's A-H plan on the built-in stator-section cell (robot base = world)."""
    from planner.parts import stator_demo as demo_cell
    from planner.parts.stator import StatorGeometry

    g = StatorGeometry.full_section()
    T = demo_cell.nominal_T_base_wobj()
    points = [
        PlanPoint.from_probe_point(p, role=pid) for pid, p in demo_cell.stator_ah_points(g).items()
    ]
    size, T_table = demo_cell.demo_table(g, T)  # the table of make_demo_cell
    table = FixtureSpec(
        name="table",
        box_size_m=(float(size[0]), float(size[1]), float(size[2])),
        T_world_fixture=Pose.from_matrix(T_table),
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
