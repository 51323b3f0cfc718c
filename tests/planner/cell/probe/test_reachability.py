"""Tests of planner.cell.probe.reachability: area-weighted surface samples and per-sample
feasibility."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from calib.errors import ShapeError
from calib.frames import make_transform
from planner.cell.cell import Cell
from planner.cell.probe.reachability import FEASIBLE, INFEASIBLE, sample_surface


def test_samples_lie_on_the_surface_with_face_normals(rng) -> None:
    mesh = trimesh.creation.icosphere(subdivisions=2, radius=0.3)
    pts, nrm, face = sample_surface(mesh, 500, rng)
    _, dist, _ = trimesh.proximity.closest_point(mesh, pts)
    assert dist.max() < 1e-9
    np.testing.assert_allclose(np.linalg.norm(nrm, axis=1), 1.0, atol=1e-12)
    np.testing.assert_array_equal(nrm, mesh.face_normals[face])
    # outward: on a sphere about the origin, the normal and the position agree in direction
    assert np.all(np.einsum("ij,ij->i", nrm, pts) > 0)


def test_samples_are_area_weighted(rng) -> None:
    plate = trimesh.creation.box([1.0, 1.0, 0.01])  # top + bottom: 2 m^2, sides: 0.04 m^2
    n = 4000
    _, nrm, _ = sample_surface(plate, n, rng)
    share = float(np.mean(np.abs(nrm[:, 2]) > 0.99))
    p = 2.0 / 2.04
    assert abs(share - p) < 4 * np.sqrt(p * (1 - p) / n)


def test_same_seed_same_samples() -> None:
    mesh = trimesh.creation.box([0.2, 0.3, 0.4])
    a = sample_surface(mesh, 50, np.random.default_rng(7))
    b = sample_surface(mesh, 50, np.random.default_rng(7))
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)


@pytest.mark.slow
def test_map_of_a_box_agrees_with_probe_checks(rng) -> None:
    with Cell(use_acl_cache=False) as cell:
        with pytest.raises(ShapeError, match="work object"):
            cell.reachability_map(10, rng)
        cell.set_work_object(trimesh.creation.box([0.4] * 3), "m", make_transform(p=[1.4, 0, 0.4]))
        rmap = cell.reachability_map(60, rng)
        again = cell.check_probes(rmap.points_wobj, rmap.normals_wobj)
        with pytest.raises(ShapeError, match="n_samples"):
            cell.reachability_map(0, rng)
    assert rmap.points_wobj.shape == (60, 3) and rmap.status.shape == (60,)
    codes = {"infeasible": 0, "marginal": 1, "feasible": 2}
    np.testing.assert_array_equal(rmap.status, [codes[r.status] for r in again])
    assert rmap.reasons == tuple(r.reason for r in again)
    top = rmap.normals_wobj[:, 2] > 0.99
    bottom = rmap.normals_wobj[:, 2] < -0.99
    assert top.any() and bottom.any()
    assert np.all(rmap.status[top] == FEASIBLE)  # the top face is in easy reach
    # probing the bottom face from below needs joint 3 past its limit
    assert np.all(rmap.status[bottom] == INFEASIBLE)
    assert 0.0 < rmap.fraction_feasible < 1.0
    assert np.all(np.isfinite(rmap.clearance_m[rmap.feasible]))
