"""Test cells shared by several test modules (not a test module itself)."""

from __future__ import annotations

import trimesh

from calib.frames import make_transform
from planner.cell.cell import Cell


def add_box_on_table(
    cell: Cell, subdivide_m: float, post_xyz_m: tuple[float, float, float]
) -> None:
    """A dense 0.6 x 0.5 x 0.4 m box (work object ``part``, triangles at most ``subdivide_m``)
    on a 1 x 1 m table before the robot, and a 0.6 m post of radius 50 mm at ``post_xyz_m``
    (world frame, m)."""
    box = trimesh.creation.box([0.6, 0.5, 0.4]).subdivide_to_size(subdivide_m)
    cell.set_work_object(box, "m", make_transform(p=[1.3, 0.1, 0.45]), name="part")
    cell.add_fixture(
        "table", size_m=(1.0, 1.0, 0.05), T_world_fixture=make_transform(p=[1.3, 0, 0.225])
    )
    cell.add_fixture(
        "post", radius_m=0.05, height_m=0.6, T_world_fixture=make_transform(p=post_xyz_m)
    )
