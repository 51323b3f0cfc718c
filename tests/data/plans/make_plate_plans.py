"""Regenerate ``assets/plans/plate_holes_321.json`` and ``plate_holes_best_fit.json``.

Run ``python tests/data/plans/make_plate_plans.py`` (with ``../shared/reference`` present);
``tests/planner/check/test_plate_plans.py`` checks that the shipped files equal :func:`plate_plans`
byte for
byte, so this module stays their single source.

The part is the machined plate of ``../shared/reference/parts/plate_holes.STL`` (millimetres:
8 x 12 x 0.5 in, a flat top with five through-holes, side faces flat for their upper 6.35 mm
and rounded below). It lies flat on a pedestal (a 100 x 200 mm box, so the plate overhangs it
on every side) 0.75 m up and 1.3 m in front of the built-in IRB 4400 with the cable-feeder
tool, whose sensor TCP carries a touch probe with a 2 mm ball (the flat band of the sides is
too narrow for the 18 mm proximity sensor: the planar-face check refuses it). Every point is
reachable and collision-free (``wobjcal check``). The misplacement is 3 mm and 1 deg (a plate
laid against stops by hand); searches start 15 mm out and run 15 mm past the face. The points
avoid the holes and the rounded corners; the top points come first, so the side points are
commanded after the top has fixed the height (3-2-1: primary first; best fit: progressive).
"""

from __future__ import annotations

import math
from pathlib import Path

from calib.models import Misplacement, TouchProbe
from calib.plan.file import (
    CellSpec,
    FixtureSpec,
    Plan,
    PlanPoint,
    Pose,
    RobotSpec,
    ToolSpec,
    ValidationSpec,
    WorkObjectSpec,
    file_sha256,
    save_plan,
)
from calib.probing import ProbePoint, SearchSpec
from calib.procedures import BestFit, ThreeTwoOne

REPO = Path(__file__).resolve().parents[3]
PLANS = REPO / "assets" / "plans"
MESH = REPO.parent / "shared" / "reference" / "parts" / "plate_holes.STL"
#: The mesh, relative to ``assets/plans``.
MESH_REF = "../../../shared/reference/parts/plate_holes.STL"
TOP, SIDE_X, SIDE_Y, SIDE_Y2 = (0, 0, 1), (-1, 0, 0), (0, -1, 0), (0, 1, 0)
Z_TOP, Z_SIDE = 12.7, 9.525  # mm: the top, and the middle of the sides' flat band


def _points(spots: list[tuple[str, str, tuple[float, float, float], tuple]]) -> list[PlanPoint]:
    search = SearchSpec("approach", start_offset_m=0.015, overtravel_m=0.015)
    return [
        PlanPoint.from_probe_point(
            ProbePoint(pid, tuple(v * 1e-3 for v in xyz), normal, search), role
        )
        for pid, role, xyz, normal in spots
    ]


def plate_plans() -> dict[str, Plan]:
    """The 3-2-1 and the best-fit plan, by file name."""
    common = {
        "cell": CellSpec(
            robot=RobotSpec(urdf="builtin:irb4400"),
            tool=ToolSpec(name="builtin:cable_feeder", tcp="sensor"),
            fixtures=[
                FixtureSpec(
                    name="pedestal",
                    box_size_m=(0.10, 0.20, 0.74),
                    T_world_fixture=Pose(position_m=(1.4016, 0.0, 0.37)),
                )
            ],
        ),
        "work_object": WorkObjectSpec(
            mesh=MESH_REF,
            units="mm",
            sha256=file_sha256(MESH),
            T_world_wobj=Pose(position_m=(1.3, -0.1524, 0.75)),
        ),
        "validation": ValidationSpec(
            sensor=TouchProbe(tip_diameter_m=0.002),
            misplacement=Misplacement(max_translation_m=0.003, max_angle_rad=math.radians(1.0)),
        ),
    }
    p321 = Plan(
        name="plate_holes_321",
        description=(
            "3-2-1 on the machined plate (8 x 12 x 0.5 in, mm mesh) with a touch probe: 3 points "
            "on the top, 2 on the side facing the robot, 1 on the -y side; the plate lies on a "
            "pedestal in front of the IRB 4400."
        ),
        points=_points(
            [
                ("P1", "primary", (30, 160, Z_TOP), TOP),
                ("P2", "primary", (175, 100, Z_TOP), TOP),
                ("P3", "primary", (175, 220, Z_TOP), TOP),
                ("S1", "secondary", (0, 60, Z_SIDE), SIDE_X),
                ("S2", "secondary", (0, 245, Z_SIDE), SIDE_X),
                ("T1", "tertiary", (120, 0, Z_SIDE), SIDE_Y),
            ]
        ),
        procedure=ThreeTwoOne(),
        **common,
    )
    best = Plan(
        name="plate_holes_best_fit",
        description=(
            "10-point best fit on the machined plate (8 x 12 x 0.5 in, mm mesh) with a touch "
            "probe: 4 points on the top (measured first), 3 on the side facing the robot, 2 on "
            "the -y side, 1 on the +y side."
        ),
        points=_points(
            [
                ("T1", "fit", (30, 160, Z_TOP), TOP),
                ("T2", "fit", (175, 100, Z_TOP), TOP),
                ("T3", "fit", (175, 220, Z_TOP), TOP),
                ("T4", "fit", (100, 60, Z_TOP), TOP),
                ("X1", "fit", (0, 40, Z_SIDE), SIDE_X),
                ("X2", "fit", (0, 150, Z_SIDE), SIDE_X),
                ("X3", "fit", (0, 265, Z_SIDE), SIDE_X),
                ("Y1", "fit", (60, 0, Z_SIDE), SIDE_Y),
                ("Y2", "fit", (150, 0, Z_SIDE), SIDE_Y),
                ("Y3", "fit", (100, 304.8, Z_SIDE), SIDE_Y2),
            ]
        ),
        procedure=BestFit(),
        **common,
    )
    return {"plate_holes_321.json": _with_vias(p321), "plate_holes_best_fit.json": _with_vias(best)}


def _with_vias(plan: Plan) -> Plan:
    """The plan with the via points its moves between points need in its cell
    (:func:`planner.check.vias.plan_with_vias`)."""
    from planner.check.vias import plan_with_vias
    from planner.plan_cell import open_cell

    with open_cell(plan, PLANS) as cell:
        return plan_with_vias(plan, cell)[0]


def main() -> None:
    """Write the plans into ``assets/plans``."""
    for name, plan in plate_plans().items():
        save_plan(plan, PLANS / name)


if __name__ == "__main__":
    main()
