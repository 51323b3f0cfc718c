"""planner.faces.outline's union of a face's triangles: the coverage union where it is surely
the same geometry as ``union_all`` (every face of the stator), ``union_all`` where it is not."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from planner.faces.detection import find_planar_faces
from planner.faces.outline import FaceOutlines, _union
from planner.parts.stator import StatorGeometry
from planner.parts.stator_mesh import build_stator_mesh


@pytest.mark.slow  # 1,446 faces of 1 mm and more (about 1.5 s)
def test_every_face_of_the_stator_is_the_same_geometry_as_union_all() -> None:
    mesh = build_stator_mesh(StatorGeometry.prototype())
    faces = find_planar_faces(mesh, min_area_m2=np.pi * 0.001**2, footprint_radius_m=0.001)
    outlines = FaceOutlines(faces, 0.009)
    tri = np.asarray(mesh.triangles, dtype=np.float64)
    assert len(faces.faces) > 100
    for fid in range(len(faces.faces)):
        uv = tri[faces.face_id == fid] @ outlines.basis(fid)
        want = shapely.union_all(shapely.polygons(uv))
        assert shapely.normalize(_union(uv)) == shapely.normalize(want), fid


def test_overlapping_or_folded_triangles_take_union_all() -> None:
    square = np.array([[[0, 0], [1, 0], [1, 1]], [[0, 0], [1, 1], [0, 1]]], dtype=float)
    overlap = np.concatenate([square, square + 0.5])  # two squares overlapping by a quarter
    got = _union(overlap)
    assert got.is_valid and abs(got.area - 1.75) < 1e-12
    folded = np.concatenate([square, square[:1, ::-1]])  # one triangle turned over, on top
    got = _union(folded)
    assert got.is_valid and abs(got.area - 1.0) < 1e-12
    assert shapely.normalize(_union(square)) == shapely.normalize(shapely.box(0, 0, 1, 1))
