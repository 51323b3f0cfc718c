"""Broad phase of the clearance query: which parts surely report nothing, for many candidates.

A clearance query (:meth:`planner.cell.collision.CollisionChecker.plan`) is made of parts: a
robot or tool link against an environment body, looking ``dist_m`` far, and the self part,
whose link pairs look as far. Bullet reports a part only when it finds a point nearer than the
look distance. The broad phase shows, for whole batches of candidates, that a part (or a self
pair) cannot report anything: every sphere of the link's sphere tree
(:mod:`planner.cell.sphere_tree`) lies at least ``dist_m + margin`` from a lower bound of the
distance to the body (exact for boxes, cylinders and spheres; a distance field for meshes,
:mod:`planner.cell.distance_field`), where ``margin`` is :data:`SAFETY_M` plus Bullet's inflation
of each side (1 mm for a convex hull or a concave triangle mesh, 0 for boxes and cylinders,
which Bullet shrinks and rounds; see :mod:`planner.cell.link_geometry`). Such a part's result is
``None`` in the exact query; the others go to Bullet (:mod:`planner.cell.probe_clearance`), so
the answer is the exact query's.

Link poses: robot links from the chain's forward kinematics (URDF link frames), tool links from
the flange pose. A link whose pose the chain does not know or whose shapes cannot be covered is
never called clear.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import trimesh
from numpy.typing import NDArray

from calib.frames import invert_transform
from planner.cell import broad_kernels as kernels
from planner.cell import gjk_kernels as G
from planner.cell.bodies import world_link_pose
from planner.cell.distance_field import DistanceField, distance_field
from planner.cell.link_geometry import (
    BULLET_MESH_MARGIN_M,
    BULLET_ROUNDING_M,
    LinkShape,
    bullet_excess,
    link_shapes,
)
from planner.cell.pybullet_client import pb
from planner.cell.sphere_tree import SphereTree, link_tree

if TYPE_CHECKING:
    from planner.cell.clearance import QueryPlan
    from planner.cell.scene import CellScene

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

# numba dispatchers take any arguments (their stubs say otherwise)
_parts_state: Any = kernels.parts_state
_pairs_state: Any = kernels.pairs_state

#: Added to every part's look distance before a part is called clear, m (covers Bullet's
#: single-precision poses and the GJK tolerance with a wide margin).
SAFETY_M = 0.0005


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
    """Environment bodies in the kernels' layout (see :mod:`planner.cell.broad_kernels`).

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


@dataclass
class BroadPhase:
    """The broad phase of one cell scene (built by :meth:`of`; rebuilt when its bodies change).

    Attributes:
        links: the broad-phase links, robot then tool.
        fields: distance fields by body id of the mesh bodies (work object, mesh fixtures).
    """

    links: list[BroadLink]
    fields: dict[int, DistanceField] = field(default_factory=dict)
    _by_body_link: dict[tuple[int, int], int] = field(default_factory=dict)
    _meshes: dict[int, trimesh.Trimesh] = field(default_factory=dict)
    _tree_arrays: tuple[NDArray, ...] | None = None
    _shape_arrays: tuple[NDArray, ...] | None = None
    _fixed: dict[float, BoolArray] = field(default_factory=dict)
    _fields_key: tuple[tuple[str, int], ...] | None = None
    _fields_cat: tuple[NDArray, ...] = ()
    _part_map_key: object = None
    _part_map: PartMap | None = None
    #: run the exact (GJK) step where the sphere trees do not clear a part.
    exact: bool = True

    @classmethod
    def of(cls, scene: CellScene) -> BroadPhase:
        """The robot and tool links of ``scene`` with their sphere trees and poses."""
        c = scene.client
        links: list[BroadLink] = []
        attach = scene.chain.link_attach
        robot = scene.robot
        for i in scene.checker._robot_links():
            name = robot.names[i]
            shapes = link_shapes(c, robot, i)
            joint, T = attach.get(name, (None, None))
            links.append(
                BroadLink(
                    robot.body_id, i, scene.checker.names(robot.body_id, i), shapes,
                    link_tree(shapes),
                    max((s.inflation_m for s in shapes), default=0.0),
                    max((bullet_excess(s) for s in shapes), default=0.0), joint,
                    None if T is None else np.asarray(T, dtype=float),
                )
            )  # fmt: skip
        tool = scene.tool_body
        if tool is not None:
            T_world_root = world_link_pose(c, tool, -1)
            mesh = scene.tool.mesh if scene.tool is not None else None
            hull = mesh.convex_hull.vertices if mesh is not None else None
            for i in scene.checker._tool_links():
                shapes = link_shapes(c, tool, i, hull if i == -1 else None)
                T_root_link = invert_transform(T_world_root) @ world_link_pose(c, tool, i)
                links.append(
                    BroadLink(
                        tool.body_id, i, scene.checker.names(tool.body_id, i), shapes,
                        link_tree(shapes),
                        max((s.inflation_m for s in shapes), default=0.0),
                        max((bullet_excess(s) for s in shapes), default=0.0), None, T_root_link,
                    )
                )  # fmt: skip
        bp = cls(links)
        bp._by_body_link = {(b.body, b.link): k for k, b in enumerate(links)}
        return bp

    # ------------------------------------------------------------------ arrays
    def tree_arrays(self) -> tuple[NDArray, ...]:
        """``(node_c, node_r, node_child, link_root, node_shape)`` of all links: their trees
        concatenated, leaves tagged with the global index of their shape in
        :meth:`shape_arrays` (links without a tree get an empty root; they are never
        queried)."""
        if self._tree_arrays is None:
            cs, rs, ch, sh, roots = [], [], [], [], []
            offset = 0
            shape0 = 0
            for b in self.links:
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
            self._tree_arrays = (
                np.ascontiguousarray(np.concatenate(cs)),
                np.ascontiguousarray(np.concatenate(rs)),
                np.ascontiguousarray(np.concatenate(ch).astype(np.int64)),
                np.array(roots, dtype=np.int64),
                np.ascontiguousarray(np.concatenate(sh).astype(np.int64)),
            )
        return self._tree_arrays

    def shape_arrays(self) -> tuple[NDArray, ...]:
        """``(kind, T_link_shape (S, 3, 4), dims, center, half, vstart, vcount, verts,
        link_start (L,), link_count (L,))``: the links' shapes in the GJK layout
        (:mod:`planner.cell.gjk_kernels`); ``center``/``half``: each shape's box, shape frame."""
        if self._shape_arrays is None:
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
            for b in self.links:
                usable = b.tree is not None
                l0.append(len(kind))
                ln.append(len(b.shapes) if usable else 0)
                if not usable:
                    continue
                for sh in b.shapes:
                    k, d, c, h, v = _gjk_shape(sh)
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
            self._shape_arrays = (
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
        return self._shape_arrays

    def environment(self, scene: CellScene) -> EnvArrays:
        """The scene's environment bodies now (poses read from the scene)."""
        bodies = list(scene.checker.environment)
        kinds, Ts, dims, fidx, infl, excess = [], [], [], [], [], []
        fields: list[tuple[DistanceField, trimesh.Trimesh]] = []
        by_name = scene.fixtures
        for body in bodies:
            name = scene.checker.environment[body]
            if body == scene.checker.wobj_body and scene.work_object is not None:
                T = scene.T_world_wobj
                mesh = scene.work_object.mesh
                fld = self._field(body, mesh)
                kind, d = kernels.FIELD, np.zeros(3)
            else:
                fx = by_name[name]
                T = fx.T_world_fixture
                fld = None
                if fx.shape == "box":
                    kind, d = kernels.BOX, np.asarray(fx.size_m, dtype=float) / 2
                elif fx.shape == "cylinder":
                    kind, d = kernels.CYLINDER, np.array([fx.size_m[0], fx.size_m[1] / 2, 0.0])
                else:
                    assert fx.mesh is not None
                    mesh = fx.mesh
                    fld = self._field(body, mesh)
                    kind, d = kernels.FIELD, np.zeros(3)
            kinds.append(kind)
            Ts.append(np.asarray(T, dtype=float))
            dims.append(d)
            fidx.append(len(fields) if fld is not None else -1)
            infl.append(BULLET_MESH_MARGIN_M if fld is not None else 0.0)
            excess.append(0.0 if fld is not None else BULLET_ROUNDING_M)
            if fld is not None:
                fields.append((fld, mesh))
        key = tuple((f.key, id(m)) for f, m in fields)
        if self._fields_key != key:  # concatenating the fields costs a copy of them
            self._fields_cat = _concat_fields(fields)
            self._fields_key = key
        T_all = np.array(Ts).reshape(-1, 4, 4)
        arrays = (
            np.array(kinds, dtype=np.int64),
            np.ascontiguousarray(invert_transform(T_all)[:, :3])
            if len(Ts)
            else np.zeros((0, 3, 4)),
            np.ascontiguousarray(T_all[:, :3]),
            np.ascontiguousarray(np.array(dims, dtype=float).reshape(-1, 3)),
            np.array(fidx, dtype=np.int64),
        )
        return EnvArrays(
            {b: k for k, b in enumerate(bodies)},
            np.array(infl),
            np.array(excess),
            arrays,
            self._fields_cat,
        )

    def _field(self, body: int, mesh: trimesh.Trimesh) -> DistanceField:
        """The distance field of the mesh of ``body`` (rebuilt when the body's mesh changed)."""
        held = self._meshes.get(body)
        if held is None or held is not mesh or body not in self.fields:
            self.fields[body] = distance_field(mesh)
            self._meshes[body] = mesh
        return self.fields[body]

    def link_radius(self, k: int) -> float:
        """Radius of link ``k``'s bounding sphere, m (inf when it has no tree)."""
        t = self.links[k].tree
        return float(t.radius[0]) if t is not None else float("inf")

    def part_map(self, scene: CellScene, plan: QueryPlan, env: EnvArrays) -> PartMap:
        """The plan's parts on this broad phase's links and ``env``'s bodies (kept for the
        next query with the same plan and bodies)."""
        key = (plan, tuple(env.index.items()), tuple(env.inflation_m), tuple(env.excess_m))
        if self._part_map_key != key:
            self._part_map = self._build_part_map(scene, plan, env)
            self._part_map_key = key
        assert self._part_map is not None
        return self._part_map

    def _build_part_map(self, scene: CellScene, plan: QueryPlan, env: EnvArrays) -> PartMap:
        pl, pe, pt, pn, pk, pi = [], [], [], [], [], []
        margin = plan.margin_m
        for part in plan.parts:
            if part.kind == "self":
                continue
            k = self._by_body_link.get((part.body, part.link), -1)
            e = env.index.get(part.env, -1)
            known = k >= 0 and e >= 0 and self._known(k)
            infl = (self.links[k].inflation_m if k >= 0 else 0.0) + (
                env.inflation_m[e] if e >= 0 else 0.0
            )
            excess = (self.links[k].excess_m if k >= 0 else 0.0) + (
                env.excess_m[e] if e >= 0 else 0.0
            )
            pl.append(max(k, 0))
            pe.append(max(e, 0))
            pt.append(part.dist_m + infl + SAFETY_M)
            pn.append(part.need_m + margin - excess - SAFETY_M)
            pk.append(known)
            pi.append(part.index)
        self_look = plan.parts[-1].dist_m
        bodies, link_idx, pa, pb_ = scene.checker._self_pair_table()
        ka = [self._by_body_link.get((bodies[a], link_idx[a]), -1) for a in pa.tolist()]
        kb = [self._by_body_link.get((bodies[b], link_idx[b]), -1) for b in pb_.tolist()]
        pair_known = [
            a >= 0 and b >= 0 and self._known(a) and self._known(b) for a, b in zip(ka, kb)
        ]
        pair_thr = [
            self_look + SAFETY_M + (self.links[a].inflation_m if a >= 0 else 0.0)
            + (self.links[b].inflation_m if b >= 0 else 0.0)
            for a, b in zip(ka, kb)
        ]  # fmt: skip
        self_need = plan.parts[-1].need_m
        pair_near = [
            self_need + margin - SAFETY_M - (self.links[a].excess_m if a >= 0 else 0.0)
            - (self.links[b].excess_m if b >= 0 else 0.0)
            for a, b in zip(ka, kb)
        ]  # fmt: skip
        fixed = self._fixed_pairs_clear(scene, ka, kb, pair_known, self_look + SAFETY_M)
        return PartMap(
            np.array(pl, dtype=np.int64),
            np.array(pe, dtype=np.int64),
            np.array(pt, dtype=float),
            np.array(pn, dtype=float),
            np.array(pk, dtype=bool),
            np.array(pi, dtype=np.int64),
            np.array([max(a, 0) for a in ka], dtype=np.int64),
            np.array([max(b, 0) for b in kb], dtype=np.int64),
            np.array(pair_thr, dtype=float),
            np.array(pair_near, dtype=float),
            np.array(pair_known, dtype=bool),
            fixed,
        )

    def _fixed_pairs_clear(
        self, scene: CellScene, ka: list[int], kb: list[int], known: list[bool], look: float
    ) -> BoolArray:
        """Pairs of links on the same joint (they never move against each other) that Bullet
        finds farther apart than ``look`` (asked once per look distance, at the home pose)."""
        key = round(look, 12)
        if key not in self._fixed:
            n_last = scene.chain.n_joints - 1
            out = np.zeros(len(ka), dtype=bool)
            with scene.saved_state():
                scene.set_joint_positions(scene.home_q)
                for s_, (a, b) in enumerate(zip(ka, kb)):
                    if not known[s_]:
                        continue
                    la, lb_ = self.links[a], self.links[b]
                    ja = n_last if la.joint is None else la.joint
                    jb = n_last if lb_.joint is None else lb_.joint
                    if ja != jb:
                        continue
                    hits = pb.getClosestPoints(
                        la.body, lb_.body, look, linkIndexA=la.link, linkIndexB=lb_.link,
                        physicsClientId=scene.client,
                    )  # fmt: skip
                    out[s_] = not hits
            self._fixed[key] = out
        return self._fixed[key].copy()

    def _known(self, k: int) -> bool:
        b = self.links[k]
        return b.tree is not None and b.T_const is not None

    # ------------------------------------------------------------------ queries
    def link_poses(self, scene: CellScene, q: FloatArray, T_base_flange: FloatArray) -> FloatArray:
        """``T_world_link (M, L, 3, 4)`` of every link for configurations ``q (M, n)`` whose
        flange (where the tool sits) is ``T_base_flange (M, 4, 4)``."""
        M = q.shape[0]
        out = np.zeros((M, len(self.links), 3, 4))
        T_wb = scene.T_world_base
        frames = scene.chain.joint_frames(q) if M else np.zeros((0, 0, 4, 4))
        T_wf = T_wb @ T_base_flange
        for k, b in enumerate(self.links):
            if b.T_const is None:
                continue
            if b.joint is None:
                out[:, k] = (T_wf @ b.T_const)[:, :3]
            elif b.joint < 0:
                out[:, k] = (T_wb @ b.T_const)[:3]
            else:
                out[:, k] = (T_wb @ frames[:, b.joint] @ b.T_const)[:, :3]
        return out

    def states(
        self, parts: PartMap, env: EnvArrays, T_links: FloatArray
    ) -> tuple[NDArray[np.int8], NDArray[np.int8], NDArray[np.int64]]:
        """``(part states (M, P), pair states (M, S), opened (M,))`` for link poses
        ``T_links (M, L, 3, 4)``: 1 the part (pair) reports nothing in Bullet's query; -1 its
        slack is below the margin; 0 not known here; ``opened``: sphere-tree leaves near the
        environment, per candidate (see :func:`planner.cell.broad_kernels.parts_state`)."""
        M = T_links.shape[0]
        trees = self.tree_arrays()
        shapes = self.shape_arrays()
        todo_p = np.broadcast_to(parts.known, (M, parts.known.size)).copy()
        T = np.ascontiguousarray(T_links)
        ps, opened = _parts_state(
            T, todo_p, parts.part_link, parts.part_env, parts.part_thr, parts.part_near,
            *trees, *shapes, *env.arrays, *env.fields, self.exact,
        )  # fmt: skip
        todo_s = np.broadcast_to(parts.pair_known, (M, parts.pair_known.size)).copy()
        todo_s &= ~parts.pair_fixed_clear
        ss = _pairs_state(
            T, todo_s, parts.pair_a, parts.pair_b, parts.pair_thr, parts.pair_near,
            *trees, *shapes, self.exact,
        )  # fmt: skip
        ss[:, parts.pair_fixed_clear] = 1
        return ps, ss, opened


def broad_phase_of(scene: CellScene) -> BroadPhase:
    """The scene's broad phase, built on first use and kept in ``scene.query_cache``."""
    bp = scene.query_cache.get("broad_phase")
    if not isinstance(bp, BroadPhase):
        bp = scene.query_cache["broad_phase"] = BroadPhase.of(scene)
    return bp


def _gjk_shape(sh: LinkShape) -> tuple[int, FloatArray, FloatArray, FloatArray, FloatArray | None]:
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


def _concat_fields(fields: list[tuple[DistanceField, trimesh.Trimesh]]) -> tuple[NDArray, ...]:
    """The fields, bucket grids and triangles of the mesh bodies, concatenated (see
    :mod:`planner.cell.broad_kernels`)."""
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
