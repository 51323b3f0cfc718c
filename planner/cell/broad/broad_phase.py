"""Broad phase of the clearance query: which parts surely report nothing, for many candidates.

A clearance query (:meth:`planner.cell.scene.collision.CollisionChecker.plan`) is made of parts: a
robot or tool link against an environment body, looking ``dist_m`` far, and the self part,
whose link pairs look as far. Bullet reports a part only when it finds a point nearer than the
look distance. The broad phase shows, for whole batches of candidates, that a part (or a self
pair) cannot report anything: every sphere of the link's sphere tree
(:mod:`planner.cell.broad.sphere_tree`) lies at least ``dist_m + margin`` from a lower bound of the
distance to the body (exact for boxes, cylinders and spheres; a distance field for meshes,
:mod:`planner.cell.broad.distance_field`), where ``margin`` is a safety
(:mod:`planner.cell.broad.broad_parts`) plus Bullet's inflation
of each side (1 mm for a convex hull or a concave triangle mesh, 0 for boxes and cylinders,
which Bullet shrinks and rounds; see :mod:`planner.cell.broad.link_geometry`). Such a part's result
is ``None`` in the exact query; the others go to Bullet (:mod:`planner.cell.probe.probe_clearance`),
so the answer is the exact query's.

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
from planner.cell.broad.broad_arrays import (
    BroadLink,
    EnvArrays,
    PartMap,
    concat_fields,
    shape_arrays,
    tree_arrays,
)
from planner.cell.broad.broad_parts import build_part_map
from planner.cell.broad.distance_field import DistanceField, distance_field
from planner.cell.broad.link_geometry import (
    BULLET_MESH_MARGIN_M,
    BULLET_ROUNDING_M,
    bullet_excess,
    link_shapes,
)
from planner.cell.broad.sphere_tree import link_tree
from planner.cell.kernels import broad_kernels as kernels
from planner.cell.scene import world_link_pose

if TYPE_CHECKING:
    from planner.cell.scene import CellScene, QueryPlan

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

# numba dispatchers take any arguments (their stubs say otherwise)
_parts_state: Any = kernels.parts_state
_pairs_state: Any = kernels.pairs_state


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
                # the tool's links in the flange frame, through the tool's mount on the flange
                T_root_link = invert_transform(T_world_root) @ world_link_pose(c, tool, i)
                T_flange_link = scene.T_flange_tool @ T_root_link
                links.append(
                    BroadLink(
                        tool.body_id, i, scene.checker.names(tool.body_id, i), shapes,
                        link_tree(shapes),
                        max((s.inflation_m for s in shapes), default=0.0),
                        max((bullet_excess(s) for s in shapes), default=0.0), None, T_flange_link,
                    )
                )  # fmt: skip
        bp = cls(links)
        bp._by_body_link = {(b.body, b.link): k for k, b in enumerate(links)}
        return bp

    # ------------------------------------------------------------------ arrays
    def tree_arrays(self) -> tuple[NDArray, ...]:
        """The links' sphere trees in the kernels' layout (:func:`~planner.cell.broad.broad_arrays.
        tree_arrays`), built once."""
        if self._tree_arrays is None:
            self._tree_arrays = tree_arrays(self.links)
        return self._tree_arrays

    def shape_arrays(self) -> tuple[NDArray, ...]:
        """The links' shapes in the GJK layout (:func:`~planner.cell.broad.broad_arrays.
        shape_arrays`), built once."""
        if self._shape_arrays is None:
            self._shape_arrays = shape_arrays(self.links)
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
            self._fields_cat = concat_fields(fields)
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
            self._part_map = build_part_map(scene, self.links, plan, env, self._fixed)
            self._part_map_key = key
        assert self._part_map is not None
        return self._part_map

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
        environment, per candidate (see :func:`planner.cell.kernels.broad_kernels.parts_state`)."""
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
