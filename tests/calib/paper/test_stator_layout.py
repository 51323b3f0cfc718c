"""Validation of the nominal A-H layout against what the paper's equations assume."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from calib.errors import DegenerateGeometryError, ShapeError
from calib.paper.stator_layout import (
    STATOR_POINT_IDS,
    check_stator_points,
    example_stator_points,
    relabel_point,
)
from calib.probing import ProbePoint, SearchSpec


def _with(point_id: str, **changes) -> dict[str, ProbePoint]:
    pts = example_stator_points()
    pts[point_id] = replace(pts[point_id], **changes)
    return pts


def test_example_layout_is_valid_and_follows_fig_8a() -> None:
    layout = check_stator_points(example_stator_points())
    assert tuple(layout.points) == STATOR_POINT_IDS
    assert layout.face_coords_wobj == (0.0, 0.0, 0.0)
    p = {k: np.asarray(v.position_m) for k, v in layout.points.items()}
    assert p["A"][1] < p["B"][1] and p["E"][2] < p["D"][2] < p["F"][2] == 0.0
    assert p["H"][1] < p["F"][1] and p["F"][1] == p["D"][1] == p["E"][1]
    # F starts at E's height, H at G's: the plan's reading of "from point E" / "from G"
    for edge, start in (("F", "E"), ("H", "G")):
        pt = layout.points[edge]
        start_z = pt.position_m[2] - pt.search.start_offset_m
        assert start_z == pytest.approx(p[start][2])
    assert check_stator_points(layout) is layout  # validated once, reused


def test_faces_off_the_origin_give_face_coordinates() -> None:
    off = np.array([-0.01, 0.02, -0.03])
    pts = [
        replace(p, position_m=tuple(np.asarray(p.position_m) + off))
        for p in example_stator_points().values()
    ]
    layout = check_stator_points(pts)  # a sequence of points is keyed by their ids
    np.testing.assert_allclose(layout.face_coords_wobj, off)


def test_points_are_relabelled_with_their_role() -> None:
    pts = {k: relabel_point(p, f"plan_{k}") for k, p in example_stator_points().items()}
    pts["X"] = pts["A"]  # extra points are ignored
    layout = check_stator_points(pts)
    assert [p.id for p in layout.points.values()] == list(STATOR_POINT_IDS)
    a = layout.points["A"]
    assert relabel_point(a, "A") is a


@pytest.mark.parametrize(
    ("points", "error", "match"),
    [
        ({k: v for k, v in example_stator_points().items() if k != "H"}, ShapeError, "missing H"),
        (_with("C", normal=(1.0, 0.0, 0.0)), DegenerateGeometryError, "point C must have normal"),
        (_with("A", normal=(0.0, 1.0, 0.0)), DegenerateGeometryError, "point A must have normal"),
        (_with("E", position_m=(0.0, -0.1, -0.01)), DegenerateGeometryError, "E lies below D"),
        (_with("D", position_m=(0.0, -0.1, 0.01)), DegenerateGeometryError, "D lies below"),
        (_with("B", position_m=(0.0, -0.95, -0.25)), DegenerateGeometryError, "smaller y than B"),
        (_with("A", position_m=(0.0, -0.9, -0.20)), DegenerateGeometryError, "A and B share z"),
        (_with("G", position_m=(-0.01, -0.5, -0.1)), DegenerateGeometryError, "share x"),
        (_with("H", position_m=(0.0, -0.5, -0.01)), DegenerateGeometryError, "F and H share z"),
        (_with("F", search=SearchSpec()), ShapeError, "F must be an edge search"),
        (
            _with("D", search=SearchSpec("edge", 0.05, 0.05, (0.0, 0.0, 1.0))),
            ShapeError,
            "D must be an approach search",
        ),
        (
            _with("H", search=SearchSpec("edge", 0.05, 0.05, (0.0, 1.0, 0.0))),
            DegenerateGeometryError,
            "H must search up the side face",
        ),
    ],
)
def test_bad_layouts_raise(points, error, match) -> None:
    with pytest.raises(error, match=match):
        check_stator_points(points)


def test_a_normal_clicked_on_a_triangle_is_accepted() -> None:
    """Item 3: `validate` refused B clicked in the UI on the right face (normal off by 3e-6)."""
    pts = _with("B", normal=(0.9999999999956295, -2.6e-06, -1.4e-06))
    check_stator_points(pts)
    tilted = (float(np.cos(0.01)), float(np.sin(0.01)), 0.0)  # 0.57 deg
    with pytest.raises(
        DegenerateGeometryError, match=r"point B must have normal .* 0\.573 deg off"
    ):
        check_stator_points(_with("B", normal=tilted))


def test_side_face_points_share_x_within_the_face_tolerance() -> None:
    a = example_stator_points()["A"].position_m
    layout = check_stator_points(_with("A", position_m=(a[0] + 4e-4, a[1], a[2])))
    assert layout.face_coords_wobj[0] == pytest.approx(4e-4 / 7)  # the mean of A, B, D-H
    with pytest.raises(DegenerateGeometryError, match=r"share x within 0\.5 mm .* 0\.600 mm"):
        check_stator_points(_with("A", position_m=(a[0] + 6e-4, a[1], a[2])))
