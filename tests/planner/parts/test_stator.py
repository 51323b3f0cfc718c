"""The stator section: dimensions, watertight mesh with real slot holes, bulge, ground truth."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from calib.errors import ShapeError
from planner.parts.stator import EPSILON_M, StatorGeometry
from planner.parts.stator_mesh import build_stator_mesh
from planner.sim.raycast import MeshRayCaster


@pytest.fixture(scope="module")
def proto() -> StatorGeometry:
    return StatorGeometry.prototype()


@pytest.fixture(scope="module")
def proto_mesh(proto: StatorGeometry):
    return build_stator_mesh(proto, deformed=False)


def test_full_section_has_about_500_holes_and_epsilon_is_a_slot_hole() -> None:
    g = StatorGeometry.full_section()
    holes = g.slot_centres_m(reach_only=False)
    assert 480 <= len(holes) <= 520
    reach = g.slot_centres_m()
    assert np.all(reach[:, 1] >= -g.reach_length_m - 1e-9)
    # epsilon = (0, -1.000, -0.100) is the hole furthest from the origin within reach
    d = np.linalg.norm(reach[:, 1:] - np.asarray(EPSILON_M)[1:], axis=1)
    assert d.min() < 1e-12
    far = np.argmax(np.linalg.norm(reach[:, 1:], axis=1))
    assert np.allclose(reach[far, 1:], EPSILON_M[1:], atol=1e-12)


def test_mesh_is_watertight_with_the_volume_of_box_minus_holes(proto, proto_mesh) -> None:
    m = proto_mesh
    assert m.is_watertight and m.is_winding_consistent and m.is_volume
    n_holes = len(proto.slot_centres_m(reach_only=False))
    hole = math.pi * (proto.hole_diameter_m / 2) ** 2 * proto.depth_m  # polygon keeps the area
    box = proto.length_m * proto.height_m * proto.depth_m
    assert m.volume == pytest.approx(box - n_holes * hole, rel=1e-9)
    assert np.allclose(m.bounds, [[-proto.depth_m, -proto.length_m, -proto.height_m], [0, 0, 0]])


def test_triangle_count_stays_small() -> None:
    assert len(build_stator_mesh(StatorGeometry.full_section()).faces) < 200_000


def test_rays_pass_through_holes_and_hit_metal_elsewhere(proto, proto_mesh, rng) -> None:
    caster = MeshRayCaster(proto_mesh)
    y = rng.uniform(-proto.length_m + 0.01, -0.01, 4000)
    z = rng.uniform(-proto.height_m + 0.01, -0.01, 4000)
    origins = np.column_stack([np.full_like(y, 0.01), y, z])
    d = caster.first_hits(origins, np.tile([-1.0, 0.0, 0.0], (len(y), 1)))
    in_hole = proto.hole_near(y, z)
    # points within 0.05 mm of a hole rim may fall either side of the 12-gon
    j = np.rint((-y - proto.first_slot_offset_m) / proto.slot_pitch_m)
    k = np.rint((-z - proto.first_layer_depth_m) / proto.layer_pitch_m)
    rim = np.hypot(
        y + proto.first_slot_offset_m + j * proto.slot_pitch_m,
        z + proto.first_layer_depth_m + k * proto.layer_pitch_m,
    )
    clear = np.abs(rim - proto.hole_diameter_m / 2) > 0.0005
    assert in_hole.sum() > 200
    assert np.all(np.isinf(d[in_hole & clear]))
    assert np.allclose(d[~in_hole & clear], 0.01, atol=1e-12)


def test_bolt_bulge_is_applied_to_mesh_and_ground_truth(proto) -> None:
    m = build_stator_mesh(proto, deformed=True)
    assert m.is_watertight
    front = m.vertices[m.vertices[:, 0] > -1e-6]
    expect = proto.side_face_offset_m(front[:, 1], front[:, 2])
    assert np.allclose(front[:, 0], expect, atol=1e-15)
    assert 0.5 * proto.bolt_bulge_m < front[:, 0].max() <= proto.bolt_bulge_m
    truth = proto.slot_centres_m()
    assert np.allclose(truth[:, 0], proto.side_face_offset_m(truth[:, 1], truth[:, 2]))
    # largest at a bolt slot (slot 3), small far from all bolts
    y3 = proto.slot_y_m[2]
    assert proto.side_face_offset_m(y3, -0.0625) > 0.9 * proto.bolt_bulge_m
    assert proto.side_face_offset_m(-0.49, -0.0625) < 0.05 * proto.bolt_bulge_m


def test_bad_dimensions_name_the_field() -> None:
    with pytest.raises(ShapeError, match="hole_diameter_m"):
        StatorGeometry(hole_diameter_m=0.030)
    with pytest.raises(ShapeError, match=r"geometry\.depth_m"):
        StatorGeometry(depth_m=-1.0)
    with pytest.raises(ShapeError, match="hole_segments"):
        StatorGeometry(hole_segments=10)
    with pytest.raises(ShapeError, match="yoke"):
        StatorGeometry(height_m=0.1)


def test_flat_variant_without_holes_is_a_box() -> None:
    g = dataclasses.replace(StatorGeometry.prototype(), n_layers=0, bolt_bulge_m=0.0)
    m = build_stator_mesh(g)
    assert m.is_volume
    assert m.volume == pytest.approx(g.length_m * g.height_m * g.depth_m, rel=1e-12)
    assert len(g.slot_centres_m()) == 0


def test_builtins_registered() -> None:
    from planner.builtins import builtin_mesh

    m = builtin_mesh("builtin:stator_prototype")
    assert m.is_watertight and m.bounds[0, 1] == pytest.approx(-0.5)
