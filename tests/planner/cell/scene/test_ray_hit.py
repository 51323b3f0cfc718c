"""Tests of planner.cell.scene.ray_hit: the first body a ray meets, on a box, a post and the robot
posed over the box (known geometry: the box's faces and the post's radius)."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest

from calib.errors import ShapeError
from planner.cell.cell import Cell
from planner.cell.scene.ray_hit import first_hit
from tests.cells import add_box_on_table

#: The box (work object ``part``) is 0.6 x 0.5 x 0.4 m centred at (1.3, 0.1, 0.45): its top
#: face is z = 0.65, its -y face y = -0.15; the post (radius 50 mm) stands at POST.
TOP_Z, FACE_Y = 0.65, -0.15
POST = (1.3, -0.5, 0.55)


@pytest.fixture(scope="module")
def cell() -> Iterator[Cell]:
    with Cell(use_acl_cache=False) as c:
        add_box_on_table(c, 0.1, POST)
        yield c


def test_a_ray_down_onto_the_box_hits_the_part_at_its_top_face(cell: Cell) -> None:
    hit = first_hit(cell, (1.55, 0.3, 2.0), (0.0, 0.0, -3.0))  # direction need not be unit
    assert hit is not None and hit.kind == "work object" and hit.name == "part"
    assert hit.distance_m == pytest.approx(2.0 - TOP_Z, abs=1e-4)
    np.testing.assert_allclose(hit.position_world, (1.55, 0.3, TOP_Z), atol=1e-4)
    assert first_hit(cell, (1.55, 0.3, 2.0), (0.0, 0.0, 1.0)) is None, "up: nothing"


def test_a_fixture_in_front_of_the_part_is_hit_first(cell: Cell) -> None:
    # along +y through the post's axis, then into the box's -y face
    origin = np.array([POST[0], -2.0, 0.6])
    hit = first_hit(cell, origin, (0.0, 1.0, 0.0))
    assert hit is not None and (hit.kind, hit.name) == ("fixture", "post"), hit
    assert hit.distance_m == pytest.approx(POST[1] - 0.05 - origin[1], abs=2e-3)
    assert hit.describe() == "the fixture post"
    past = first_hit(cell, origin + np.array([0.0, 1.6, 0.0]), (0.0, 1.0, 0.0))  # beyond the post
    assert past is not None and past.kind == "work object"
    assert past.distance_m == pytest.approx(FACE_Y - (origin[1] + 1.6), abs=1e-4)


def test_the_robot_posed_over_the_part_is_hit_before_it(cell: Cell) -> None:
    """The same vertical ray meets the part with the robot at home, and the tool or a link
    with the robot at a probe pose over that point; the cell's joint values are kept."""
    target = np.array([1.55, 0.3, TOP_Z])
    (pose,) = cell.check_probes(
        (target - cell.T_world_wobj[:3, 3])[None], np.array([[0.0, 0.0, 1.0]])
    )
    assert pose.q is not None and pose.feasible, pose
    q_before = cell.joint_positions
    origin, down = target + np.array([0.0, 0.0, 1.5]), (0.0, 0.0, -1.0)
    at_home = first_hit(cell, origin, down, q=cell.home_q)
    assert at_home is not None and at_home.kind == "work object"
    over = first_hit(cell, origin, down, q=pose.q)
    assert over is not None and over.kind in ("tool", "robot"), over
    assert over.distance_m < 1.5 - 0.01, "above the part's surface"
    assert over.describe().startswith(f"the {over.kind} (link ")
    np.testing.assert_array_equal(cell.joint_positions, q_before)


@pytest.mark.parametrize(
    ("origin", "direction"),
    [((0, 0), (0, 0, 1)), ((0, 0, 0), (0, 0, 0)), ((0, 0, np.nan), (0, 0, 1))],
)
def test_bad_rays_are_refused(cell: Cell, origin: tuple, direction: tuple) -> None:
    with pytest.raises(ShapeError, match="ray"):
        first_hit(cell, origin, direction)
