"""Constraint layouts: flattening, Jacobians against finite differences, the random layout
generator against its own geometry, and named errors."""

from __future__ import annotations

import numpy as np
import pytest

from calib.errors import DegenerateGeometryError, ShapeError
from calib.estimators.layout import (
    MIN_SCALE_M,
    axis_name,
    constraint_jacobian,
    constraint_set,
    cross_rows,
    point_motion_jacobian,
    random_face_layout,
    small_motion_matrix,
)
from calib.frames import invert_transform, small_motion, transform_points
from calib.probing import ProbePoint, SearchSpec


def test_edge_points_add_a_second_constraint_row() -> None:
    up = (0.0, 0.0, 1.0)
    pts = [
        ProbePoint("A", (0.0, -0.8, -0.08), (1.0, 0.0, 0.0)),
        ProbePoint(
            "F",
            (0.0, -0.25, 0.0),
            (1.0, 0.0, 0.0),
            SearchSpec("edge", edge_direction=up),
            edge_normal=up,
        ),
    ]
    cs = constraint_set(pts)
    assert cs.n_points == 2 and cs.n_constraints == 3
    assert cs.constraint_ids == ("A", "F", "F")
    np.testing.assert_array_equal(cs.normals, [[1, 0, 0], [1, 0, 0], [0, 0, 1]])
    np.testing.assert_array_equal(cs.nominal_m[2], pts[1].position_m)
    assert cs.scale_m == pytest.approx(0.5 * np.hypot(0.55, 0.08))  # RMS radius of 2 points
    assert constraint_set(cs) is cs
    single = constraint_set(pts[:1])
    assert single.scale_m == MIN_SCALE_M


def test_constraint_jacobian_matches_finite_differences(rng: np.random.Generator) -> None:
    faces = random_face_layout(rng, (3, 2, 2), n_edge_points=1)
    cs = constraint_set(faces.points)
    T = small_motion(rng.normal(size=6) * 0.3)
    q = transform_points(T, cs.positions_m + rng.normal(scale=0.01, size=cs.positions_m.shape))
    qm = q[cs.point_index]

    def residuals(delta: np.ndarray) -> np.ndarray:
        x = transform_points(invert_transform(T @ small_motion(delta)), qm)
        return np.einsum("ij,ij->i", cs.normals, x - cs.nominal_m)

    x0 = transform_points(invert_transform(T), qm)
    J = constraint_jacobian(cs.normals, x0)
    h = 1e-6
    numeric = np.stack(
        [(residuals(h * e) - residuals(-h * e)) / (2 * h) for e in np.eye(6)], axis=1
    )
    np.testing.assert_allclose(J, numeric, atol=1e-8)


def test_point_motion_jacobian_matches_small_motions(rng: np.random.Generator) -> None:
    p = rng.normal(size=(4, 3))
    delta = rng.normal(size=6) * 1e-7
    moved = transform_points(small_motion(delta), p) - p
    np.testing.assert_allclose(point_motion_jacobian(p) @ delta, moved, atol=1e-13)


@pytest.mark.parametrize("angle", [0.0, 1e-12, 1e-9, 1e-7, 1e-3, 0.5, 3.0])
def test_fast_small_motion_equals_frames_small_motion(
    rng: np.random.Generator, angle: float
) -> None:
    axis = rng.normal(size=3)
    delta = np.concatenate([rng.normal(size=3), angle * axis / np.linalg.norm(axis)])
    np.testing.assert_allclose(small_motion_matrix(delta), small_motion(delta), atol=1e-15)


def test_cross_rows_equals_numpy(rng: np.random.Generator) -> None:
    a, b = rng.normal(size=(7, 3)), rng.normal(size=(7, 3))
    np.testing.assert_allclose(cross_rows(a, b), np.cross(a, b), atol=1e-15)
    np.testing.assert_allclose(cross_rows(a[0], b), np.cross(a[0], b), atol=1e-15)


def test_random_layout_points_lie_on_their_faces(rng: np.random.Generator) -> None:
    faces = random_face_layout(rng, (4, 3, 2), n_edge_points=2)
    np.testing.assert_allclose(faces.normals @ faces.corner_m, faces.offsets_m, atol=1e-12)
    for p, f in zip(faces.points, faces.face_of):
        assert np.dot(faces.normals[f], p.position_m) == pytest.approx(faces.offsets_m[f])
        if p.edge_normal is not None:
            assert np.dot(faces.normals[1], p.position_m) == pytest.approx(faces.offsets_m[1])
            assert p.search.kind == "edge"
    assert len(faces.points) == 4 + 3 + 2 + 2


def test_axis_names() -> None:
    assert axis_name([0.0, 0.0, -2.0]) == "wobj z"
    assert axis_name([0.0, -0.8, 0.6]) == "wobj (0, 0.8, -0.6)"


def test_bad_layouts_raise_named_errors() -> None:
    a = ProbePoint("a", (0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    with pytest.raises(ShapeError, match="at least one"):
        constraint_set([])
    with pytest.raises(ShapeError, match="repeated: a"):
        constraint_set([a, a])
    b = ProbePoint("b", (0.0, 0.0, 5e-7), (0.0, 0.0, 1.0))
    with pytest.raises(DegenerateGeometryError, match="'a' and 'b' coincide"):
        constraint_set([a, b], "layout")
    with pytest.raises(ShapeError, match=r"layout\[0\] must be a ProbePoint"):
        constraint_set([{"id": "a"}], "layout")  # type: ignore[list-item]
