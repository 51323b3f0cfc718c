"""Tests of planner.cell.scene.fixtures: primitive and mesh fixtures at known poses."""

from __future__ import annotations

import numpy as np
import pybullet as pb
import pytest
import trimesh

from calib.errors import DegenerateGeometryError, ShapeError
from calib.frames import make_transform, matrix_from_rotvec
from planner.cell.scene.fixtures import Fixture, fixture_from_spec, table
from planner.errors import MeshError


def _distance_to_point(fixture: Fixture, p: list[float]) -> float:
    """Distance from a 1 mm sphere at ``p`` to the fixture, measured by PyBullet."""
    client = pb.connect(pb.DIRECT)
    try:
        body = fixture.create_body(client)
        shape = pb.createCollisionShape(pb.GEOM_SPHERE, radius=0.001, physicsClientId=client)
        probe = pb.createMultiBody(0, shape, basePosition=p, physicsClientId=client)
        pts = pb.getClosestPoints(probe, body.body_id, 1.0, physicsClientId=client)
    finally:
        pb.disconnect(client)
    return min(q[8] for q in pts) + 0.001


def test_box_fixture_is_centred_at_its_pose() -> None:
    T = make_transform(matrix_from_rotvec([0, 0, np.pi / 2]), [1.0, 2.0, 0.5])
    clamp = Fixture.box("clamp", (0.4, 0.1, 0.2), T)
    # rotated 90 deg about z: the 0.4 side runs along world y
    assert _distance_to_point(clamp, [1.0, 2.0 + 0.2 + 0.05, 0.5]) == pytest.approx(0.05)
    assert _distance_to_point(clamp, [1.0 + 0.05 + 0.03, 2.0, 0.5]) == pytest.approx(0.03)


def test_cylinder_fixture() -> None:
    post = Fixture.cylinder("post", 0.05, 0.3, make_transform(p=[0, 0, 0.15]))
    assert _distance_to_point(post, [0.15, 0.0, 0.1]) == pytest.approx(0.10, abs=1e-6)
    assert _distance_to_point(post, [0.0, 0.0, 0.35]) == pytest.approx(0.05, abs=1e-6)


def test_table_top_height() -> None:
    t = table(top_z_m=0.8, size_m=(1.0, 2.0, 0.04), center_xy_m=(0.5, 0.0))
    assert t.name == "table"
    assert _distance_to_point(t, [0.5, 0.0, 0.85]) == pytest.approx(0.05)
    assert t.T_world_fixture[2, 3] == pytest.approx(0.78)


def test_mesh_fixture_is_concave() -> None:
    ring = trimesh.creation.annulus(r_min=0.1, r_max=0.2, height=0.05)
    f = Fixture.from_mesh("ring", ring, make_transform(p=[0, 0, 0]), units="m")
    assert f.shape == "mesh"
    # the centre of the hole is 0.1 m from the (polygonal) inner wall, not inside a hull
    assert _distance_to_point(f, [0.0, 0.0, 0.0]) == pytest.approx(0.1, abs=2e-3)


def test_bad_fixtures() -> None:
    with pytest.raises(ShapeError, match=r"'clamp'.*size_m"):
        Fixture.box("clamp", (0.1, 0.1))
    with pytest.raises(ShapeError, match=r"'clamp'.*size_m"):
        Fixture.box("clamp", (0.1, -0.1, 0.1))
    with pytest.raises(ShapeError, match=r"radius_m"):
        Fixture.cylinder("post", 0.0, 1.0)
    with pytest.raises(DegenerateGeometryError, match=r"T_world_fixture"):
        Fixture.box("clamp", (0.1, 0.1, 0.1), np.diag([1.0, 1.0, -1.0, 1.0]))
    with pytest.raises(MeshError, match=r"nope\.stl"):
        Fixture.from_mesh("m", "nope.stl")


def test_fixture_from_keywords() -> None:
    T = make_transform(p=[0.0, 0.0, 1.0])
    assert fixture_from_spec("a", size_m=(1, 2, 3), T_world_fixture=T).shape == "box"
    assert fixture_from_spec("b", radius_m=0.1, height_m=0.2).size_m == (0.1, 0.2)
    ring = trimesh.creation.annulus(r_min=0.1, r_max=0.2, height=0.05)
    assert fixture_from_spec("c", mesh=ring, units="m").shape == "mesh"
    with pytest.raises(ShapeError, match=r"'d' needs size_m"):
        fixture_from_spec("d", radius_m=0.1)
