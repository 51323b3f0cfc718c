"""Sphere covers of link collision shapes, as binary sphere trees (link frame).

Each shape is cut into cells of at most :func:`cell_size` along each axis and every cell that
may hold part of the shape gets the sphere through its corners (its circumsphere), so the
union of the leaves covers the shape's solid: every point of the shape lies in some leaf. The
leaves of a link are then grouped into a binary tree, top-down by the median along the widest
spread; a node's sphere holds both children's spheres. A query walks down only where a node is
not clear (:mod:`planner.cell.kernels.broad_kernels`).

Cylinders thinner than a cell are cut along their axis only (each piece's sphere holds the
disc); other cylinders, boxes and hulls are cut on a grid of their box; a hull's cells that lie
wholly outside one of its faces are dropped.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass

import numpy as np
import trimesh
from numpy.typing import NDArray

from planner.cell.broad.link_geometry import LinkShape
from planner.memo import Memo

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Smallest cell edge, m, and the most cells along a shape's longest side.
MIN_CELL_M = 0.02
MAX_CELLS_PER_SIDE = 8


@dataclass(frozen=True)
class SphereTree:
    """A binary tree of spheres, root first.

    Attributes:
        center: ``(K, 3)`` sphere centres, link frame, m.
        radius: ``(K,)`` radii, m.
        child: ``(K,)`` index of the first of the node's two (consecutive) children; -1 for a
            leaf.
        shape: ``(K,)`` for a leaf, the index of the link shape it covers; -1 for inner nodes.
    """

    center: FloatArray
    radius: FloatArray
    child: IntArray
    shape: IntArray

    @property
    def leaves(self) -> NDArray[np.bool_]:
        """``(K,)`` True for the leaves."""
        return self.child < 0


def cell_size(extents: FloatArray) -> float:
    """Cell edge for a shape of ``extents (3,)``, m: ``MIN_CELL_M`` or the longest side over
    ``MAX_CELLS_PER_SIDE``, whichever is larger."""
    return max(MIN_CELL_M, float(np.max(extents)) / MAX_CELLS_PER_SIDE)


def _grid_cells(lo: FloatArray, hi: FloatArray, cell: float) -> tuple[FloatArray, FloatArray]:
    """Centres ``(C, 3)`` and full sizes ``(3,)`` of a grid of cells over the box ``lo..hi``."""
    ext = np.maximum(hi - lo, 0.0)
    n = np.maximum(1, np.ceil(ext / cell - 1e-9)).astype(int)
    size = ext / n
    axes = [lo[k] + (np.arange(n[k]) + 0.5) * size[k] for k in range(3)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    return grid, size


def shape_leaves(shape: LinkShape) -> tuple[FloatArray, FloatArray]:
    """Leaf spheres ``(centres (C, 3), radii (C,))`` covering ``shape``, link frame.

    Raises:
        ValueError: the shape is ``"unknown"`` (it cannot be covered).
    """
    if shape.kind == "sphere":
        c, r = np.zeros((1, 3)), np.array([shape.size_m[0]])
    elif shape.kind in ("cylinder", "capsule"):
        c, r = _cylinder_leaves(shape.size_m[0], shape.size_m[1], shape.kind == "capsule")
    elif shape.kind == "box":
        half = np.asarray(shape.size_m) / 2
        c, size = _grid_cells(-half, half, cell_size(2 * half))
        r = np.full(len(c), float(np.linalg.norm(size)) / 2)
    elif shape.kind == "hull" and shape.vertices_m is not None:
        c, r = _hull_leaves(shape.vertices_m)
    else:
        raise ValueError(f"cannot cover a shape of kind {shape.kind!r}")
    T = shape.T_link_shape
    return c @ T[:3, :3].T + T[:3, 3], r


def _cylinder_leaves(radius: float, length: float, capsule: bool) -> tuple[FloatArray, FloatArray]:
    ends = length + (2 * radius if capsule else 0.0)
    cell = cell_size(np.array([2 * radius, 2 * radius, ends]))
    if 2 * radius <= cell:  # pieces along the axis; each sphere holds its piece's discs
        n = max(1, math.ceil(length / cell - 1e-9))
        piece = length / n
        z = -length / 2 + (np.arange(n) + 0.5) * piece
        c = np.column_stack([np.zeros(n), np.zeros(n), z])
        r = math.hypot(radius, piece / 2) if not capsule else radius + piece / 2
        return c, np.full(n, r)
    half = np.array([radius, radius, ends / 2])
    c, size = _grid_cells(-half, half, cell)
    # keep cells whose xy rectangle comes within the radius of the axis
    near = np.maximum(np.abs(c[:, :2]) - size[:2] / 2, 0.0)
    keep = np.hypot(near[:, 0], near[:, 1]) <= radius
    c = c[keep]
    return c, np.full(len(c), float(np.linalg.norm(size)) / 2)


def _hull_leaves(vertices: FloatArray) -> tuple[FloatArray, FloatArray]:
    pts = np.asarray(vertices, dtype=float)
    try:
        hull = trimesh.convex.convex_hull(pts)
        T_obb, ext = trimesh.bounds.oriented_bounds(hull)
        T_hull_obb = np.linalg.inv(T_obb)
    except Exception:  # degenerate point sets (flat, collinear): fall back to the axis box
        hull = None
        T_hull_obb = np.eye(4)
        T_hull_obb[:3, 3] = (pts.min(0) + pts.max(0)) / 2
        ext = pts.max(0) - pts.min(0)
    half = np.asarray(ext, dtype=float) / 2
    c_obb, size = _grid_cells(-half, half, cell_size(2 * half))
    c = c_obb @ T_hull_obb[:3, :3].T + T_hull_obb[:3, 3]
    r = float(np.linalg.norm(size)) / 2
    if hull is not None and len(hull.faces) > 0:
        # drop cells whose circumsphere lies wholly outside one face plane of the hull
        normals = hull.face_normals
        offsets = np.einsum("ij,ij->i", normals, hull.vertices[hull.faces[:, 0]])
        outside = (c @ normals.T - offsets) > r
        c = c[~outside.any(axis=1)]
    if len(c) == 0:
        c = np.array([pts.mean(axis=0)])
        r = float(np.max(np.linalg.norm(pts - c, axis=1)))
    return c, np.full(len(c), r)


def _bounding(centers: FloatArray, radii: FloatArray) -> tuple[FloatArray, float]:
    lo = (centers - radii[:, None]).min(axis=0)
    hi = (centers + radii[:, None]).max(axis=0)
    mid = (lo + hi) / 2
    r = float(np.max(np.linalg.norm(centers - mid, axis=1) + radii))
    return mid, r * (1 + 1e-12) + 1e-12


def build_tree(centers: FloatArray, radii: FloatArray, tags: IntArray | None = None) -> SphereTree:
    """A binary sphere tree over leaf spheres ``centers (C, 3)``, ``radii (C,)`` (C >= 1),
    each leaf tagged with ``tags (C,)`` (default 0: the shape it covers).

    Every node's sphere contains its children's spheres (and so all leaves below it).
    """
    C = len(radii)
    tags = np.zeros(C, dtype=np.int64) if tags is None else np.asarray(tags, dtype=np.int64)
    out_c = np.zeros((2 * C - 1, 3))
    out_r = np.zeros(2 * C - 1)
    out_child = np.full(2 * C - 1, -1, dtype=np.int64)
    out_shape = np.full(2 * C - 1, -1, dtype=np.int64)
    next_free = 1
    stack = [(0, np.arange(C))]
    while stack:
        node, idx = stack.pop()
        if len(idx) == 1:
            out_c[node], out_r[node] = centers[idx[0]], radii[idx[0]]
            out_shape[node] = tags[idx[0]]
            continue
        out_c[node], out_r[node] = _bounding(centers[idx], radii[idx])
        spread = centers[idx].max(axis=0) - centers[idx].min(axis=0)
        axis = int(np.argmax(spread))
        order = idx[np.argsort(centers[idx, axis], kind="stable")]
        half = len(order) // 2
        left, right = next_free, next_free + 1
        next_free += 2
        out_child[node] = left
        stack.append((left, order[:half]))
        stack.append((right, order[half:]))
    n = next_free
    return SphereTree(out_c[:n], out_r[:n], out_child[:n], out_shape[:n])


def link_tree(shapes: tuple[LinkShape, ...]) -> SphereTree | None:
    """The sphere tree of a link's shapes; ``None`` when one of them cannot be covered.

    Kept per leaf content: every cell of the same robot and tool has the same trees, and
    building one takes far longer than its leaves (the same arrays, read-only)."""
    if not shapes or any(s.kind == "unknown" for s in shapes):
        return None
    parts = [shape_leaves(s) for s in shapes]
    centers = np.ascontiguousarray(np.concatenate([c for c, _ in parts]), dtype=np.float64)
    radii = np.ascontiguousarray(np.concatenate([r for _, r in parts]), dtype=np.float64)
    tags = np.concatenate([np.full(len(r), k, dtype=np.int64) for k, (_, r) in enumerate(parts)])
    h = hashlib.sha1(centers.tobytes())
    h.update(radii.tobytes())
    h.update(tags.tobytes())
    key = h.hexdigest()
    tree = _TREES.get(key)
    if tree is None:
        tree = build_tree(centers, radii, tags)
        for a in (tree.center, tree.radius, tree.child, tree.shape):
            a.flags.writeable = False
        tree = _TREES.put(key, tree)
    return tree


#: :func:`link_tree`'s trees: ``{content hash of the leaves: tree}``.
_TREES: Memo[str, SphereTree] = Memo(256)
