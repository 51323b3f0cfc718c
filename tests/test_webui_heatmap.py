"""The heat map's colours (issue 14, item 6): coloured by what fails, spread smoothly over a
refined surface."""

from __future__ import annotations

import numpy as np
import trimesh

from webui.heatmap import CATEGORY_RGB, category_of, refined, smooth_vertex_colours
from webui.testing import box_mesh


def test_each_failure_has_its_colour() -> None:
    assert category_of("feasible", "", True) == "feasible"
    assert category_of("marginal", "joint 2 near its limit", True) == "marginal"
    assert category_of("feasible", "", False) == "footprint"
    assert category_of("infeasible", "out of reach (2.87 m from the shoulder)", True) == "reach"
    assert category_of("infeasible", "joint 5 at limit (joint_5)", True) == "joint limit"
    assert category_of("infeasible", "singular wrist", True) == "joint limit"
    assert category_of("infeasible", "link_4 hits table (clearance -3.0 mm)", True) == "collision"
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
