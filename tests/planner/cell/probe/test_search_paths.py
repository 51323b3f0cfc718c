"""Tests of planner.cell.probe.search_paths: approach and edge searches on a box, blocked by a
clamp."""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import replace

import numpy as np
import pytest
import trimesh

from calib.errors import DegenerateGeometryError, NonFiniteError
from calib.frames import make_transform
from calib.probing import ProbePoint, SearchCommand, SearchSpec
from planner.cell.cell import Cell

BOX = 0.4
X0 = 1.6  # box centre, world x: far enough for the front face to keep joint 3 off its limit
T_WORLD_WOBJ = make_transform(p=[X0, 0.0, 0.4])  # top face at world z = 0.6
TOP_APPROACH = ProbePoint(
    "A", (0.0, 0.0, BOX / 2), (0.0, 0.0, 1.0), SearchSpec("approach", 0.05, 0.02)
)
FRONT_EDGE = ProbePoint(
    "F",
    (-BOX / 2, 0.0, BOX / 2),
    (-1.0, 0.0, 0.0),
    SearchSpec("edge", 0.05, 0.02, edge_direction=(0.0, 0.0, 1.0)),
    edge_normal=(0.0, 0.0, 1.0),
)


@pytest.fixture(scope="module")
def cell() -> Iterator[Cell]:
    with Cell(use_acl_cache=False) as c:
        c.set_work_object(trimesh.creation.box([BOX] * 3), "m", T_WORLD_WOBJ, name="box")
        yield c


def _sensor_positions(cell: Cell, q_path: np.ndarray) -> np.ndarray:
    return (cell.chain.fk(q_path) @ cell.T_flange_tcp("sensor"))[:, :3, 3]


def test_approach_search_on_top_is_feasible(cell: Cell) -> None:
    cmd = SearchCommand.from_point(TOP_APPROACH, cell.T_base_wobj)
    res = cell.check_search(cmd)
    assert res.feasible and res.reason == "" and np.isnan(res.fail_at_m)
    assert res.s_m.size == 71 and np.diff(res.s_m).max() <= 0.001 + 1e-12
    assert res.q_path.shape == (71, 6)
    expected = cmd.start_m + res.s_m[:, None] * cmd.direction
    np.testing.assert_allclose(_sensor_positions(cell, res.q_path), expected, atol=1e-6)
    assert np.abs(np.diff(res.q_path, axis=0)).max() < np.radians(5)
    # one branch all along: the analytic solver classifies every sample the same
    codes = {cell.solver.abb_confdata(q)[3] for q in res.q_path}
    assert len(codes) == 1
    # the last 12 mm run the sensor into the nominal surface: allowed past the nominal point
    with cell.saved_state():
        cell.set_joint_positions(res.q_path[-1])
        assert not cell.clearance(sensor_wobj_allowed=True).ok


def test_long_overtravel_is_not_checked_against_the_nominal_part(cell: Cell) -> None:
    """60 mm past the surface the cable tubes would be 32 mm inside the nominal part; a real
    search stops at the surface wherever the part is, so only fixtures count there."""
    deep = replace(TOP_APPROACH, search=SearchSpec("approach", 0.05, 0.06))
    res = cell.check_search(SearchCommand.from_point(deep, cell.T_base_wobj))
    assert res.feasible, res.reason
    assert res.s_m[-1] == pytest.approx(0.11)


def test_search_into_a_clamp_fails_at_the_right_distance(cell: Cell) -> None:
    """A 20 mm clamp on the top face under the sensor: the sensor face starts 58 mm above the
    surface (50 mm start offset + 8 mm standoff) and must keep 5 mm from the clamp top."""
    top = 0.6 + 0.020
    cell.add_fixture(
        "clamp", size_m=(0.05, 0.05, 0.02), T_world_fixture=make_transform(p=[X0, 0.0, top - 0.01])
    )
    try:
        res = cell.check_search(
            SearchCommand.from_point(TOP_APPROACH, cell.T_base_wobj), margin_m=0.005
        )
    finally:
        cell.remove_fixture("clamp")
    expected = (0.6 + 0.05 + 0.008) - top - 0.005  # travel where the gap reaches 5 mm
    assert not res.feasible
    assert abs(res.fail_at_m - expected) <= 0.001 + 1e-9
    assert re.search(r"sensor_body is too near clamp \(clearance [45]\.0 mm\)", res.reason)
    assert res.reason.startswith(f"at {res.fail_at_m * 1e3:.1f} mm: ")
    assert res.q_path.shape[0] == int(np.searchsorted(res.s_m, res.fail_at_m))


def test_edge_search_up_the_front_face_is_feasible(cell: Cell) -> None:
    cmd = SearchCommand.from_point(FRONT_EDGE, cell.T_base_wobj)
    res = cell.check_search(cmd)
    assert res.feasible, res.reason
    pos = _sensor_positions(cell, res.q_path)
    np.testing.assert_allclose(pos[:, 0], X0 - BOX / 2, atol=1e-6)  # on the front face plane
    np.testing.assert_allclose(pos[[0, -1], 2], [0.55, 0.62], atol=1e-6)
    assert res.min_clearance_m > 0.005


@pytest.mark.slow
def test_a_search_leaving_the_workspace_fails_midway(cell: Cell) -> None:
    cmd = SearchCommand.from_point(TOP_APPROACH, cell.T_base_wobj)
    away = replace(cmd, kind="edge", direction=np.array([1.0, 0.0, 0.0]), length_m=1.0)
    res = cell.check_search(away)
    assert not res.feasible
    assert 0.1 < res.fail_at_m < 1.0
    assert "out of reach" in res.reason or "at limit" in res.reason
    # every sample before the failure passed, and is on the path
    pos = _sensor_positions(cell, res.q_path)
    np.testing.assert_allclose(
        pos, away.start_m + res.s_m[: len(pos), None] * away.direction, atol=1e-6
    )


def test_unreachable_start_and_joint_jumps(cell: Cell) -> None:
    cmd = SearchCommand.from_point(TOP_APPROACH, cell.T_base_wobj)
    shift = np.array([5.0, 0.0, 0.0])
    far = replace(cmd, start_m=cmd.start_m + shift, nominal_m=cmd.nominal_m + shift)
    res = cell.check_search(far)
    assert not res.feasible and res.fail_at_m == 0.0 and "out of reach" in res.reason
    tight = cell.check_search(cmd, max_joint_jump_rad=1e-6)
    assert not tight.feasible and tight.fail_at_m == pytest.approx(0.001)
    assert "jumps" in tight.reason


def test_bad_commands(cell: Cell) -> None:
    cmd = SearchCommand.from_point(TOP_APPROACH, cell.T_base_wobj)
    with pytest.raises(DegenerateGeometryError, match=r"command\.direction"):
        cell.check_search(replace(cmd, direction=np.zeros(3)))
    with pytest.raises(NonFiniteError, match=r"command\.start_m"):
        cell.check_search(replace(cmd, start_m=np.array([np.nan, 0.0, 0.0])))


@pytest.mark.slow
def test_numeric_ik_robot_runs_a_search(reference_dir) -> None:
    """UR5 (offset wrist, numeric IK): one approach search, continuous joints on the path."""
    with Cell(reference_dir / "robots" / "ur5" / "ur5.urdf", use_acl_cache=False) as ur5:
        # beside the arm's plane: straight in front, the upper arm passes the box within 5 mm
        ur5.set_work_object(trimesh.creation.box([0.2] * 3), "m", make_transform(p=[0.5, 0.2, 0.1]))
        point = replace(TOP_APPROACH, position_m=(0.0, 0.0, 0.1))
        res = ur5.check_search(SearchCommand.from_point(point, ur5.T_base_wobj))
        assert ur5.solver.kind == "numeric"
        assert res.feasible, res.reason
        pos = _sensor_positions(ur5, res.q_path)
    np.testing.assert_allclose(
        pos[:, :2], np.broadcast_to([0.5, 0.2], (res.s_m.size, 2)), atol=1e-5
    )
    np.testing.assert_allclose(pos[:, 2], 0.2 + 0.05 - res.s_m, atol=1e-5)
    assert np.abs(np.diff(res.q_path, axis=0)).max() < np.radians(5)


def test_a_given_sensor_x_and_branch_fix_the_rotation_and_the_configuration(cell: Cell) -> None:
    """The program runs the probe pose's orientation and configuration: with ``sensor_x`` and
    ``branch`` the path keeps that x axis (any axial component ignored) on that branch."""
    cmd = SearchCommand.from_point(TOP_APPROACH, cell.T_base_wobj)
    free = cell.check_search(cmd)
    x = np.array([np.cos(0.1), np.sin(0.1), 0.0])  # off the 15-deg grid
    res = cell.check_search(cmd, sensor_x=x + 0.3 * cmd.sensor_axis, branch=free.branch)
    assert res.feasible and res.branch == free.branch
    T = cell.chain.fk(res.q_path) @ cell.T_flange_tcp("sensor")
    np.testing.assert_allclose(T[:, :3, 0], np.repeat(x[None], len(T), axis=0), atol=1e-6)
    other = next(b for b in range(8) if b != free.branch)
    res_other = cell.check_search(cmd, sensor_x=x, branch=other, max_starts=1)
    if res_other.feasible:  # reachable on that branch too: then it is that branch
        assert res_other.branch == other
    with pytest.raises(DegenerateGeometryError, match="sensor_x"):
        cell.check_search(cmd, sensor_x=cmd.sensor_axis)


def test_a_branch_the_start_does_not_have_is_named(cell: Cell) -> None:
    cmd = SearchCommand.from_point(TOP_APPROACH, cell.T_base_wobj)
    res = cell.check_search(cmd, branch=99)
    assert not res.feasible and "no solution on IK branch 99" in res.reason
