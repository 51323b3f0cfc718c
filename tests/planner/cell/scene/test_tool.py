"""Tests of planner.cell.scene.tool: the built-in cable-feeder tool, TCP frames, tool loading
errors."""

from __future__ import annotations

import numpy as np
import pybullet as pb
import pytest
import trimesh

from calib.errors import ShapeError
from calib.frames import make_transform
from calib.models import ProximitySensor
from planner.cell.scene.tool import Tool, load_tool
from planner.errors import MeshError, UnknownBuiltinError, UnknownFrameError, URDFError

#: The plan's default sensor: the built-in tool's geometry must match it.
SENSOR = ProximitySensor()


@pytest.fixture(scope="module")
def feeder() -> Tool:
    return load_tool("builtin:cable_feeder")


def test_builtin_tool_has_the_papers_tcps(feeder: Tool) -> None:
    assert feeder.tcp_names == ["flange", "sensor", "tube_1", "tube_2"]
    assert feeder.sensor_tcp == "sensor"
    np.testing.assert_array_equal(feeder.T_flange_tcp("flange"), np.eye(4))


def test_sensor_tcp_lies_at_the_sensing_distance_in_front_of_the_sensor_face(feeder: Tool) -> None:
    """Measured on the PyBullet body: the sensor cylinder's face and diameter."""
    client = pb.connect(pb.DIRECT)
    try:
        body = feeder.create_body(client)
        lo, hi = pb.getAABB(body.body_id, body.index("sensor_body"), physicsClientId=client)
    finally:
        pb.disconnect(client)
    T = feeder.T_flange_tcp("sensor")
    # sensor +z is the flange z (pointing away from the tool, into the surface)
    np.testing.assert_allclose(T[:3, 2], [0, 0, 1], atol=1e-12)
    assert T[2, 3] - hi[2] == pytest.approx(SENSOR.sensing_distance_m, abs=1e-6)
    assert hi[0] - lo[0] == pytest.approx(SENSOR.face_diameter_m, abs=1e-6)
    assert (lo[0] + hi[0]) / 2 == pytest.approx(T[0, 3], abs=1e-9)  # on the sensor axis
    # the sensor protrudes beyond the cable tubes, so it can probe a flat face
    assert T[2, 3] - SENSOR.sensing_distance_m > feeder.T_flange_tcp("tube_1")[2, 3]


def test_tube_tcps_are_symmetric(feeder: Tool) -> None:
    t1, t2 = feeder.T_flange_tcp("tube_1"), feeder.T_flange_tcp("tube_2")
    assert t1[1, 3] == pytest.approx(-t2[1, 3])
    assert t1[1, 3] != 0


def test_unknown_tcp_lists_valid_names(feeder: Tool) -> None:
    with pytest.raises(UnknownFrameError, match=r"'probe'.*sensor.*tube_1"):
        feeder.T_flange_tcp("probe")


def test_unknown_builtin_tool() -> None:
    with pytest.raises(UnknownBuiltinError, match=r"builtin:cable_feeder"):
        load_tool("builtin:welding_gun")


def test_tool_from_mesh_with_tcp_dict() -> None:
    mesh = trimesh.creation.cylinder(radius=0.03, height=0.2)
    mesh.apply_translation([0, 0, 0.1])
    T = make_transform(p=[0, 0, 0.208])
    tool = Tool.from_mesh(mesh, {"sensor": T}, name="pen", sensor_tcp="sensor")
    np.testing.assert_array_equal(tool.T_flange_tcp("sensor"), T)
    client = pb.connect(pb.DIRECT)
    try:
        body = tool.create_body(client)
        _, hi = pb.getAABB(body.body_id, -1, physicsClientId=client)
    finally:
        pb.disconnect(client)
    assert 0.2 <= hi[2] <= 0.2 + 3e-3  # the hull top, plus Bullet's AABB margin


def test_tool_from_mesh_bad_inputs() -> None:
    with pytest.raises(MeshError, match=r"empty"):
        Tool.from_mesh(trimesh.Trimesh(), {})
    box = trimesh.creation.box([0.1, 0.1, 0.1])
    with pytest.raises(ShapeError, match=r"tcps\['s'\]"):
        Tool.from_mesh(box, {"s": np.eye(3)})
    with pytest.raises(UnknownFrameError, match=r"sensor_tcp"):
        Tool.from_mesh(box, {"s": np.eye(4)}, sensor_tcp="sensor")


def test_tool_urdf_errors_name_the_file(tmp_path) -> None:
    missing = tmp_path / "nope.urdf"
    with pytest.raises(URDFError, match=r"nope\.urdf"):
        load_tool(missing)
    bad = tmp_path / "bad.urdf"
    bad.write_text('<robot name="x"><link name="a"></robot>')
    with pytest.raises(URDFError, match=r"bad\.urdf"):
        load_tool(bad)
    moving = tmp_path / "moving.urdf"
    moving.write_text(
        '<robot name="m"><link name="a"/><link name="b"/>'
        '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
        '<limit lower="0" upper="1" effort="1" velocity="1"/></joint></robot>'
    )
    with pytest.raises(URDFError, match=r"not fixed"):
        load_tool(moving)
    desc = tmp_path / "tool.json"
    desc.write_text('{"urdf": "moving.urdf"')
    with pytest.raises(URDFError, match=r"tool\.json"):
        load_tool(desc)


def test_tool_urdf_tcps_compose_fixed_joints(tmp_path) -> None:
    urdf = tmp_path / "t.urdf"
    urdf.write_text(
        '<robot name="t"><link name="mount"/><link name="arm"/><link name="tip"/>'
        '<joint name="a" type="fixed"><parent link="mount"/><child link="arm"/>'
        '<origin xyz="0 0 0.1" rpy="0 0 1.5707963267948966"/></joint>'
        '<joint name="b" type="fixed"><parent link="arm"/><child link="tip"/>'
        '<origin xyz="0.05 0 0" rpy="0 0 0"/></joint></robot>'
    )
    tool = Tool.from_urdf(urdf)
    assert tool.tcp_names == ["arm", "flange", "tip"]
    # arm is turned 90 deg about z, so its x offset lands on flange y
    np.testing.assert_allclose(tool.T_flange_tcp("tip")[:3, 3], [0, 0.05, 0.1], atol=1e-12)
    with pytest.raises(URDFError, match=r"no link 'nib'"):
        Tool.from_urdf(urdf, tcps=["nib"])


def test_fingerprint_changes_with_geometry(feeder: Tool) -> None:
    assert feeder.fingerprint() == feeder.urdf_path.read_bytes()
    a = Tool.from_mesh(trimesh.creation.box([0.1, 0.1, 0.1]), {})
    b = Tool.from_mesh(trimesh.creation.box([0.1, 0.1, 0.2]), {})
    assert a.fingerprint() != b.fingerprint()


def test_tool_urdf_with_a_moving_joint_names_the_file_and_the_joint(tmp_path) -> None:
    arm = tmp_path / "arm.urdf"
    arm.write_text(
        '<robot name="m"><link name="a"/><link name="b"/><link name="c"/>'
        '<joint name="fix" type="fixed"><parent link="a"/><child link="b"/></joint>'
        '<joint name="wrist" type="continuous"><parent link="b"/><child link="c"/></joint></robot>'
    )
    with pytest.raises(URDFError, match=r"arm\.urdf: <joint name='wrist'> is continuous, not fix"):
        Tool.from_urdf(arm)


def test_single_link_tool_has_only_the_flange(tmp_path) -> None:
    one = tmp_path / "plate.urdf"
    one.write_text('<robot name="p"><link name="mount"/></robot>')
    assert Tool.from_urdf(one).tcp_names == ["flange"]
