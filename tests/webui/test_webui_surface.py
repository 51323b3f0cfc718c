"""Click-to-place geometry: rays on the work-object mesh, projection of drags."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from calib.frames import make_transform, matrix_from_rotvec
from webui.surface import SurfacePicker


@pytest.fixture
def box() -> trimesh.Trimesh:
    # 0.4 x 0.2 x 0.1 m box with its top face at z = 0 (like the stator's top side)
    m = trimesh.creation.box(extents=(0.4, 0.2, 0.1))
    m.apply_translation((0.0, 0.0, -0.05))
    return m


def test_ray_hits_top_face_with_its_normal(box: trimesh.Trimesh) -> None:
    T_world_wobj = make_transform(matrix_from_rotvec([0, 0, np.pi / 2]), [1.0, 0.5, 0.3])
    picker = SurfacePicker(box, T_world_wobj)
    target_wobj = np.array([0.1, -0.05, 0.0])
    target_world = T_world_wobj[:3, :3] @ target_wobj + T_world_wobj[:3, 3]
    origin = target_world + np.array([0.2, 0.1, 1.0])
    hit = picker.pick(origin, target_world - origin)
    assert hit is not None
    np.testing.assert_allclose(hit.position_wobj, target_wobj, atol=1e-9)
    np.testing.assert_allclose(hit.normal_wobj, [0, 0, 1], atol=1e-12)
    assert hit.distance_m == pytest.approx(np.linalg.norm(target_world - origin))


def test_ray_miss_returns_none(box: trimesh.Trimesh) -> None:
    picker = SurfacePicker(box, np.eye(4))
    assert picker.pick([5, 5, 5], [0, 0, 1]) is None


def test_side_face_normal(box: trimesh.Trimesh) -> None:
    picker = SurfacePicker(box, np.eye(4))
    hit = picker.pick([1.0, 0.01, -0.03], [-1, 0, 0])
    assert hit is not None
    np.testing.assert_allclose(hit.position_wobj, [0.2, 0.01, -0.03], atol=1e-9)
    np.testing.assert_allclose(hit.normal_wobj, [1, 0, 0], atol=1e-12)


def test_projection_lands_on_surface(box: trimesh.Trimesh) -> None:
    picker = SurfacePicker(box, make_transform(p=[0, 0, 1.0]))
    hit = picker.project_world([0.05, 0.02, 1.03])  # 3 cm above the top face
    np.testing.assert_allclose(hit.position_wobj, [0.05, 0.02, 0.0], atol=1e-9)
    np.testing.assert_allclose(hit.normal_wobj, [0, 0, 1], atol=1e-12)
    assert hit.distance_m == pytest.approx(0.03)


def test_zero_direction_is_a_clear_error(box: trimesh.Trimesh) -> None:
    picker = SurfacePicker(box, np.eye(4))
    with pytest.raises(ValueError, match="ray_direction"):
        picker.pick([0, 0, 1], [0, 0, 0])


def test_marker_on_ray_takes_the_nearest_visible_marker() -> None:
    from webui.surface import marker_on_ray

    centres = [[0.0, 0.0, 1.0], [0.0, 0.0, 2.0], [0.05, 0.0, 0.5]]
    down = [0.0, 0.0, -1.0]
    assert marker_on_ray(centres, [0, 0, 5.0], down, 0.01) == 1, "nearest the camera first"
    assert marker_on_ray(centres, [0.005, 0, 5.0], down, 0.01) == 1
    assert marker_on_ray(centres, [0.02, 0, 5.0], down, 0.01) is None, "passes beside them"
    # the surface hit at z = 2.5 hides markers behind it (z < 2.5 - 1.25 r)
    assert marker_on_ray(centres, [0, 0, 5.0], down, 0.01, hit_world=[0, 0, 2.5]) is None
    assert marker_on_ray(centres, [0, 0, 0.0], [0, 0, 1.0], 0.01) == 0, "looking up: z = 1 first"
