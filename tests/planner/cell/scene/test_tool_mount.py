"""The tool's mount on the flange (issue 10, item 2): along the last joint's axis whatever the
tip frame's convention, refused naming the plan field when it cannot be told, and never a tool
link allowed against a robot link other than the ones it is mounted on."""

from __future__ import annotations

from pathlib import Path

import msgspec
import numpy as np
import pytest

from calib.frames import make_transform, matrix_from_rotvec
from calib.plan.file import Pose, load_plan
from planner.builtins import robot_urdf
from planner.cell.scene.tool import MOUNT_FIELD, flange_axis, tool_mount
from planner.check.job import check_plan
from planner.errors import ToolMountError
from planner.robot.kinematics.chain import KinematicChain

REPO = Path(__file__).resolve().parents[4]
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"
TOOL0 = '<joint name="joint_6-tool0" type="fixed">'


def _robot_with_tool0(tmp_path: Path, rpy: str) -> Path:
    """The built-in IRB 4400 with another tool0 rotation on link_6 (``rpy`` of the joint)."""
    text = robot_urdf("builtin:irb4400").read_text()
    i = text.index(TOOL0)
    j = text.index("</joint>", i)
    joint = text[i:j].replace('rpy="0 1.5707963267948966 0"', f'rpy="{rpy}"')
    assert joint != text[i:j]
    path = tmp_path / "irb4400_tool0.urdf"
    path.write_text(text[:i] + joint + text[j:])
    return path


def _plan_with_robot(urdf: Path, mount: Pose | None = None):  # type: ignore[no-untyped-def]
    plan = load_plan(STATOR)
    robot = msgspec.structs.replace(plan.cell.robot, urdf=str(urdf))
    tool = msgspec.structs.replace(plan.cell.tool, T_flange_tool=mount or msgspec.UNSET)
    cell = msgspec.structs.replace(plan.cell, robot=robot, tool=tool)
    return msgspec.structs.replace(plan, cell=cell)


def test_the_flange_axis_is_found_in_either_convention(tmp_path: Path) -> None:
    z_out = KinematicChain.from_urdf(robot_urdf("builtin:irb4400"))
    np.testing.assert_allclose(flange_axis(z_out), [0, 0, 1], atol=1e-9)
    np.testing.assert_allclose(tool_mount(z_out), np.eye(4), atol=1e-12)
    x_out = KinematicChain.from_urdf(_robot_with_tool0(tmp_path, "0 0 0"))  # ROS-I ABB style
    np.testing.assert_allclose(flange_axis(x_out), [1, 0, 0], atol=1e-9)
    mount = tool_mount(x_out)
    np.testing.assert_allclose(mount[:3, 2], [1, 0, 0], atol=1e-12)  # tool z along tip x
    # the tool ends up where the z-out robot has it
    T_zout = z_out.fk(np.zeros(6))[0]
    T_xout = x_out.fk(np.zeros(6))[0] @ mount
    np.testing.assert_allclose(T_xout, T_zout, atol=1e-12)


def test_a_tilted_flange_is_refused_naming_the_plan_field(tmp_path: Path) -> None:
    tilted = KinematicChain.from_urdf(_robot_with_tool0(tmp_path, "0 0.3 0"))
    with pytest.raises(ToolMountError, match=rf"not along one of its axes.*set {MOUNT_FIELD}"):
        tool_mount(tilted)
    given = make_transform(matrix_from_rotvec([0, np.pi / 2 - 0.3, 0]), [0, 0, 0])
    np.testing.assert_allclose(tool_mount(tilted, given), given)
    plan = _plan_with_robot(tilted.urdf_path)  # type: ignore[arg-type]
    with pytest.raises(ToolMountError, match=MOUNT_FIELD):
        check_plan(plan, STATOR.parent)


@pytest.mark.slow
def test_x_out_vendor_urdf_checks_like_the_z_out_one(tmp_path: Path) -> None:
    """Before: the tool stuck sideways through the wrist, every point 'feasible' with confdata
    of an impossible pose. Now the check, poses and confdata equal those of the same robot with
    tool0 turned z-out (the built-in), point by point."""
    want = check_plan(load_plan(STATOR), STATOR.parent)
    got = check_plan(_plan_with_robot(_robot_with_tool0(tmp_path, "0 0 0")), STATOR.parent)
    assert [p.status for p in got.points] == [p.status for p in want.points]
    assert [p.confdata for p in got.points] == [p.confdata for p in want.points]
    for g, w in zip(got.points, want.points, strict=True):
        assert g.q is not None and w.q is not None
        np.testing.assert_allclose(g.q, w.q, atol=1e-6)
        np.testing.assert_allclose(g.T_base_tcp, w.T_base_tcp, atol=1e-9)
        assert g.clearance_pair == w.clearance_pair


@pytest.mark.slow
def test_the_plan_mount_is_used_and_exported(tmp_path: Path) -> None:
    """A tilted vendor flange with the mount given in the plan: the cell and the exported
    tool data use it (the controller's flange is the mount's rotation of the tip frame)."""
    from planner.plan_cell import tool_data

    urdf = _robot_with_tool0(tmp_path, "0 0.3 0")
    mount = make_transform(matrix_from_rotvec([0, np.pi / 2 - 0.3, 0]), [0, 0, 0])
    plan = _plan_with_robot(urdf, Pose.from_matrix(mount))
    want = check_plan(load_plan(STATOR), STATOR.parent)
    got = check_plan(plan, STATOR.parent)
    assert [p.confdata for p in got.points] == [p.confdata for p in want.points]
    tool, _ = tool_data(plan, STATOR.parent)
    builtin, _ = tool_data(load_plan(STATOR), STATOR.parent)
    np.testing.assert_allclose(tool.T_flange_tcp, builtin.T_flange_tcp, atol=1e-12)


def _rod_tool(tmp_path: Path) -> Path:
    """A tool whose rod runs back from the flange through the robot's wrist."""
    path = tmp_path / "rod_tool.urdf"
    path.write_text(
        """<robot name="rod_tool">
  <link name="mount"><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry>
  </collision></link>
  <link name="rod"><collision><origin xyz="0 0 -0.15"/><geometry>
    <cylinder radius="0.02" length="0.3"/></geometry></collision></link>
  <link name="sensor"/>
  <joint name="mount-rod" type="fixed"><parent link="mount"/><child link="rod"/></joint>
  <joint name="mount-sensor" type="fixed"><parent link="mount"/><child link="sensor"/>
    <origin xyz="0 0 0.25"/></joint>
</robot>
"""
    )
    return path


def test_a_tool_through_the_wrist_is_never_allowed(tmp_path: Path) -> None:
    """Before: sampling found the rod near link_5 in every pose and allowed the pair, so the
    check called the points feasible. Now tool links are allowed only against the links the
    tool is mounted on, and every pose collides, naming the pair."""
    from planner.cell.cell import Cell

    with Cell("builtin:irb4400", _rod_tool(tmp_path), use_acl_cache=False) as cell:
        acl = cell.checker.acl
        wrist = {p for p in acl.allowed if "rod" in p}
        assert wrist <= {("link_6", "rod"), ("rod", "tool0")}, wrist
        assert acl.near_fraction[("link_5", "rod")] > 0.95  # what used to be allowed
        cell.set_joint_positions(np.array([0, 0.3, 0.2, 0, 0.5, 0]))
        c = cell.clearance()
        assert not c.ok and c.pair is not None and "rod" in c.pair, c.describe()


def test_fast_path_agrees_with_the_exact_check_for_a_mounted_tool(tmp_path: Path) -> None:
    """The broad phase and the staged exact parts pose the tool through its mount, as the cell
    does: on an x-out flange (mount = a quarter turn) the fast path gives the exact check's
    answers. Before, both posed the tool on the bare flange and C came out with a different
    pose and a clearance of 15 mm instead of 9.9 mm (link_4 - tool_mount)."""
    from planner.plan_cell import open_cell

    plan = _plan_with_robot(_robot_with_tool0(tmp_path, "0 0 0"))
    P = np.array([p.position_m for p in plan.points])
    N = np.array([p.normal for p in plan.points])
    with open_cell(plan, STATOR.parent) as cell:
        assert not np.allclose(cell.T_flange_tool, np.eye(4))
        fast = cell.check_probes(P, N, tcp="sensor")
        exact = cell.check_probes(P, N, tcp="sensor", staged=False)
    for f, e in zip(fast, exact, strict=True):
        assert (f.status, f.reason, f.clearance_pair) == (e.status, e.reason, e.clearance_pair)
        np.testing.assert_allclose(f.q, e.q, atol=1e-12)
        assert f.clearance_m == pytest.approx(e.clearance_m, abs=1e-9)
