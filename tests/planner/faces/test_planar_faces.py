"""Planar faces of work-object meshes, and probe points and sensor footprints on them."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import shapely
import trimesh
from scipy.spatial.transform import Rotation

from calib.errors import ShapeError
from calib.probing import ProbePoint, SearchSpec
from planner.cell.scene.workobject import load_work_object
from planner.errors import MeshError
from planner.faces.checks import check_plan_faces, check_probe_faces
from planner.faces.detection import NoPlanarFaceError, find_planar_faces
from planner.parts.stator import StatorGeometry
from planner.parts.stator_mesh import build_stator_mesh

EXTENTS = (0.10, 0.20, 0.30)
X = np.array([1.0, 0.0, 0.0])


@pytest.fixture(scope="module")
def stator() -> trimesh.Trimesh:
    return build_stator_mesh(StatorGeometry.prototype())


def _grid_plane(noise_m: float, rng: np.random.Generator, size_m: float = 0.1) -> trimesh.Trimesh:
    """An open 0.1 m square of 2 mm triangles in z = 0 with Gaussian noise on z."""
    n = round(size_m / 0.002) + 1
    xy = np.stack(np.meshgrid(np.linspace(0, size_m, n), np.linspace(0, size_m, n)), -1)
    v = np.column_stack([xy.reshape(-1, 2), rng.normal(0.0, noise_m, n * n)])
    i = np.arange(n * n).reshape(n, n)
    a, b, c, d = i[:-1, :-1], i[:-1, 1:], i[1:, :-1], i[1:, 1:]
    f = np.vstack([np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)])
    return trimesh.Trimesh(v, f, process=False)


def test_box_has_six_faces_with_normals_and_areas() -> None:
    box = trimesh.creation.box(extents=EXTENTS)
    pf = find_planar_faces(box)
    assert len(pf.faces) == 6
    ex, ey, ez = EXTENTS
    want = {(1, 0, 0): ey * ez, (0, 1, 0): ex * ez, (0, 0, 1): ex * ey}
    for f in pf.faces:
        axis = tuple(round(abs(c)) for c in f.normal)
        assert f.area_m2 == pytest.approx(want[axis], rel=1e-12)
        assert f.rms_m < 1e-7  # round-off of the second moments
        k = int(np.argmax(np.abs(f.normal)))
        assert f.offset_m == pytest.approx(EXTENTS[k] / 2, abs=1e-12)  # outward normals
    assert (pf.face_id >= 0).all()
    centres = np.array([f.normal * f.offset_m for f in pf.faces])
    np.testing.assert_array_equal(pf.face_at(centres), np.arange(6))


def test_fitted_plane_of_a_rotated_box_is_exact(rng: np.random.Generator) -> None:
    R = Rotation.random(random_state=1).as_matrix()
    box = trimesh.creation.box(extents=EXTENTS)
    box.apply_transform(
        np.block([[R, rng.normal(size=(3, 1))], [np.zeros((1, 3)), np.ones((1, 1))]])
    )
    pf = find_planar_faces(box)
    got = np.sort(np.abs(pf.normals @ R), axis=0)  # each face normal is a rotated axis
    np.testing.assert_allclose(got[-2:], np.ones((2, 3)), atol=1e-9)


def test_detection_is_cached_by_mesh_content() -> None:
    box = trimesh.creation.box(extents=EXTENTS)
    assert find_planar_faces(box) is find_planar_faces(box.copy())
    assert find_planar_faces(box) is not find_planar_faces(box, flatness_tol_m=1e-5)


def test_detection_is_shared_by_callers_that_name_the_mesh_differently(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """check names the part, the landing risk does not: one detection serves both (the name
    is for messages only), each answer carrying its caller's name."""
    import planner.faces.detection as detection

    calls: list[str] = []
    real = detection._detect

    def counted(mesh: trimesh.Trimesh, name: str, **tols: float) -> object:
        calls.append(name)
        return real(mesh, name, **tols)

    monkeypatch.setattr(detection, "_detect", counted)
    box = trimesh.creation.box(extents=(0.31, 0.17, 0.09))  # a size no other test uses
    a = find_planar_faces(box, name="part A")
    b = find_planar_faces(box)
    assert calls == ["part A"]
    assert (a.name, b.name) == ("part A", "work object")
    assert np.array_equal(a.face_id, b.face_id) and len(a.faces) == 6


def test_sphere_has_no_planar_face_and_says_so() -> None:
    sphere = trimesh.creation.icosphere(subdivisions=4, radius=0.2)
    sphere.metadata["name"] = "ball"
    assert find_planar_faces(sphere).faces == ()
    with pytest.raises(NoPlanarFaceError, match=r"^ball: no planar face: "):
        check_probe_faces(sphere, [[0.2, 0, 0]], [X])


def test_noise_above_the_flatness_tolerance_is_not_a_plane(rng: np.random.Generator) -> None:
    assert len(find_planar_faces(_grid_plane(5e-6, rng)).faces) == 1
    assert find_planar_faces(_grid_plane(3e-4, rng)).faces == ()


def test_stator_side_face_and_a_footprint_over_a_slot_hole(stator: trimesh.Trimesh) -> None:
    pf = find_planar_faces(stator)
    side = [i for i, f in enumerate(pf.faces) if f.normal @ X > 0.999]
    assert len(side) == 1 and pf.faces[side[0]].area_m2 > 0.08
    g = StatorGeometry.prototype()
    slot_y = -g.first_slot_offset_m - 5 * g.slot_pitch_m
    z_layer = -g.first_layer_depth_m - g.layer_pitch_m
    pts = [
        [0.0, -0.1, -0.15],  # on the yoke: fine
        [0.0, slot_y + 0.007, z_layer],  # on metal, 2 mm from a slot hole's rim
        [0.0, -0.1, -0.15],
    ]
    tilted = Rotation.from_rotvec([0, 0, math.radians(10)]).apply(X)
    ok, hole, tilt = check_probe_faces(pf, pts, [X, X, tilted])
    assert ok.ok and ok.face_id == side[0] and ok.reason == ""
    assert not hole.ok and hole.face_id == side[0] and not hole.footprint_on_face
    assert hole.reason.startswith("footprint over a hole/edge")
    assert not tilt.ok and "10.0 deg from the face normal" in tilt.reason
    assert math.degrees(tilt.normal_angle_rad) == pytest.approx(10.0, abs=0.05)


def test_stator_edge_and_off_surface_points(stator: trimesh.Trimesh) -> None:
    g = StatorGeometry.prototype()
    hole = [0.0, -g.first_slot_offset_m, -g.first_layer_depth_m]  # centre of slot hole 1
    pts = [[0.0, -0.003, -0.1], [0.05, -0.1, -0.1], hole]
    corner, off, in_hole = check_probe_faces(stator, pts, [X, X, X])
    assert not corner.ok and corner.reason.startswith("footprint over a hole/edge")
    assert not in_hole.ok and in_hole.reason.startswith("footprint over a hole/edge: the point")
    assert not off.ok and off.reason.endswith("mm from the surface")
    assert off.distance_m == pytest.approx(0.05, abs=3e-4)  # the bolt bulge is under 0.3 mm


def test_edge_search_is_checked_where_it_starts(stator: trimesh.Trimesh) -> None:
    spec = SearchSpec("edge", start_offset_m=0.0925, edge_direction=(0.0, 0.0, 1.0))
    edge = ProbePoint("F", (0.0, -0.1, 0.0), (1.0, 0.0, 0.0), spec, (0.0, 0.0, 1.0))
    (check,) = check_plan_faces(stator, [edge])
    assert check.ok, check.reason
    short = SearchSpec("edge", start_offset_m=0.004, edge_direction=(0.0, 0.0, 1.0))
    bad = ProbePoint("F", (0.0, -0.1, 0.0), (1.0, 0.0, 0.0), short, (0.0, 0.0, 1.0))
    (check,) = check_plan_faces(stator, [bad])
    assert not check.ok and check.reason.startswith("at the edge search's start: footprint")


def test_plate_with_holes_in_mm_has_its_two_large_faces(reference_dir: Path) -> None:
    wo = load_work_object(reference_dir / "parts" / "plate_holes.STL", units="mm")
    pf = find_planar_faces(wo.mesh)
    # the 12.7 mm thick sides cannot hold the 18 mm sensor face
    assert len(pf.faces) == 2
    np.testing.assert_allclose(np.abs(pf.normals[:, 2]), [1.0, 1.0], atol=1e-9)
    assert pf.normals[0, 2] * pf.normals[1, 2] < 0
    plate = 8 * 12 * 0.0254**2
    for f in pf.faces:
        assert 0.8 * plate < f.area_m2 < plate


def test_noether_scan_has_no_planar_face(reference_dir: Path) -> None:
    wo = load_work_object(reference_dir / "parts" / "noether_raw_mesh.ply", units="m")
    pf = find_planar_faces(wo.mesh, name=wo.name)
    assert pf.faces == () and pf.largest_region is not None
    with pytest.raises(MeshError, match=r"noether_raw_mesh: no planar face: largest flat region"):
        check_probe_faces(pf, wo.mesh.vertices[:1], wo.mesh.vertex_normals[:1])


def test_bad_input_is_named() -> None:
    box = trimesh.creation.box(extents=EXTENTS)
    with pytest.raises(ShapeError, match="points"):
        check_probe_faces(box, [[0.0, 0.0]], [X])
    with pytest.raises(ShapeError, match="normals"):
        check_probe_faces(box, [[0.05, 0, 0]], [X, X])
    with pytest.raises(MeshError, match="flatness_tol_m"):
        find_planar_faces(box, flatness_tol_m=-1.0)


@pytest.mark.parametrize(
    ("extents", "why"),
    [
        ((0.012, 0.012, 0.012), "144.0 mm^2 (2 triangles), RMS 0.000 mm, too small"),
        ((0.030, 0.014, 0.014), "no spot of it holds the sensor face"),  # 420 mm^2, 14 mm wide
    ],
)
def test_small_or_narrow_faces_cannot_hold_the_sensor(extents: tuple[float, ...], why: str) -> None:
    pf = find_planar_faces(trimesh.creation.box(extents=extents), name="block")
    assert pf.faces == ()
    with pytest.raises(NoPlanarFaceError, match=r"^block: no planar face: largest flat") as err:
        pf.require_any()
    assert why in str(err.value)


def test_a_flat_face_too_small_for_the_sensor_says_so() -> None:
    """Item 4: a 10 x 10 mm flat top was reported as "curved, noisy or too small"."""
    base = trimesh.creation.box([0.2, 0.2, 0.05])
    boss = trimesh.creation.box([0.01, 0.01, 0.01])
    boss.apply_translation([0.0, 0.0, 0.03])
    mesh = trimesh.util.concatenate([base, boss])
    (on_boss, on_base) = check_probe_faces(
        mesh, [[0.0, 0.0, 0.035], [0.06, 0.06, 0.025]], [[0, 0, 1.0], [0, 0, 1.0]]
    )
    assert on_base.ok
    assert on_boss.reason == (
        "on a flat face of 100.0 mm^2, too small for the 18 mm sensor (its face covers 254 mm^2)"
    )


@pytest.mark.parametrize(
    ("width_m", "room_to_spare"),
    [(0.020, True), (0.0182, False)],  # the 18 mm sensor: 18.36 mm with room, 18 mm at all
)
def test_a_strip_meshed_as_two_long_triangles_holds_the_sensor_on_its_centre_line(
    width_m: float, room_to_spare: bool
) -> None:
    """No triangle centroid of a 200 mm strip meshed as two triangles lies on its centre line:
    a 20 mm strip is found by a spot with room to spare, an 18.2 mm one only by the centre of
    its largest inscribed circle (the cheap spot has no room there)."""
    from planner.faces.footprint import DEFAULT_FOOTPRINT_RADIUS_M as r
    from planner.faces.footprint import _roomiest_spot, _spot_with_room

    strip = trimesh.creation.box(extents=(0.2, width_m, 0.010))
    pf = find_planar_faces(strip, name="strip")
    normals = sorted(tuple(np.round(f.normal, 6) + 0.0) for f in pf.faces)
    assert normals == [(0.0, 0.0, -1.0), (0.0, 0.0, 1.0)]
    outline = shapely.box(-0.1, -width_m / 2, 0.1, width_m / 2)
    assert (_spot_with_room(outline, r) is not None) == room_to_spare
    centre = _roomiest_spot(outline, r)
    assert centre is not None and abs(centre[1]) < 0.02 * r
