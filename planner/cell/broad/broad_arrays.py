"""The broad phase's arrays: its links, and the layouts its compiled kernels take.

:mod:`planner.cell.broad.broad_phase` builds these once per cell (links, trees, shapes) or per query
(environment bodies, the parts of a query plan); :mod:`planner.cell.kernels.broad_kernels` and
:mod:`planner.cell.kernels.gjk_kernels` document the layouts.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh
from numpy.typing import NDArray

from planner.cell.broad.distance_field import DistanceField
from planner.cell.broad.link_geometry import LinkShape
from planner.cell.broad.sphere_tree import SphereTree
from planner.cell.kernels import gjk_kernels as G

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


@dataclass(frozen=True)
class BroadLink:
    """One robot or tool link of the broad phase.

    Attributes:
        body: PyBullet body id; link: link index in it.
        name: the link's report name.
        shapes: its collision shapes (link frame).
        tree: its sphere tree (link frame), ``None`` when it cannot be covered.
        inflation_m: Bullet's inflation of its shapes, m.
        excess_m: how much Bullet's distance to it can exceed the true one, m (its rounded
            box and cylinder edges).
        joint: robot links: index of the moving joint the link follows (-1: the base);
            tool links: ``None``.
        T_const: robot links: ``T_joint_link`` (or ``T_base_link``); tool links:
            ``T_flange_link``; ``None`` when the pose is unknown.
    """

    body: int
    link: int
    name: str
    shapes: tuple[LinkShape, ...]
    tree: SphereTree | None
    inflation_m: float
    excess_m: float
    joint: int | None
    T_const: FloatArray | None


@dataclass(frozen=True)
class EnvArrays:
    """Environment bodies in the kernels' layout (see :mod:`planner.cell.kernels.broad_kernels`).

    Attributes:
        index: body id -> row.
        inflation_m: ``(E,)`` Bullet's inflation of each body's shape, m.
        excess_m: ``(E,)`` how much Bullet's distance to it can exceed the true one, m.
        arrays: ``(kind, Tinv, T, dims, field)``: the bodies.
        fields: the distance fields, bucket grids and triangles of the mesh bodies.
    """

    index: dict[int, int]
    inflation_m: FloatArray
    excess_m: FloatArray
    arrays: tuple[NDArray, ...]
    fields: tuple[NDArray, ...]


@dataclass
class PartMap:
    """The parts of one query plan mapped onto broad-phase links and bodies.

    Attributes:
        part_link, part_env, part_thr, part_near: ``(P,)`` per env part (robot/tool kind, in
            plan order): link index, env index, clear threshold (look distance plus margins),
            near threshold (a part certified nearer than this has slack below the margin), m;
            ``known (P,)`` whether it can be decided here.
        part_index: ``(P,)`` index of each in ``plan.parts``.
        pair_a, pair_b, pair_thr, pair_near: ``(S,)`` per self pair of the checker's pair table;
            ``pair_known (S,)``; ``pair_fixed_clear (S,)``: pairs of links that never move
            against each other (both on one joint, e.g. the flange link and the tool) which
            Bullet, asked once, finds clear.
    """

    part_link: NDArray[np.int64]
    part_env: NDArray[np.int64]
    part_thr: FloatArray
    part_near: FloatArray
    known: BoolArray
    part_index: NDArray[np.int64]
    pair_a: NDArray[np.int64]
    pair_b: NDArray[np.int64]
    pair_thr: FloatArray
    pair_near: FloatArray
    pair_known: BoolArray
    pair_fixed_clear: BoolArray


def tree_arrays(links: list[BroadLink]) -> tuple[NDArray, ...]:
    """``(node_c, node_r, node_child, link_root, node_shape)`` of all links: their trees
    concatenated, leaves tagged with the global index of their shape in
    :meth:`shape_arrays` (links without a tree get an empty root; they are never
    queried)."""
    cs, rs, ch, sh, roots = [], [], [], [], []
    offset = 0
    shape0 = 0
    for b in links:
        t = b.tree
        if t is None:
            roots.append(0)
            continue
        cs.append(t.center)
        rs.append(t.radius)
        ch.append(np.where(t.child >= 0, t.child + offset, -1))
        sh.append(np.where(t.shape >= 0, t.shape + shape0, -1))
        roots.append(offset)
        offset += len(t.radius)
        shape0 += len(b.shapes)
    if not cs:
        cs, rs, ch, sh = (
            [np.zeros((1, 3))],
            [np.zeros(1)],
            [np.full(1, -1)],
            [np.full(1, -1)],
        )
    return (
        np.ascontiguousarray(np.concatenate(cs)),
        np.ascontiguousarray(np.concatenate(rs)),
        np.ascontiguousarray(np.concatenate(ch).astype(np.int64)),
        np.array(roots, dtype=np.int64),
        np.ascontiguousarray(np.concatenate(sh).astype(np.int64)),
    )


def shape_arrays(links: list[BroadLink]) -> tuple[NDArray, ...]:
    """``(kind, T_link_shape (S, 3, 4), dims, center, half, vstart, vcount, verts,
    link_start (L,), link_count (L,))``: the links' shapes in the GJK layout
    (:mod:`planner.cell.kernels.gjk_kernels`); ``center``/``half``: each shape's box, shape
    frame."""
    kind: list[int] = []
    T: list[FloatArray] = []
    dims: list[FloatArray] = []
    center: list[FloatArray] = []
    half: list[FloatArray] = []
    vs: list[int] = []
    vc: list[int] = []
    verts = [np.zeros((1, 3))]
    nverts = 1
    l0, ln = [], []
    for b in links:
        usable = b.tree is not None
        l0.append(len(kind))
        ln.append(len(b.shapes) if usable else 0)
        if not usable:
            continue
        for sh in b.shapes:
            k, d, c, h, v = gjk_shape(sh)
            kind.append(k)
            T.append(sh.T_link_shape[:3])
            dims.append(d)
            center.append(c)
            half.append(h)
            vs.append(nverts if v is not None else 0)
            vc.append(len(v) if v is not None else 0)
            if v is not None:
                verts.append(v)
                nverts += len(v)
    S = len(kind)
    return (
        np.array(kind, dtype=np.int64),
        np.ascontiguousarray(np.array(T, dtype=float).reshape(S, 3, 4)),
        np.array(dims, dtype=float).reshape(S, 3),
        np.array(center, dtype=float).reshape(S, 3),
        np.array(half, dtype=float).reshape(S, 3),
        np.array(vs, dtype=np.int64),
        np.array(vc, dtype=np.int64),
        np.ascontiguousarray(np.concatenate(verts)),
        np.array(l0, dtype=np.int64),
        np.array(ln, dtype=np.int64),
    )


def gjk_shape(sh: LinkShape) -> tuple[int, FloatArray, FloatArray, FloatArray, FloatArray | None]:
    """``(kind, dims, box centre, box half extents, hull vertices)`` of a shape for GJK."""
    if sh.kind == "box":
        half = np.asarray(sh.size_m, dtype=float) / 2
        return G.BOX, half, np.zeros(3), half, None
    if sh.kind in ("cylinder", "capsule"):
        r, hz = sh.size_m[0], sh.size_m[1] / 2
        cap = sh.kind == "capsule"
        box = np.array([r, r, hz + (r if cap else 0.0)])
        return (G.CAPSULE if cap else G.CYLINDER), np.array([r, hz, 0.0]), np.zeros(3), box, None
    if sh.kind == "sphere":
        r = sh.size_m[0]
        return G.SPHERE, np.array([r, 0.0, 0.0]), np.zeros(3), np.full(3, r), None
    assert sh.vertices_m is not None
    v = np.ascontiguousarray(sh.vertices_m, dtype=float)
    lo, hi = v.min(axis=0), v.max(axis=0)
    return G.HULL, np.zeros(3), (lo + hi) / 2, (hi - lo) / 2, v


def concat_fields(fields: list[tuple[DistanceField, trimesh.Trimesh]]) -> tuple[NDArray, ...]:
    """The fields, bucket grids and triangles of the mesh bodies, concatenated (see
    :mod:`planner.cell.kernels.broad_kernels`)."""
    if not fields:
        flds: list[DistanceField] = []
        meshes: list[trimesh.Trimesh] = []
    else:
        flds = [f for f, _ in fields]
        meshes = [m for _, m in fields]

    def offsets(sizes: list[int]) -> NDArray[np.int64]:
        return np.cumsum([0, *sizes[:-1]]).astype(np.int64) if sizes else np.zeros(0, np.int64)

    def cat(arrays: list[NDArray], empty: NDArray) -> NDArray:
        return np.ascontiguousarray(np.concatenate(arrays)) if arrays else empty

    F = len(flds)
    return (
        np.array([f.origin for f in flds], dtype=float).reshape(F, 3),
        np.array([f.spacing for f in flds], dtype=float),
        np.array([f.values.shape for f in flds], dtype=np.int64).reshape(F, 3),
        offsets([f.values.size for f in flds]),
        cat([f.values.ravel() for f in flds], np.zeros(0, np.float32)),
        np.array([f.lo for f in flds], dtype=float).reshape(F, 3),
        np.array([f.hi for f in flds], dtype=float).reshape(F, 3),
        np.array([f.bucket_origin for f in flds], dtype=float).reshape(F, 3),
        np.array([f.bucket_size for f in flds], dtype=float),
        np.array([f.bucket_n for f in flds], dtype=np.int64).reshape(F, 3),
        offsets([f.bucket_start.size for f in flds]),
        cat([f.bucket_start for f in flds], np.zeros(0, np.int64)),
        offsets([f.bucket_tris.size for f in flds]),
        cat([f.bucket_tris for f in flds], np.zeros(0, np.int64)),
        offsets([len(m.vertices) for m in meshes]),
        offsets([len(m.faces) for m in meshes]),
        cat([np.asarray(m.vertices, dtype=float) for m in meshes], np.zeros((0, 3))),
        cat([np.asarray(m.faces, dtype=np.int64) for m in meshes], np.zeros((0, 3), np.int64)),
    )
