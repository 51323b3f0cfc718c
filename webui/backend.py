"""The UI's only door into ``planner``: build the cell of a plan and check points in it.

A :class:`CellSession` lives on the :class:`webui.worker.CellWorker` thread and owns the
PyBullet cell (built by :func:`planner.plan_cell.open_cell`, as ``wobjcal check`` builds it).
"""

from __future__ import annotations

import dataclasses
import logging
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray

from calib.frames import invert_transform
from calib.plan.file import Plan, resolve_ref
from calib.probing import ProbePoint, SearchCommand
from planner.builtins import robot_urdf
from planner.cell.workobject import load_work_object
from planner.plan_cell import open_cell
from webui.status import PointCheck

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
    """

    robot_urdf: Path | None
    T_world_base: NDArray[np.float64]
    wobj_mesh: trimesh.Trimesh
    T_world_wobj: NDArray[np.float64]
    fixtures: dict[str, tuple[trimesh.Trimesh, NDArray[np.float64]]] = field(default_factory=dict)
    tool_urdf: Path | None = None
    tool_mesh: trimesh.Trimesh | None = None
    chain: Any = None

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


def resolve_robot_urdf(ref: str, plan_dir: Path) -> Path | None:
    """The URDF file of ``plan.cell.robot.urdf`` (``builtin:NAME`` from the bundled assets)."""
    resolved = resolve_ref(ref, plan_dir)
    if isinstance(resolved, Path):
        return resolved if resolved.is_file() else None
    return Path(robot_urdf(ref))


def load_mesh(ref: str, units: str, plan_dir: Path) -> trimesh.Trimesh:
    """A work-object or fixture mesh in metres, loaded and repaired by ``planner.cell.workobject``.

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
        self.view = CellView(
            robot_urdf=resolve_robot_urdf(plan.cell.robot.urdf, self.plan_dir),
            T_world_base=plan.cell.robot.T_world_base.matrix(),
            wobj_mesh=load_mesh(plan.work_object.mesh, plan.work_object.units, self.plan_dir),
            T_world_wobj=plan.work_object.T_world_wobj.matrix(),
            fixtures=self._fixture_meshes(),
        )
        self.cell: Any = open_cell(plan, self.plan_dir)
        tool = self.cell.tool
        self.view = dataclasses.replace(
            self.view,
            tool_urdf=getattr(tool, "urdf_path", None),
            tool_mesh=getattr(tool, "mesh", None),
            chain=self.cell.chain,
        )

    def _fixture_meshes(self) -> dict[str, tuple[trimesh.Trimesh, NDArray[np.float64]]]:
        out = {}
        for f in self.plan.cell.fixtures:
            if f.box_size_m is not None:
                mesh = trimesh.creation.box(extents=f.box_size_m)
            else:
                mesh = load_mesh(f.mesh or "", f.units, self.plan_dir)
            out[f.name] = (mesh, f.T_world_fixture.matrix())
        return out

    def check_points(self, points: list[ProbePoint]) -> list[PointCheck]:
        """Check the probe poses and search paths of ``points`` (wobj frame) in the cell."""
        if not points:
            return []
        t0 = time.perf_counter()
        P = np.array([p.position_m for p in points], dtype=np.float64)
        N = np.array([p.normal for p in points], dtype=np.float64)
        results = self.cell.check_probes(P, N, tcp=self.plan.cell.tool.tcp)
        checks = [self._combine(p, r, t0) for p, r in zip(points, results, strict=True)]
        return _with_planar_faces(self.view.wobj_mesh, points, checks)

    def _combine(self, point: ProbePoint, res: Any, t0: float) -> PointCheck:
        status, reason = str(res.status), str(res.reason or "")
        q = None if res.q is None else np.asarray(res.q, dtype=np.float64)
        q_path = None
        if status != "infeasible":
            cmd = SearchCommand.from_point(point, self.view.T_base_wobj)
            path = self.cell.check_search(cmd, q_ref=q)
            q_path = None if path.q_path is None else np.asarray(path.q_path, dtype=np.float64)
            if not path.feasible:
                status = "infeasible"
                reason = f"search path: {path.reason}"
        return PointCheck(
            point_id=point.id,
            status=status,  # type: ignore[arg-type]
            reason=reason,
            q=q,
            q_path=q_path,
            clearance_m=float(getattr(res, "clearance_m", float("nan"))),
            elapsed_s=time.perf_counter() - t0,
        )

    def close(self) -> None:
        """Release the PyBullet client."""
        if self.cell is not None:
            self.cell.close()
        self.cell = None


def _with_planar_faces(
    mesh: trimesh.Trimesh, points: list[ProbePoint], checks: list[PointCheck]
) -> list[PointCheck]:
    """Mark points off a planar face (or with the footprint over a hole/edge) infeasible."""
    from planner.faces.checks import plan_face_reasons

    reasons = plan_face_reasons(mesh, points, raise_if_none=False)
    return [
        c if not why else dataclasses.replace(c, status="infeasible", reason=why)
        for c, why in zip(checks, reasons, strict=True)
    ]
