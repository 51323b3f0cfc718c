"""A new point's default search sized to the part and the sensor (issue 22, item 6): on a thin
plate lying on a table the default overtravel stops short of the table (it was 20 mm: the
sensor ran into the table under a 12.7 mm plate); the start offset clears the sensing
distance; a misplacement needing more than the part allows keeps its own value."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import msgspec
import numpy as np
import pytest
import trimesh

from calib.frames import make_transform
from calib.models.misplacement import Misplacement
from calib.plan.file import (
    CellSpec,
    FixtureSpec,
    Plan,
    PlanPoint,
    Pose,
    RobotSpec,
    WorkObjectSpec,
    file_sha256,
)
from calib.probing import ProbePoint, SearchSpec
from calib.procedures import ThreeTwoOne
from planner.cell.scene.collision import DEFAULT_MARGIN_M
from webui import plan_doc
from webui.plan_adapter import plan_point, ui_plan_from_plan
from webui.search_room import SPARE_M, overtravel_cap_m, room_behind_m
from webui.surface import SurfacePicker

#: The plate: 200 x 300 x 12.7 mm, top face z = 0 (wobj), lying on the table.
PLATE = (0.2, 0.3, 0.0127)
TABLE_TOP_Z = 0.75
T_WORLD_WOBJ = make_transform(np.eye(3), [1.3, 0.0, TABLE_TOP_Z + PLATE[2]])
TABLE = FixtureSpec(
    name="table",
    box_size_m=(0.8, 0.8, TABLE_TOP_Z),
    T_world_fixture=Pose(position_m=(1.3, 0.0, TABLE_TOP_Z / 2)),
)


def _plate() -> trimesh.Trimesh:
    mesh = trimesh.creation.box(extents=PLATE)
    mesh.apply_translation((0.0, 0.0, -PLATE[2] / 2))
    return mesh


def _plan(folder: Path, misplacement: Misplacement) -> Plan:
    mesh_path = folder / "plate.stl"
    _plate().export(mesh_path)
    points = [
        PlanPoint.from_probe_point(ProbePoint(pid, pos, (0.0, 0.0, 1.0)), "primary")
        for pid, pos in (("P1", (-0.06, -0.1, 0.0)), ("P2", (0.06, -0.1, 0.0)))
    ]
    plan = Plan(
        name="plate_on_table",
        cell=CellSpec(robot=RobotSpec(urdf="builtin:irb4400"), fixtures=[TABLE]),
        work_object=WorkObjectSpec(
            mesh=mesh_path.name, units="m", sha256=file_sha256(mesh_path),
            T_world_wobj=Pose(position_m=tuple(float(v) for v in T_WORLD_WOBJ[:3, 3])),  # type: ignore[arg-type]
        ),
        points=points,
        procedure=ThreeTwoOne(),
    )  # fmt: skip
    return msgspec.structs.replace(
        plan, validation=msgspec.structs.replace(plan.validation, misplacement=misplacement)
    )


def _fixtures() -> dict[str, tuple[trimesh.Trimesh, np.ndarray]]:
    box = trimesh.creation.box(extents=TABLE.box_size_m)
    return {"table": (box, TABLE.T_world_fixture.matrix())}


def test_the_room_behind_a_point_is_the_plate_or_the_table() -> None:
    picker = SurfacePicker(_plate(), T_WORLD_WOBJ)
    top = room_behind_m(picker, _fixtures(), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    assert top == pytest.approx(PLATE[2], abs=1e-6)  # the plate ends where the table starts
    alone = room_behind_m(picker, {}, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    assert alone == pytest.approx(PLATE[2], abs=1e-6)  # leaves the part
    side = room_behind_m(picker, _fixtures(), (0.1, 0.0, -0.005), (1.0, 0.0, 0.0))
    assert side == pytest.approx(PLATE[0], abs=1e-6)  # through the plate's width
    sheet = trimesh.Trimesh(  # an open mesh (one face), 0.25 m above the table
        [[-0.1, -0.15, 0.0], [0.1, -0.15, 0.0], [0.1, 0.15, 0.0], [-0.1, 0.15, 0.0]],
        [[0, 1, 2], [0, 2, 3]],
    )
    lifted = SurfacePicker(sheet, make_transform(np.eye(3), [1.3, 0.0, 1.0]))
    below = room_behind_m(lifted, _fixtures(), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    assert below == pytest.approx(0.25, abs=1e-6)  # no part to leave: the table
    assert room_behind_m(lifted, _fixtures(), (0.0, 0.0, 0.0), (0.0, 0.0, -1.0)) is None
    cap = overtravel_cap_m(top, 0.008)
    assert cap == pytest.approx(PLATE[2] + 0.008 - DEFAULT_MARGIN_M - SPARE_M)
    assert overtravel_cap_m(None, 0.008) is None


def test_a_new_points_search_stops_short_of_the_table(tmp_path: Path) -> None:
    """With a small misplacement (3 mm, 1 deg) the default overtravel is what the plate and
    the sensor leave (14.7 mm for 12.7 mm, 8 mm sensing), not 20 mm, and the check passes;
    the old 20 mm ran the sensor into the table."""
    from planner.check.job import check_points
    from planner.plan_cell import open_cell

    plan = _plan(tmp_path, Misplacement(max_translation_m=0.003, max_angle_rad=math.radians(1)))
    doc = ui_plan_from_plan(plan)
    picker = SurfacePicker(_plate(), T_WORLD_WOBJ)
    p, n = np.array([0.0, 0.02, 0.0]), np.array([0.0, 0.0, 1.0])
    cap = overtravel_cap_m(room_behind_m(picker, _fixtures(), p, n), 0.008)
    new = plan_doc.place_point(doc, "Q", p, n, role="primary", max_overtravel_m=cap)
    search = new.get("Q").probe.search
    assert search.overtravel_m == pytest.approx(cap) and search.overtravel_m < 0.020
    sd = plan.validation.sensor.standoff_m
    assert search.start_offset_m >= sd + DEFAULT_MARGIN_M
    old = dataclasses.replace(
        new.get("Q"), probe=dataclasses.replace(new.get("Q").probe, search=SearchSpec())
    )
    with open_cell(plan, tmp_path) as cell:
        sized, default = check_points(
            cell, plan, [plan_point(new.get("Q")), plan_point(dataclasses.replace(old))]
        )
    assert sized.status in ("feasible", "marginal") and "table" not in sized.reason, sized.reason
    assert "table" in default.reason, "the old default ran into the table"


def test_the_misplacements_need_wins_over_the_part(tmp_path: Path) -> None:
    """A misplacement of 20 mm needs more overtravel than the plate leaves: its value is kept
    (the check then says the sensor meets the table, which is the truth)."""
    plan = _plan(tmp_path, Misplacement(max_translation_m=0.020, max_angle_rad=math.radians(3)))
    doc = ui_plan_from_plan(plan)
    p, n = np.array([0.0, 0.02, 0.0]), np.array([0.0, 0.0, 1.0])
    unlimited = plan_doc.place_point(doc, "Q", p, n, role="primary").get("Q").probe.search
    capped = plan_doc.place_point(doc, "Q", p, n, role="primary", max_overtravel_m=0.0147)
    assert capped.get("Q").probe.search == unlimited
    assert unlimited.overtravel_m > 0.020
