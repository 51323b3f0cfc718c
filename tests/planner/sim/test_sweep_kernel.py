"""The compiled sweep of the touch probe's ball (:mod:`planner.sim.sweep_kernel`, through
:func:`planner.sim.touch.sweep_contact`) against the same formulas written with numpy (what it
replaced): random balls swept at random meshes and at a box's faces, edges and corners."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from numpy.typing import NDArray

from planner.sim.raycast import MeshRayCaster
from planner.sim.touch import sweep_contact

FloatArray = NDArray[np.float64]


def _numpy_sweep(
    caster: MeshRayCaster,
    centre0: FloatArray,
    a: FloatArray,
    r: float,
    triangles: NDArray[np.int64],
) -> tuple[float, FloatArray, int]:
    """The sweep as written with numpy before it was compiled (the reference)."""
    tri = np.asarray(triangles, dtype=np.int64)
    n = caster.triangle_normal(tri)  # (K, 3)
    v = caster.triangle_vertices(tri)  # (K, 3, 3)
    cos = n @ a
    with np.errstate(divide="ignore", invalid="ignore"):
        t_face = (n @ centre0 - caster.triangle_offset(tri) - r) / -cos
    facing = cos < -1e-12
    t_face = np.where(facing, t_face, np.inf)
    q = centre0 + np.where(facing, t_face, 0.0)[:, None] * a - r * n  # no inf * 0
    edges = v[:, [1, 2, 0]] - v  # (K, 3, 3): v1 - v0, v2 - v1, v0 - v2
    inside = facing & np.all(
        np.einsum("kij,kj->ki", np.cross(edges, q[:, None, :] - v), n) >= -1e-12, axis=1
    )
    t_face = np.where(inside, t_face, np.inf)
    # edges: the distance from the moving centre to each edge's line reaches r
    length = np.linalg.norm(edges, axis=2)
    e = edges / length[..., None]
    u = centre0 - v  # (K, 3, 3)
    u_perp = u - np.sum(u * e, axis=2, keepdims=True) * e
    a_perp = a - (e @ a)[..., None] * e
    t_edge = _first_roots(
        np.sum(a_perp * a_perp, axis=2),
        np.sum(u_perp * a_perp, axis=2),
        np.sum(u_perp * u_perp, axis=2) - r * r,
    )
    finite = np.isfinite(t_edge)
    s = np.sum((centre0 + np.where(finite, t_edge, 0.0)[..., None] * a - v) * e, axis=2)
    t_edge = np.where(finite & (s >= 0.0) & (s <= length), t_edge, np.inf)
    # corners: the distance from the moving centre to each corner reaches r
    t_corner = _first_roots(np.ones(u.shape[:2]), u @ a, np.sum(u * u, axis=2) - r * r)
    best = [float(np.min(t_face)), float(np.min(t_edge)), float(np.min(t_corner))]
    kind = int(np.argmin(best))
    travel = best[kind]
    if not np.isfinite(travel):
        return math.inf, -a, -1
    centre = centre0 + travel * a
    if kind == 0:
        k = int(np.argmin(t_face))
        return travel, n[k].copy(), int(tri[k])
    if kind == 1:
        ke, ie = (int(x) for x in np.unravel_index(int(np.argmin(t_edge)), t_edge.shape))
        foot = v[ke, ie] + s[ke, ie] * e[ke, ie]
        return travel, (centre - foot) / r, -1
    kc, ic = (int(x) for x in np.unravel_index(int(np.argmin(t_corner)), t_corner.shape))
    return travel, (centre - v[kc, ic]) / r, -1


def _first_roots(A: FloatArray, half_b: FloatArray, c: FloatArray) -> FloatArray:
    """Smaller roots of ``A t^2 + 2 half_b t + c = 0`` (``inf`` where none or ``A`` is 0)."""
    disc = half_b * half_b - A * c
    ok = (A > 1e-18) & (disc >= 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        root = (-half_b - np.sqrt(np.where(ok, disc, 0.0))) / np.where(ok, A, 1.0)
    return np.where(ok, root, np.inf)


def _assert_same(caster: MeshRayCaster, centre0: FloatArray, a: FloatArray, r: float) -> str:
    tri = np.arange(len(caster.triangle_arrays()[0]), dtype=np.int64)
    want = _numpy_sweep(caster, centre0, a, r, tri)
    got = sweep_contact(caster, centre0, a, r, tri)
    assert got[2] == want[2]
    if not math.isfinite(want[0]):
        assert not math.isfinite(got[0])
        return "none"
    assert got[0] == pytest.approx(want[0], rel=0, abs=1e-13)
    np.testing.assert_allclose(got[1], want[1], rtol=0, atol=1e-11)
    return "face" if want[2] >= 0 else "edge or corner"


@pytest.mark.parametrize("seed", range(6))
def test_random_balls_at_a_random_mesh_meet_it_where_numpy_says(seed: int) -> None:
    rng = np.random.default_rng(seed)
    mesh = trimesh.creation.icosphere(subdivisions=1, radius=0.05)
    mesh.vertices += rng.normal(0, 0.01, mesh.vertices.shape)  # faces, edges, corners all met
    caster = MeshRayCaster(mesh)
    seen = set()
    for _ in range(60):
        a = rng.normal(size=3)
        a /= np.linalg.norm(a)
        centre0 = -0.15 * a + rng.normal(0, 0.03, 3)
        seen.add(_assert_same(caster, centre0, a, float(rng.uniform(0.001, 0.02))))
    assert {"face", "edge or corner"} <= seen


def test_a_ball_at_a_box_meets_its_face_edge_and_corner_where_numpy_says() -> None:
    box = trimesh.creation.box(extents=(0.4, 0.4, 0.1))
    caster = MeshRayCaster(box)
    down = np.array([0.0, 0.0, -1.0])
    r = 0.003
    kinds = [
        _assert_same(caster, np.array([0.05, 0.02, 0.1]), down, r),  # the top face
        _assert_same(caster, np.array([0.2 + 0.001, 0.0, 0.1]), down, r),  # its edge
        _assert_same(caster, np.array([0.2 + 0.001, 0.2 + 0.001, 0.1]), down, r),  # a corner
        _assert_same(caster, np.array([0.3, 0.0, 0.1]), down, r),  # past the box: nothing
    ]
    assert kinds == ["face", "edge or corner", "edge or corner", "none"]


def test_a_degenerate_triangle_is_met_at_its_corners_and_breaks_nothing() -> None:
    """A triangle with two coinciding corners (real meshes have them) has no edge there; the
    ball meets the box where it would without it, and the sliver's corner where it lies."""
    box = trimesh.creation.box(extents=(0.4, 0.4, 0.1))
    sliver = np.array([[0.0, 0.0, 0.06], [0.0, 0.0, 0.06], [0.0, 0.01, 0.06]])  # above it
    vertices = np.vstack([box.vertices, sliver])
    faces = np.vstack([box.faces, len(box.vertices) + np.arange(3)[None]])
    caster = MeshRayCaster(trimesh.Trimesh(vertices, faces, process=False))
    tri = np.arange(len(faces), dtype=np.int64)
    down = np.array([0.0, 0.0, -1.0])
    travel, normal, k = sweep_contact(caster, np.array([0.1, 0.1, 0.1]), down, 0.003, tri)
    assert travel == pytest.approx(0.047, abs=1e-12) and 0 <= k < len(box.faces)
    travel, normal, k = sweep_contact(caster, np.array([-0.002, -0.001, 0.1]), down, 0.003, tri)
    assert k == -1 and np.isfinite(normal).all()  # the sliver's corner, above the top face
    assert travel == pytest.approx(0.04 - np.sqrt(0.003**2 - 0.002**2 - 0.001**2), abs=1e-12)


def test_the_preloaded_kernel_is_the_one_a_sweep_runs() -> None:
    """A fork server's :func:`load_kernel` compiles (or loads) the version of the kernel for the
    argument types a sweep passes (the caster's corners are read-only): a worker's first
    sweep then compiles nothing."""
    from planner.sim import sweep_kernel

    sweep_kernel.load_kernel()
    before = set(sweep_kernel.first_contact.signatures)
    caster = MeshRayCaster(trimesh.creation.box(extents=(0.4, 0.4, 0.1)))
    tri = np.arange(12, dtype=np.int64)
    sweep_contact(caster, np.array([0.05, 0.02, 0.1]), np.array([0.0, 0.0, -1.0]), 0.003, tri)
    assert set(sweep_kernel.first_contact.signatures) == before
