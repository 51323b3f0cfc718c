"""Tests of planner.cell.broad.distance_field: lower bounds against exact distances, the bucket
grid, and the disk cache (reused when valid, rebuilt when missing, corrupt or foreign)."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pytest
import trimesh

from planner.cell.broad import distance_field as df
from planner.cell.disk_cache import cache_path


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("WOBJCAL_CACHE_DIR", str(tmp_path))
    return tmp_path


def meshes() -> list[trimesh.Trimesh]:
    """A subdivided box, a sphere and an open plate (a shell: Bullet's view of any mesh)."""
    plate = trimesh.creation.box([0.4, 0.3, 0.01]).subdivide_to_size(0.05)
    plate.update_faces(plate.face_normals[:, 2] > 0.5)  # only the top: an open mesh
    plate.remove_unreferenced_vertices()
    return [
        trimesh.creation.box([0.5, 0.3, 0.2]).subdivide_to_size(0.04),
        trimesh.creation.icosphere(subdivisions=3, radius=0.15),
        plate,
    ]


@pytest.mark.parametrize("k", range(3))
def test_lower_bounds_never_exceed_the_distance(k: int, rng) -> None:
    mesh = meshes()[k]
    field = df.build_field(mesh)
    lo, hi = mesh.bounds
    pts = rng.uniform(lo - 0.3, hi + 0.3, size=(3000, 3))
    near = mesh.sample(2000, seed=1) + rng.normal(scale=0.01, size=(2000, 3))
    pts = np.concatenate([pts, near])
    _, exact, _ = trimesh.proximity.closest_point(mesh, pts)
    lb = field.lower_bound(pts)
    assert np.all(lb <= exact + 1e-7)  # float32 nodes are rounded down
    # tight where every corner of the point's cell holds an exact distance (the band): off by
    # the interpolation's error bound h * sqrt(3) / 2 at most; elsewhere within a few cells
    h = field.spacing
    band = exact < df.BAND_CELLS * h - h * np.sqrt(3)
    assert band.sum() > 100
    assert np.all(exact[band] - lb[band] <= h * np.sqrt(3) / 2 + 1e-6)
    g = (pts - field.origin) / h
    in_grid = np.all((g >= 0) & (g < np.array(field.values.shape) - 1), axis=1)
    within = in_grid & (exact < df.CAP_M - 4 * h)  # outside the grid: the mesh's box bounds
    slack = np.ptp(mesh.triangles, axis=1).max()  # a triangle's box marks cells it misses
    assert np.all(exact[within] - lb[within] <= 4 * h + slack)
    assert field.values.dtype == np.float32 and field.values.size <= df.MAX_NODES


def test_buckets_list_every_triangle_in_every_cell_its_box_touches() -> None:
    mesh = meshes()[1]
    f = df.build_field(mesh)
    tri = mesh.triangles
    for t in range(0, len(tri), 37):
        c_lo = np.floor((tri[t].min(axis=0) - f.bucket_origin) / f.bucket_size).astype(int)
        c_hi = np.floor((tri[t].max(axis=0) - f.bucket_origin) / f.bucket_size).astype(int)
        c_lo, c_hi = np.clip(c_lo, 0, f.bucket_n - 1), np.clip(c_hi, 0, f.bucket_n - 1)
        for i in range(c_lo[0], c_hi[0] + 1):
            for j in range(c_lo[1], c_hi[1] + 1):
                for kk in range(c_lo[2], c_hi[2] + 1):
                    cell = (i * f.bucket_n[1] + j) * f.bucket_n[2] + kk
                    listed = f.bucket_tris[f.bucket_start[cell] : f.bucket_start[cell + 1]]
                    assert t in listed


def test_the_cache_is_reused_and_rebuilt_when_unusable(cache: Path, caplog) -> None:
    mesh = meshes()[0]
    first = df.distance_field(mesh)
    path = cache_path(df.CACHE_KIND, first.key)
    assert path.is_file() and first.build_s > 0
    again = df.distance_field(mesh)
    assert again.build_s == 0.0  # from the disk
    np.testing.assert_array_equal(again.values, first.values)
    np.testing.assert_array_equal(again.bucket_tris, first.bucket_tris)
    # a truncated file (a crash mid-write elsewhere, a full disk): rebuilt, no exception
    path.write_bytes(path.read_bytes()[:1000])
    with caplog.at_level(logging.WARNING):
        rebuilt = df.distance_field(mesh)
    assert rebuilt.build_s > 0 and "unreadable cache" in caplog.text
    np.testing.assert_array_equal(rebuilt.values, first.values)
    # a valid file of another mesh under this key: its stored key differs, so it is not used
    other = df.distance_field(meshes()[1])
    cache_path(df.CACHE_KIND, other.key).replace(path)
    caplog.clear()
    with caplog.at_level(logging.WARNING):
        again = df.distance_field(mesh)
    assert again.build_s > 0 and "another key" in caplog.text
    np.testing.assert_array_equal(again.values, first.values)


def test_the_key_follows_the_geometry() -> None:
    a, b = meshes()[0], meshes()[0]
    assert df.mesh_key(a) == df.mesh_key(b)
    b.vertices[0, 0] += 1e-9
    assert df.mesh_key(a) != df.mesh_key(b)


def test_an_unwritable_cache_costs_time_not_answers(tmp_path: Path, monkeypatch, caplog) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    monkeypatch.setenv("WOBJCAL_CACHE_DIR", str(blocker))
    with caplog.at_level(logging.WARNING):
        field = df.distance_field(meshes()[1])
    assert field.build_s > 0 and "cannot write cache" in caplog.text
