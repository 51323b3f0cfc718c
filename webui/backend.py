"""The UI's only door into ``planner``: build the cell of a plan and check points in it.

A :class:`CellSession` lives on the :class:`webui.worker.CellWorker` thread and owns the
PyBullet cell (built by :func:`planner.plan_cell.open_cell`, as ``wobjcal check`` builds it).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray

from calib.errors import InputError
from calib.frames import invert_transform
from calib.plan.file import Plan, PlanPoint, resolve_ref
from planner.cell.cell import Cell
from planner.cell.moves import MoveCheck, ViaPath, check_joint_move, check_via_path
from planner.cell.scene import RayHit, first_hit, load_work_object
from planner.check.cycle import plan_cycle_time
from planner.check.job import PointCheck, check_points, check_via_moves
from planner.plan_cell import open_cell, plan_robot_urdf
from planner.program.cycle_time import CycleTime
from planner.robot.kinematics.chain import KinematicChain

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class CellView:
    """What the scene draws and picks on, in plain geometry.

    Attributes:
        robot_urdf: the robot URDF file, or ``None`` when it cannot be found.
        T_world_base: ``(4, 4)`` robot base in the world frame.
        wobj_mesh: the work object in its own (wobj) frame, metres.
        T_world_wobj: ``(4, 4)`` nominal work-object frame in the world frame.
        fixtures: ``{name: (mesh, T_world_fixture)}`` fixed obstacles.
        tool_urdf: the tool URDF (root = flange frame), or ``None``.
        tool_mesh: the tool mesh in the flange frame (mesh tools), or ``None``.
        chain: the robot's kinematic chain (pure numpy ``fk``), or ``None`` without a cell.
        T_flange_tool: ``(4, 4)`` the tool's mount on the flange (the cell's).
    """

    robot_urdf: Path | None
    T_world_base: NDArray[np.float64]
    wobj_mesh: trimesh.Trimesh
    T_world_wobj: NDArray[np.float64]
    fixtures: dict[str, tuple[trimesh.Trimesh, NDArray[np.float64]]] = field(default_factory=dict)
    tool_urdf: Path | None = None
    tool_mesh: trimesh.Trimesh | None = None
    chain: KinematicChain | None = None
    T_flange_tool: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))

    def T_world_flange(self, q: ArrayLike) -> NDArray[np.float64] | None:
        """``(4, 4)`` flange pose in the world at joint values ``q`` (``None``: no chain)."""
        if self.chain is None:
            return None
        q_arr = np.asarray(q, dtype=np.float64).reshape(1, -1)
        return self.T_world_base @ np.asarray(self.chain.fk(q_arr), dtype=np.float64)[0]

    @property
    def T_base_wobj(self) -> NDArray[np.float64]:
        """``(4, 4)`` nominal work object in the robot base frame."""
        return invert_transform(self.T_world_base) @ self.T_world_wobj


@dataclass(frozen=True)
class JogStatus:
    """The robot at jogged joint values: limits and clearance.

    Attributes:
        q: ``(n,)`` the joint values, rad.
        outside: joints beyond their limits (by URDF name).
        near: joints within 0.05 rad of a limit.
        clear: the robot (at ``q`` clipped into the limits) keeps its clearance everywhere.
        clearance: the limiting pair in words, e.g. ``"link_4 hits table (clearance -3.0 mm)"``.
    """

    q: NDArray[np.float64]
    outside: tuple[str, ...]
    near: tuple[str, ...]
    clear: bool
    clearance: str

    @property
    def status(self) -> str:
        """``infeasible`` (beyond a limit or colliding), ``marginal`` (near a limit) or
        ``feasible``."""
        if self.outside or not self.clear:
            return "infeasible"
        return "marginal" if self.near else "feasible"

    def describe(self) -> str:
        """One line for the panel."""
        parts = []
        if self.outside:
            parts.append(f"beyond the limits: {', '.join(self.outside)}")
        if self.near:
            parts.append(f"near a limit: {', '.join(self.near)}")
        parts.append(self.clearance)
        return "; ".join(parts)


def load_mesh(ref: str, units: str, plan_dir: Path) -> trimesh.Trimesh:
    """A work-object or fixture mesh in metres, loaded and repaired by
    ``planner.cell.scene.workobject``.

    Raises:
        MeshError: the file is missing, unreadable or empty, or its units are unknown.
    """
    resolved = resolve_ref(ref, plan_dir)
    return load_work_object(resolved, units=units).mesh


class CellSession:
    """The plan's cell: geometry to draw, and the PyBullet cell for checks (worker thread only).

    Args:
        plan: the plan whose cell to build.
        plan_dir: folder that relative file references of the plan are resolved against.
    """

    def __init__(self, plan: Plan, plan_dir: Path) -> None:
        self.plan = plan
        self.plan_dir = Path(plan_dir)
        cell = open_cell(plan, self.plan_dir)
        self.cell: Cell | None = cell
        if cell.work_object is None:  # open_cell always loads the plan's work object
            raise RuntimeError("the plan's cell has no work object")
        self.view = CellView(
            robot_urdf=plan_robot_urdf(plan, self.plan_dir),
            T_world_base=plan.cell.robot.T_world_base.matrix(),
            wobj_mesh=cell.work_object.mesh,
            T_world_wobj=plan.work_object.T_world_wobj.matrix(),
            fixtures=self._fixture_meshes(),
            tool_urdf=None if cell.tool is None else cell.tool.urdf_path,
            tool_mesh=None if cell.tool is None else cell.tool.mesh,
            chain=cell.chain,
            T_flange_tool=cell.T_flange_tool,
        )

    def _fixture_meshes(self) -> dict[str, tuple[trimesh.Trimesh, NDArray[np.float64]]]:
        out = {}
        for f in self.plan.cell.fixtures:
            if f.box_size_m is not None:
                mesh = trimesh.creation.box(extents=f.box_size_m)
            elif (cylinder := f.cylinder) is not None:  # about z, centred: as the cell's
                mesh = trimesh.creation.cylinder(radius=cylinder[0], height=cylinder[1])
            else:
                mesh = load_mesh(f.mesh or "", f.units, self.plan_dir)
            out[f.name] = (mesh, f.T_world_fixture.matrix())
        return out

    def check_points(self, points: list[PlanPoint], plan: Plan | None = None) -> list[PointCheck]:
        """Check the probe poses, search paths and planar faces of ``points`` (the session
        plan's, possibly edited) in the cell: :func:`planner.check.job.check_points`, the check
        ``wobjcal check`` runs. ``plan``: the plan as edited now (its points set the safe
        starts' pivot; default the session's)."""
        if not points or self.cell is None:
            return []
        return list(check_points(self.cell, plan or self.plan, points))

    def cycle_time(self, plan: Plan, checks: list[PointCheck]) -> CycleTime | None:
        """The estimated cycle time of ``plan``'s program (the default controller's) from the
        poses of ``checks``: :func:`planner.check.cycle.plan_cycle_time`, what ``wobjcal check``
        prints; ``None`` without a cell or a program."""
        if self.cell is None:
            return None
        try:
            return plan_cycle_time(plan, checks, self.cell)
        except InputError:  # not a refusal to tell anyone: no program yet means no cycle time
            return None  # (the status table shows why the points or the plan fall short)

    def via_moves(self, plan: Plan, checks: list[PointCheck]) -> tuple[PointCheck, ...]:
        """``checks`` (of all of ``plan``'s points, in plan order) with the moves between the
        points checked: :func:`planner.check.job.check_via_moves`, as ``wobjcal check`` and
        the export check them (unchanged without a cell)."""
        if self.cell is None:
            return tuple(checks)
        return check_via_moves(self.cell, plan, checks)

    # ---- jogging ---------------------------------------------------------------------------
    def T_world_tcp(self, q: ArrayLike, tcp: str) -> NDArray[np.float64]:
        """``(4, 4)`` the TCP ``tcp`` in the world at joint values ``q`` (rad)."""
        cell = self._cell()
        qa = np.asarray(q, dtype=np.float64).reshape(1, -1)
        T_base_flange = np.asarray(cell.chain.fk(qa), dtype=np.float64)[0]
        return cell.T_world_base @ T_base_flange @ cell.T_flange_tcp(tcp)

    def jog_status(self, q: ArrayLike, near_limit_rad: float = 0.05) -> JogStatus:
        """Joint limits and clearance of the robot at ``q`` (the cell's own state is kept)."""
        cell = self._cell()
        qa = np.asarray(q, dtype=np.float64).reshape(-1)
        names = cell.chain.joint_names
        lo, hi = cell.chain.lower, cell.chain.upper
        outside = [names[i] for i in range(len(qa)) if not lo[i] - 1e-9 <= qa[i] <= hi[i] + 1e-9]
        near = [
            names[i]
            for i in range(len(qa))
            if min(qa[i] - lo[i], hi[i] - qa[i]) < near_limit_rad and names[i] not in outside
        ]
        with cell.saved_state():
            cell.set_joint_positions(np.clip(qa, lo, hi))
            clearance = cell.clearance()
        return JogStatus(
            q=qa, outside=tuple(outside), near=tuple(near), clear=clearance.ok,
            clearance=clearance.describe(),
        )  # fmt: skip

    def ik_near(
        self, T_world_tcp: ArrayLike, q_now: ArrayLike, tcp: str
    ) -> NDArray[np.float64] | None:
        """The IK solution for the TCP pose ``T_world_tcp`` nearest ``q_now`` (so the arm keeps
        its branch), or ``None`` when the pose cannot be reached within the joint limits."""
        cell = self._cell()
        T_base_flange = (
            invert_transform(cell.T_world_base)
            @ np.asarray(T_world_tcp, dtype=np.float64)
            @ invert_transform(cell.T_flange_tcp(tcp))
        )
        q0 = np.asarray(q_now, dtype=np.float64).reshape(-1)
        sols = cell.solver.solve(T_base_flange[None], seeds=q0[None])
        q = sols.q[0][sols.valid[0]]
        if len(q) == 0:
            return None
        return np.asarray(q[int(np.argmin(np.linalg.norm(q - q0, axis=1)))], dtype=np.float64)

    def check_move(self, q_from: ArrayLike, q_to: ArrayLike, tcp: str) -> MoveCheck:
        """The joint move from ``q_from`` to ``q_to`` (rad): the TCP's path (world) and the
        first pose that collides, if any (:func:`planner.cell.moves.check_joint_move`)."""
        return check_joint_move(self._cell(), q_from, q_to, tcp)

    def check_via_path(
        self,
        q_prev: ArrayLike | None,
        vias_q: list[NDArray[np.float64]],
        q_point: ArrayLike | None,
        tcp: str,
    ) -> ViaPath:
        """The moves from ``q_prev`` through the vias to ``q_point``
        (:func:`planner.cell.moves.check_via_path`, as ``wobjcal check`` runs them)."""
        return check_via_path(self._cell(), q_prev, vias_q, q_point, tcp)

    def first_hit(
        self, origin_world: ArrayLike, direction_world: ArrayLike, q: ArrayLike | None
    ) -> RayHit | None:
        """What the ray (world) meets first in the cell with the robot at ``q`` (rad; ``None``
        or a length that is not the chain's: its current pose): :func:`planner.cell.scene.ray_hit.
        first_hit`."""
        cell = self._cell()
        qa = None if q is None else np.asarray(q, dtype=np.float64).reshape(-1)
        if qa is not None and qa.shape[0] != cell.chain.n_joints:
            qa = None
        return first_hit(cell, origin_world, direction_world, q=qa)

    def _cell(self) -> Cell:
        if self.cell is None:
            raise RuntimeError("the cell is closed")
        return self.cell

    def close(self) -> None:
        """Release the PyBullet client."""
        if self.cell is not None:
            self.cell.close()
        self.cell = None
