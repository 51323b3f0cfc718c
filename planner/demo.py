"""The built-in demo: the stator-section cell and its A-H plan.

Both are made from the placement in :mod:`planner.parts.stator_demo`. The plan is shipped as
``assets/plans/stator_section_ah.json`` (:data:`DEMO_PLAN`); ``wobjcal demo --write-plan FILE``
writes it, and ``tests/planner/cli/test_cli.py`` checks that the shipped file equals
:func:`stator_plan_text` byte for byte, so this module stays the single source.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from calib.plan.file import (
    CellSpec,
    FixtureSpec,
    Plan,
    PlanPoint,
    Pose,
    ValidationSpec,
    WorkObjectSpec,
    plan_to_json,
)
from calib.procedures import Hultman2013
from planner.builtins import ASSETS
from planner.parts import stator_demo as demo_cell
from planner.parts.stator import StatorGeometry
from planner.parts.stator_mesh import build_stator_mesh

if TYPE_CHECKING:
    from planner.cell.cell import Cell

#: The built-in demo plan (the paper's A-H plan on the built-in stator cell).
DEMO_PLAN = ASSETS / "plans" / "stator_section_ah.json"


def stator_plan() -> Plan:
    """The paper's A-H plan on the built-in stator-section cell (robot base = world), with the
    x-offset run and the paper's Table 1 rows in the report."""

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
        procedure=Hultman2013(beta1_rad=demo_cell.BETA1_RAD, xoffset=demo_cell.stator_xoffset(g)),
        validation=ValidationSpec(report=demo_cell.STATOR_REPORT),
    )


def stator_plan_text() -> str:
    """The canonical JSON of :func:`stator_plan` with the via points its moves between points
    need in the demo cell (:func:`planner.check.vias.plan_with_vias`; opens the cell)."""
    from planner.check.vias import plan_with_vias
    from planner.plan_cell import open_cell

    plan = stator_plan()
    with open_cell(plan, DEMO_PLAN.parent) as cell:
        plan, _ = plan_with_vias(plan, cell)
    return plan_to_json(plan)


def make_demo_cell(geom: StatorGeometry | None = None, **cell_kwargs: Any) -> Cell:
    """The demo cell: built-in IRB 4400 with the cable-feeder tool, the stator on a table.

    The work object is the (bulged) stator mesh at :func:`nominal_T_base_wobj`; the robot base
    is the world frame. Extra keyword arguments go to :class:`planner.cell.cell.Cell`.
    """
    from planner.cell.cell import Cell  # PyBullet: only when a cell is built

    g = geom or StatorGeometry.full_section()
    kwargs: dict[str, Any] = {"robot": "builtin:irb4400", "tool": "builtin:cable_feeder"}
    kwargs.update(cell_kwargs)
    cell = Cell(**kwargs)
    T = demo_cell.nominal_T_base_wobj()
    cell.set_work_object(build_stator_mesh(g), units="m", T_world_wobj=T)
    size, T_table = demo_cell.demo_table(g, T)
    cell.add_fixture("table", size_m=size, T_world_fixture=T_table)
    return cell
