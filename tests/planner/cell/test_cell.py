"""Tests of planner.cell.cell: the Cell's client, frames, joint state, scene and bad input."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pybullet as pb
import pybullet_data
import pytest
import trimesh

from calib.errors import NonFiniteError, ShapeError
from calib.frames import invert_transform, make_transform, matrix_from_rotvec
from planner.cell.cell import Cell
from planner.cell.scene.tool import Tool
from planner.errors import MeshError, UnknownBuiltinError, UnknownFrameError, URDFError

T_WORLD_BASE = make_transform(matrix_from_rotvec([0, 0, 0.3]), [0.5, -0.2, 0.1])


@pytest.fixture(scope="module")
def cell() -> Iterator[Cell]:
    with Cell(T_world_base=T_WORLD_BASE, use_acl_cache=False) as c:
        yield c


def test_builtin_robot_takes_the_analytic_path(cell: Cell) -> None:
    assert cell.solver.kind == "opw"
    assert cell.chain.n_joints == 6
    assert np.degrees(cell.chain.upper[4]) == pytest.approx(120.0)


def test_link_poses_follow_the_chain_and_the_base_pose(cell: Cell, rng) -> None:
    q = rng.uniform(cell.chain.lower, cell.chain.upper)
    cell.set_joint_positions(q)
    np.testing.assert_allclose(cell.joint_positions, q, atol=1e-12)
    poses = cell.link_poses()
    T_world_flange = T_WORLD_BASE @ cell.chain.fk(q)[0]
    np.testing.assert_allclose(poses[cell.chain.tip_link], T_world_flange, atol=1e-6)
    # the tool rides on the flange: its sensor TCP link is where the tool says
    np.testing.assert_allclose(
        poses["sensor"], T_world_flange @ cell.T_flange_tcp("sensor"), atol=1e-6
    )
    np.testing.assert_allclose(poses["base_link"], T_WORLD_BASE, atol=1e-7)


def test_saved_state_restores_joints_and_tool(cell: Cell) -> None:
    q0 = cell.home_q + 0.1
    cell.set_joint_positions(q0)
    before = cell.link_poses()["sensor"]
    with cell.saved_state():
        cell.set_joint_positions(q0 + 0.3)
        assert not np.allclose(cell.link_poses()["sensor"], before)
    np.testing.assert_allclose(cell.joint_positions, q0, atol=1e-12)
    np.testing.assert_allclose(cell.link_poses()["sensor"], before, atol=1e-9)


def test_work_object_frames(cell: Cell) -> None:
    T_world_wobj = make_transform(matrix_from_rotvec([0.1, 0.2, 0.3]), [1.5, 0.2, 0.4])
    wobj = cell.set_work_object(trimesh.creation.box([0.2, 0.2, 0.2]), "m", T_world_wobj)
    assert cell.work_object is wobj
    np.testing.assert_allclose(cell.T_world_wobj, T_world_wobj)
    np.testing.assert_allclose(
        cell.T_base_wobj, invert_transform(T_WORLD_BASE) @ T_world_wobj, atol=1e-12
    )
    # replacing the work object removes the old body
    n = pb.getNumBodies(physicsClientId=cell.client)
    cell.set_work_object(trimesh.creation.box([0.1, 0.1, 0.1]), "m", T_world_wobj)
    assert pb.getNumBodies(physicsClientId=cell.client) == n


def test_fixtures_by_name_and_duplicates(cell: Cell) -> None:
    f = cell.add_fixture("post", radius_m=0.05, height_m=0.5, T_world_fixture=np.eye(4))
    assert cell.fixtures["post"] is f and f.shape == "cylinder"
    with pytest.raises(ShapeError, match=r"'post' already exists"):
        cell.add_fixture("post", size_m=(1, 1, 1))


def test_bad_scene_input(cell: Cell) -> None:
    bad = np.eye(4)
    bad[0, 3] = np.nan
    with pytest.raises(NonFiniteError, match="T_world_wobj"):
        cell.set_work_object(trimesh.creation.box([0.1] * 3), "m", bad)
    with pytest.raises(NonFiniteError, match="T_world_fixture"):
        cell.add_fixture("clamp", size_m=(0.1, 0.1, 0.1), T_world_fixture=bad)
    with pytest.raises(ShapeError, match=r"'clamp' needs size_m"):
        cell.add_fixture("clamp", radius_m=0.1)
    with pytest.raises(UnknownFrameError, match="no fixture 'vice'"):
        cell.remove_fixture("vice")
    with pytest.raises(NonFiniteError, match="T_world_base"):
        Cell(T_world_base=bad)


def test_bad_joint_values(cell: Cell) -> None:
    with pytest.raises(NonFiniteError, match=r"q"):
        cell.set_joint_positions([0, 0, np.nan, 0, 0, 0])
    with pytest.raises(ShapeError, match=r"q must be \(6\)"):
        cell.set_joint_positions([0, 0, 0])


def test_unknown_tcp_lists_names(cell: Cell) -> None:
    with pytest.raises(UnknownFrameError, match=r"tube_2"):
        cell.T_flange_tcp("nozzle")


def test_bad_mesh_names_the_file(cell: Cell, tmp_path) -> None:
    with pytest.raises(MeshError, match=r"nothing\.stl"):
        cell.set_work_object(tmp_path / "nothing.stl")


def test_mesh_tool_rides_on_the_flange() -> None:
    pen = trimesh.creation.cylinder(radius=0.03, height=0.2)
    pen.apply_translation([0, 0, 0.1])
    tool = Tool.from_mesh(pen, {"tip": make_transform(p=[0, 0, 0.2])}, name="pen")
    with Cell(tool=tool, use_acl_cache=False) as c:
        q = c.home_q + 0.2
        c.set_joint_positions(q)
        T_world_tip = c.chain.fk(q)[0] @ c.T_flange_tcp("tip")
        # a box right at the tip: the pen's hull touches it
        c.add_fixture(
            "stop",
            size_m=(0.05, 0.05, 0.05),
            T_world_fixture=T_world_tip @ make_transform(p=[0, 0, 0.025 + 0.004]),
        )
        cl = c.clearance(margin_m=0.005)
    assert cl.pair == ("pen", "stop")
    assert cl.clearance_m == pytest.approx(0.004, abs=1.5e-3)  # hull of a polygonal cylinder


def test_close_and_context_manager() -> None:
    c = Cell(tool=None, use_acl_cache=False)
    client = c.client
    assert pb.isConnected(physicsClientId=client)
    c.close()
    c.close()  # idempotent
    assert not pb.isConnected(physicsClientId=client)
    with pytest.raises(RuntimeError, match=r"closed"):
        c.set_joint_positions(np.zeros(6))


def test_cells_do_not_share_clients() -> None:
    with Cell(use_acl_cache=False) as a, Cell(use_acl_cache=False) as b:
        assert a.client != b.client
        a.set_joint_positions(a.home_q + 0.2)
        np.testing.assert_allclose(b.joint_positions, b.home_q)


def test_bad_robot_urdf_names_the_file(tmp_path) -> None:
    with pytest.raises(URDFError, match=r"absent\.urdf"):
        Cell(robot=tmp_path / "absent.urdf")
    bad = tmp_path / "broken.urdf"
    bad.write_text('<robot name="x"><link name="a"></robot>')
    with pytest.raises(URDFError, match=r"broken\.urdf"):
        Cell(robot=bad)
    with pytest.raises(UnknownBuiltinError, match=r"builtin:irb4400"):
        Cell(robot="builtin:irb9999")


def test_vendor_urdfs_load(reference_dir) -> None:
    """UR5 (meshes, offset wrist) and PyBullet's KUKA iiwa (7 joints): numeric IK path."""
    for path, n in (
        (reference_dir / "robots" / "ur5" / "ur5.urdf", 6),
        (f"{pybullet_data.getDataPath()}/kuka_iiwa/model.urdf", 7),
    ):
        with Cell(robot=path, use_acl_cache=False, acl_samples=200) as c:
            assert c.solver.kind == "numeric"
            assert c.chain.n_joints == n
            q = c.home_q + 0.1
            c.set_joint_positions(q)
            np.testing.assert_allclose(
                c.link_poses()[c.chain.tip_link], c.chain.fk(q)[0], atol=1e-6
            )
