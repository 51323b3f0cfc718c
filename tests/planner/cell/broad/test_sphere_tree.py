"""Tests of planner.cell.broad.sphere_tree and planner.cell.kernels.gjk_kernels: covers that cover,
trees whose nodes hold their children, and GJK bounds against exact distances."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from calib.frames import make_transform
from planner.cell.broad.link_geometry import LinkShape
from planner.cell.broad.sphere_tree import build_tree, link_tree, shape_leaves
from planner.cell.kernels import gjk_kernels as G

T = make_transform(Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix(), [0.1, -0.2, 0.3])
HULL = trimesh.creation.icosphere(subdivisions=1, radius=0.05).vertices * [1.0, 2.0, 0.5]
SHAPES = [
    LinkShape("box", T, (0.3, 0.1, 0.05)),
    LinkShape("cylinder", T, (0.09, 0.64)),
    LinkShape("cylinder", T, (0.009, 0.06)),
    LinkShape("capsule", T, (0.02, 0.1)),
    LinkShape("sphere", T, (0.04,)),
    LinkShape("hull", T, (), HULL),
]


def points_inside(shape: LinkShape, rng: np.random.Generator, n: int = 4000) -> np.ndarray:
    """Random points of the shape's solid (and of its surface), link frame."""
    if shape.kind == "box":
        p = rng.uniform(-0.5, 0.5, (n, 3)) * shape.size_m
        p[: n // 2, 0] = np.sign(p[: n // 2, 0]) * shape.size_m[0] / 2  # on two faces
    elif shape.kind in ("cylinder", "capsule"):
        r, h = shape.size_m
        a, rad = rng.uniform(0, 2 * np.pi, n), r * np.sqrt(rng.uniform(0, 1, n))
        rad[: n // 2] = r  # on the side
        p = np.column_stack([rad * np.cos(a), rad * np.sin(a), rng.uniform(-h / 2, h / 2, n)])
        if shape.kind == "capsule":
            cap = rng.normal(size=(n // 4, 3))
            cap = cap / np.linalg.norm(cap, axis=1, keepdims=True) * r
            p[: n // 4] = cap + np.array([0, 0, h / 2])
    elif shape.kind == "sphere":
        d = rng.normal(size=(n, 3))
        p = d / np.linalg.norm(d, axis=1, keepdims=True) * shape.size_m[0]
    else:
        hull = trimesh.convex.convex_hull(shape.vertices_m)
        p = np.concatenate([hull.sample(n // 2), trimesh.sample.volume_mesh(hull, n)])
    return p @ shape.T_link_shape[:3, :3].T + shape.T_link_shape[:3, 3]


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: f"{s.kind}{s.size_m}")
def test_the_leaves_cover_the_shape(shape: LinkShape, rng) -> None:
    c, r = shape_leaves(shape)
    p = points_inside(shape, rng)
    inside = np.linalg.norm(p[:, None] - c[None], axis=2) <= r[None] + 1e-12
    assert inside.any(axis=1).all()


def _leaves_below(tree, k: int) -> list[int]:  # type: ignore[no-untyped-def]
    if tree.child[k] < 0:
        return [k]
    return _leaves_below(tree, tree.child[k]) + _leaves_below(tree, tree.child[k] + 1)


def test_every_node_holds_its_leaves_and_leaves_name_their_shape(rng) -> None:
    """A node cleared clears its whole subtree: its sphere holds every leaf sphere below."""
    tree = link_tree(tuple(SHAPES))
    assert tree is not None
    for k in np.flatnonzero(tree.child >= 0):
        below = _leaves_below(tree, int(k))
        gap = np.linalg.norm(tree.center[below] - tree.center[k], axis=1) + tree.radius[below]
        assert np.all(gap <= tree.radius[k] + 1e-12)
    leaves = tree.leaves
    assert set(tree.shape[leaves]) == set(range(len(SHAPES))) and np.all(tree.shape[~leaves] == -1)
    single = build_tree(np.zeros((1, 3)), np.ones(1))
    assert single.child.tolist() == [-1] and single.radius.tolist() == [1.0]


def test_a_link_tree_is_kept_per_leaf_content() -> None:
    """The same shapes again (new objects) get the kept tree, equal to one built afresh and
    read-only; shapes moved in the link get their own."""
    import dataclasses

    tree = link_tree(tuple(SHAPES))
    again = link_tree(tuple(dataclasses.replace(s) for s in SHAPES))
    assert again is tree and tree is not None
    parts = [shape_leaves(s) for s in SHAPES]
    tags = np.concatenate([np.full(len(r), k) for k, (_, r) in enumerate(parts)])
    fresh = build_tree(
        np.concatenate([c for c, _ in parts]), np.concatenate([r for _, r in parts]), tags
    )
    for name in ("center", "radius", "child", "shape"):
        assert np.array_equal(getattr(tree, name), getattr(fresh, name))
    with pytest.raises(ValueError):
        tree.radius[0] = 0.0
    T = SHAPES[0].T_link_shape.copy()
    T[0, 3] += 0.1
    moved = link_tree((dataclasses.replace(SHAPES[0], T_link_shape=T), *SHAPES[1:]))
    assert moved is not None and moved is not tree
    assert not np.array_equal(moved.center, tree.center)


def test_unknown_shapes_get_no_tree() -> None:
    assert link_tree((LinkShape("unknown", np.eye(4)),)) is None
    assert link_tree(()) is None


def _shape(kind: int, R: np.ndarray, t: np.ndarray, dims, verts=None):  # type: ignore[no-untyped-def]
    T34 = np.ascontiguousarray(np.hstack([R, t[:, None]]))
    v = np.zeros((1, 3)) if verts is None else np.ascontiguousarray(verts, dtype=float)
    return kind, T34, np.asarray(dims, dtype=float), v, 0, 0 if verts is None else len(v)


@pytest.mark.slow
def test_gjk_bounds_hold_against_exact_distances(rng) -> None:
    """Spheres against boxes, cylinders, capsules and hulls: the exact distance is the
    distance from the sphere's centre to the other shape (computed independently) minus its
    radius. ``gjk_classify`` may say "apart by at least" only below it, "nearer than" only
    above it, and settles nearly every query 0.1 mm either side of it."""
    settled = 0
    for _ in range(1500):
        R = Rotation.random(random_state=int(rng.integers(1 << 30))).as_matrix()
        t = rng.uniform(-0.1, 0.1, 3)
        kind = int(rng.integers(0, 4))
        if kind == 0:
            half = rng.uniform(0.01, 0.1, 3)
            other = _shape(G.BOX, R, t, half)
            trimesh_shape = trimesh.creation.box(2 * half, transform=make_transform(R, t))
        elif kind == 1:
            r, h = rng.uniform(0.01, 0.1), rng.uniform(0.01, 0.2)
            other = _shape(G.CYLINDER, R, t, [r, h, 0])
            trimesh_shape = trimesh.creation.cylinder(
                r, 2 * h, sections=256, transform=make_transform(R, t)
            )
        elif kind == 2:
            r, h = rng.uniform(0.01, 0.05), rng.uniform(0.0, 0.1)
            other = _shape(G.CAPSULE, R, t, [r, h, 0])
            trimesh_shape = None
            seg = (R @ np.array([[0, 0, -h], [0, 0, h]]).T).T + t
        else:
            v = rng.normal(size=(12, 3)) * rng.uniform(0.01, 0.08)
            other = _shape(G.HULL, R, t, [0, 0, 0], v)
            trimesh_shape = trimesh.convex.convex_hull((R @ v.T).T + t)
        c = rng.normal(size=3)
        c = c / np.linalg.norm(c) * rng.uniform(0.05, 0.4)
        rs = rng.uniform(0.005, 0.05)
        sphere = _shape(G.SPHERE, np.eye(3), c, [rs, 0, 0])
        if trimesh_shape is None:
            u = np.clip(
                (c - seg[0])
                @ (seg[1] - seg[0])
                / max((seg[1] - seg[0]) @ (seg[1] - seg[0]), 1e-30),
                0,
                1,
            )
            d_centre = np.linalg.norm(c - (seg[0] + u * (seg[1] - seg[0]))) - other[2][0]
        else:
            d_centre = trimesh.proximity.closest_point(trimesh_shape, c[None])[1][0]
            if trimesh_shape.contains(c[None])[0]:
                d_centre = -1.0
        d = d_centre - rs
        if d <= 0.002:
            continue  # overlapping or touching: distances above are only meaningful apart
        tol = 1e-3 if kind == 1 else 1e-7  # the tessellated cylinder is up to 1 mm off
        for clear, near in ((d - 1e-4, -np.inf), (d + 1e-4, d + 2e-4), (d + 1e-4, d - 1e-4)):
            r = G.gjk_classify(*sphere, *other, clear, near)
            assert not (r == 1 and clear > d + tol), (kind, d, clear)
            assert not (r == -1 and near <= d - tol), (kind, d, near)
        settled += G.gjk_classify(*sphere, *other, d - 1e-4, -np.inf) == 1
    assert settled >= 900
