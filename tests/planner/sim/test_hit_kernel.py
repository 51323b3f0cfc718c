"""planner.sim.hit_kernel: the compiled float64 step of a ray cast gives, ray for ray and bit for
bit, what the caster's numpy version gave (kept here as the reference), on the stator (holes,
real edges, the bulge, rays from inside), across float32 seams and on the plate's STL."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import trimesh

from calib.models.proximity import ProximitySensor
from planner.parts.stator import StatorGeometry
from planner.parts.stator_mesh import build_stator_mesh
from planner.sim.raycast import MeshRayCaster

FloatArray = np.ndarray
#: how often the reference took each branch (the test is only as good as its cases)
BRANCHES: dict[str, int] = {}


def reference_first_hits_ids(
    c: MeshRayCaster, origins: FloatArray, directions: FloatArray, depth: int = 0
) -> tuple[FloatArray, FloatArray]:
    """``MeshRayCaster.first_hits_ids`` as it was in numpy, before the compiled step."""
    o = np.ascontiguousarray(origins, dtype=np.float64)
    d = np.ascontiguousarray(directions, dtype=np.float64)
    out = np.full(len(o), np.inf)
    tri_out = np.full(len(o), -1, dtype=np.int64)
    if len(o) == 0:
        return out, tri_out
    tri = np.asarray(c._scene.run(o.astype(np.float32), d.astype(np.float32)), dtype=np.int64)
    idx = np.flatnonzero(tri >= 0)
    if len(idx) == 0:
        return out, tri_out
    denom, t = _plane_hits(c, o[idx], d[idx], tri[idx], parallel=0.0)
    t = np.maximum(t, 0.0)
    beyond = _beyond_real_edge(c, o[idx] + t[:, None] * d[idx], tri[idx])
    if np.any(beyond):
        b = np.flatnonzero(beyond)
        nb_tri, nb_t = _neighbour_hits(c, o[idx[b]], d[idx[b]], t[b], tri[idx[b]])
        on = nb_tri >= 0
        BRANCHES["neighbour"] = BRANCHES.get("neighbour", 0) + int(on.sum())
        tri[idx[b[on]]], t[b[on]] = nb_tri[on], nb_t[on]
        denom[b[on]] = np.einsum("ij,ij->i", c._normals[nb_tri[on]], d[idx[b[on]]])
        beyond[b[on]] = False
    keep = ~beyond
    BRANCHES["inside"] = BRANCHES.get("inside", 0) + int(np.sum(denom[keep] > 0))
    out[idx[keep]] = np.where(denom[keep] > 0, 0.0, t[keep])
    tri_out[idx[keep]] = tri[idx[keep]]
    if np.any(beyond) and depth < 4:
        BRANCHES["continued"] = BRANCHES.get("continued", 0) + int(beyond.sum())
        r = idx[beyond]
        step = 1e-9 * c._scale
        more, more_tri = reference_first_hits_ids(
            c, o[r] + (t[beyond] + step)[:, None] * d[r], d[r], depth + 1
        )
        out[r] = t[beyond] + step + more
        tri_out[r] = more_tri
    return out, tri_out


def _neighbour_hits(c: Any, o: Any, d: Any, t: Any, tri: Any) -> tuple[Any, Any]:
    dist = _edge_distances(c, o + t[:, None] * d, tri)
    nb = c._neighbour[tri, np.argmin(dist, axis=1)]
    out_tri = np.full(len(tri), -1, dtype=np.int64)
    out_t = np.array(t, dtype=np.float64)
    has = np.flatnonzero(nb >= 0)
    if len(has) == 0:
        return out_tri, out_t
    _, t_nb = _plane_hits(c, o[has], d[has], nb[has], parallel=np.inf)
    q = o[has] + np.where(np.isfinite(t_nb), t_nb, 0.0)[:, None] * d[has]
    inside = _edge_distances(c, q, nb[has]).min(axis=1) >= -1e-12 * c._scale
    ok = inside & (np.abs(t_nb - t[has]) <= 1e-7 * c._scale)
    out_tri[has[ok]] = nb[has[ok]]
    out_t[has[ok]] = np.maximum(t_nb[ok], 0.0)
    return out_tri, out_t


def _plane_hits(c: Any, o: Any, d: Any, tri: Any, parallel: float) -> tuple[Any, Any]:
    n = c._normals[tri]
    denom = np.einsum("ij,ij->i", n, d)
    num = c._offsets[tri] - np.einsum("ij,ij->i", n, o)
    with np.errstate(divide="ignore", invalid="ignore"):
        return denom, np.where(np.abs(denom) > 1e-15, num / denom, parallel)


def _edge_distances(c: Any, p: Any, tri: Any) -> Any:
    return np.einsum("kej,kj->ke", c._edge_normals[tri], p) - c._edge_offsets[tri]


def _beyond_real_edge(c: Any, p: Any, tri: Any) -> Any:
    flags = np.zeros(len(tri), bool)
    check = np.flatnonzero(c._has_sharp[tri])
    if len(check) == 0:
        return flags
    t = tri[check]
    dist = _edge_distances(c, p[check], t)
    worst = np.argmin(dist, axis=1)
    outside = dist[np.arange(len(t)), worst] < -1e-12 * c._scale
    flags[check] = outside & c._sharp[t, worst]
    return flags


def _assert_same(c: MeshRayCaster, o: FloatArray, d: FloatArray) -> None:
    dist, tri = c.first_hits_ids(o, d)
    want_d, want_t = reference_first_hits_ids(c, o, d)
    assert np.array_equal(tri, want_t)
    assert np.array_equal(dist.view(np.int64), want_d.view(np.int64))  # every bit, signs too


@pytest.fixture(scope="module")
def stator() -> MeshRayCaster:
    return MeshRayCaster(build_stator_mesh(StatorGeometry.full_section()))


def test_sensor_bundles_on_the_stator_are_bit_for_bit(stator: MeshRayCaster) -> None:
    """Bundles of 256 rays over the side face (teeth, holes, the bulge), tilted up to 10 deg,
    from 20 mm out to 3 mm inside the part, and across the top edge."""
    rng = np.random.default_rng(11)
    s = ProximitySensor()
    for _ in range(60):
        axis = np.array([-1.0, 0.0, 0.0]) + rng.normal(0.0, 0.09, 3)
        axis /= np.linalg.norm(axis)
        y, z = rng.uniform(-1.0, -0.02), rng.uniform(-0.2, 0.01)
        tcp = np.array([rng.uniform(-0.003, 0.02), y, z])
        o = s.ray_origins(tcp, axis)
        _assert_same(stator, o, np.tile(axis, (len(o), 1)))


def test_grazing_and_random_rays_on_the_stator_are_bit_for_bit(stator: MeshRayCaster) -> None:
    """Rays along the side face and through the slot holes (their walls are real edges), and
    rays in every direction from around and inside the part."""
    rng = np.random.default_rng(12)
    n = 20_000
    o = np.column_stack(
        [rng.uniform(-0.3, 0.05, n), rng.uniform(-1.05, 0.05, n), rng.uniform(-0.25, 0.05, n)]
    )
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    _assert_same(stator, o, d)
    along = np.tile(np.array([0.0, 0.3, 0.95]) / np.linalg.norm([0.0, 0.3, 0.95]), (n, 1))
    o2 = np.column_stack([rng.uniform(-1e-6, 1e-6, n), rng.uniform(-1, 0, n), np.full(n, -0.3)])
    _assert_same(stator, o2, along)
    assert BRANCHES.get("inside", 0) > 100 and BRANCHES.get("continued", 0) > 0


def _seam_box(tilt_m: float) -> trimesh.Trimesh:
    box = trimesh.creation.box(extents=(0.1, 0.1, 0.02))
    box.apply_translation((0.05, 0.05, 0.01))
    v = np.array(box.vertices)
    corner = np.flatnonzero(np.all(np.isclose(v, [0.1, 0.1, 0.02]), axis=1))
    v[corner, 2] += tilt_m
    return trimesh.Trimesh(v, box.faces, process=False)


def test_rays_across_float32_seams_are_bit_for_bit() -> None:
    """Through the seam of two top triangles 2e-8 rad apart (the neighbour's hit) and just
    beyond the top's real edges (continued past it)."""
    c = MeshRayCaster(_seam_box(2e-9))
    n = 4001
    t = np.linspace(0.0, 1.0, n)
    off = np.linspace(-5e-8, 5e-8, n)
    xy = np.column_stack([0.05 + 0.9 * (t - 0.5) * 0.1 + off, 0.05 + 0.9 * (t - 0.5) * 0.1 - off])
    o = np.column_stack([xy, np.full(n, 0.05)])
    down = np.tile([0.0, 0.0, -1.0], (n, 1))
    _assert_same(c, o, down)
    edge = np.column_stack([np.full(n, 0.1) + off, np.linspace(0.001, 0.099, n), np.full(n, 0.05)])
    _assert_same(c, edge, down)
    assert BRANCHES.get("neighbour", 0) > 0


def test_the_plates_stl_is_bit_for_bit(reference_dir: Path) -> None:
    """Touch-probe bundles and random rays on the plate (407 float32 seams of its flat faces)."""
    mesh = trimesh.load(reference_dir / "parts" / "plate_holes.STL", force="mesh")
    mesh.apply_scale(1e-3)
    c = MeshRayCaster(mesh)
    rng = np.random.default_rng(13)
    lo, hi = mesh.bounds
    n = 30_000
    o = rng.uniform(lo - 0.01, hi + 0.01, size=(n, 3))
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    _assert_same(c, o, d)
    top = np.column_stack(
        [rng.uniform(lo[0], hi[0], n), rng.uniform(lo[1], hi[1], n), np.full(n, hi[2] + 0.01)]
    )
    _assert_same(c, top, np.tile([0.0, 0.0, -1.0], (n, 1)))
