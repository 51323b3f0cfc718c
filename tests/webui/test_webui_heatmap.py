"""The heat map's colours (issue 14, item 6): coloured by what fails, spread over a refined
surface; issue 22, item 7: one colour per face, never blended across a face."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from planner.reasons import Reason
from webui.heatmap import (
    CATEGORY_RGB,
    category_of,
    face_colours,
    refined,
    smooth_vertex_colours,
)
from webui.testing import box_mesh


def test_each_failure_has_its_colour() -> None:
    """By the kind of the sample's reason (issue 23, item 3), whatever its words."""
    assert category_of("feasible", None, True) == "feasible"
    near = Reason("joint_limit", "joint 2 near its limit")
    assert category_of("marginal", near, True) == "marginal"
    assert category_of("feasible", None, False) == "footprint"
    far = Reason("reach", "out of reach (2.87 m from the shoulder)")
    assert category_of("infeasible", far, True) == "reach"
    close = Reason("reach", "too close (wrist centre 0.10 m from the shoulder, min 0.20 m)")
    assert category_of("infeasible", close, True) == "reach"
    limit = Reason("joint_limit", "joint 5 at limit (joint_5)")
    assert category_of("infeasible", limit, True) == "joint limit"
    assert category_of("infeasible", Reason("singularity", "singular wrist"), True) == "joint limit"
    hit = Reason("collision", "link_4 hits table (clearance -3.0 mm)", ("link_4", "table"))
    assert category_of("infeasible", hit, True) == "collision"
    every = Reason("collision", "every checked pose hits an obstacle or is too near one")
    assert category_of("infeasible", every, False) == "collision", "what fails, not the face"
    assert len(set(CATEGORY_RGB.values())) == len(CATEGORY_RGB), "one colour per meaning"


def test_refined_surface_is_fine_and_keeps_the_shape() -> None:
    box = box_mesh()
    fine = refined(box)
    assert len(fine.faces) > 100 * len(box.faces)
    np.testing.assert_allclose(fine.bounds, box.bounds, atol=1e-12)
    assert abs(fine.area - box.area) < 1e-9
    edges = np.linalg.norm(np.diff(fine.vertices[fine.edges], axis=1)[:, 0], axis=1)
    assert edges.max() <= 0.02 * max(box.extents) + 1e-12


def test_colours_are_voted_never_mixed_and_match_the_samples_near_them() -> None:
    plane = trimesh.creation.box(extents=(1.0, 1.0, 0.01))
    fine = refined(plane)
    pts = np.array([[-0.4, 0.0, 0.005], [0.4, 0.0, 0.005]])
    nrm = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    rgb = np.array([[255, 0, 0], [0, 0, 255]], dtype=np.uint8)
    col = smooth_vertex_colours(fine, pts, nrm, rgb)
    top = np.where(fine.vertices[:, 2] > 0.004)[0]
    v = fine.vertices[top]
    near_red = top[np.argmin(np.linalg.norm(v - pts[0], axis=1))]
    near_blue = top[np.argmin(np.linalg.norm(v - pts[1], axis=1))]
    assert tuple(col[near_red]) == (255, 0, 0) and tuple(col[near_blue]) == (0, 0, 255)
    assert {tuple(c) for c in col[top]} == {(255, 0, 0), (0, 0, 255)}, "no mixed colours"
    left = fine.vertices[top][:, 0] < -0.01
    right = fine.vertices[top][:, 0] > 0.01
    assert np.all(col[top][left, 0] == 255) and np.all(col[top][right, 2] == 255)


@pytest.mark.slow
def test_each_face_has_one_colour_so_the_renderer_blends_nothing() -> None:
    """Vertex colours are interpolated across a face: a face whose corners voted apart drew a
    stripe of a colour that means nothing (seen between "reach" and "footprint")."""
    plane = trimesh.creation.box(extents=(1.0, 1.0, 0.01))
    fine = refined(plane)
    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(-0.5, 0.5, (40, 2)), np.full(40, 0.005)])
    nrm = np.tile([0.0, 0.0, 1.0], (40, 1))
    palette = np.array(list(CATEGORY_RGB.values()), dtype=np.uint8)
    rgb = palette[rng.integers(0, len(palette), 40)]
    col = smooth_vertex_colours(fine, pts, nrm, rgb)
    corners = col[fine.faces]  # (F, 3 corners, 3)
    assert np.all(corners == corners[:, :1, :]), "a face with two colours would be blended"
    assert {tuple(c) for c in col} <= {tuple(c) for c in palette}
    per_face = face_colours(fine, pts, nrm, rgb)
    np.testing.assert_array_equal(corners[:, 0, :], per_face)
    top = fine.face_normals[:, 2] > 0.9
    assert len({tuple(c) for c in per_face[top]}) > 3, "the borders follow the samples"
