"""The UI's only door into ``planner``: build the cell of a plan and check points in it.

A :class:`CellSession` lives on the :class:`webui.worker.CellWorker` thread and owns the
PyBullet cell. Parts of ``planner`` the UI needs may be missing in a given installation (or not
written yet); then the session says so in :attr:`CellSession.cell_error` and every check returns
status ``unknown`` with that message. Nothing is ever faked.
"""

from __future__ import annotations

import importlib
import logging
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import trimesh
from numpy.typing import NDArray

from calib.frames import invert_transform
from calib.plan import Plan, resolve_ref
from calib.probing import ProbePoint, SearchCommand
from planner.errors import MeshError
from webui.status import PointCheck

logger = logging.getLogger(__name__)

REPO_ASSETS = Path(__file__).resolve().parent.parent / "assets"


class NotAvailableError(RuntimeError):
    """A feature needs a part of ``planner`` that is not available; the message says which."""


def optional_import(module: str, what: str) -> Any:
    """Import ``module`` or raise :class:`NotAvailableError` saying ``what`` is unavailable."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise NotAvailableError(f"{what} is not available yet ({module}: {exc})") from None


@dataclass(frozen=True)
class CellView:
    """What the scene draws and picks on, in plain geometry.

    Attributes:
        robot_urdf: the robot URDF file, or ``None`` when it cannot be found.
        T_world_base: ``(4, 4)`` robot base in the world frame.
        wobj_mesh: the work object in its own (wobj) frame, metres.
        T_world_wobj: ``(4, 4)`` nominal work-object frame in the world frame.
        fixtures: ``{name: (mesh, T_world_fixture)}`` fixed obstacles.
    """

    robot_urdf: Path | None
    T_world_base: NDArray[np.float64]
    wobj_mesh: trimesh.Trimesh
    T_world_wobj: NDArray[np.float64]
    fixtures: dict[str, tuple[trimesh.Trimesh, NDArray[np.float64]]] = field(default_factory=dict)

    @property
    def T_base_wobj(self) -> NDArray[np.float64]:
        """``(4, 4)`` nominal work object in the robot base frame."""
        return invert_transform(self.T_world_base) @ self.T_world_wobj


def resolve_robot_urdf(ref: str, plan_dir: Path) -> Path | None:
    """The URDF file of ``plan.cell.robot.urdf`` (``builtin:NAME`` from the bundled assets)."""
    resolved = resolve_ref(ref, plan_dir)
    if isinstance(resolved, Path):
        return resolved if resolved.is_file() else None
    try:
        builtins = importlib.import_module("planner.builtins")
        return Path(builtins.robot_urdf(ref))
    except ImportError:
        name = ref.split(":", 1)[1]
        candidate = REPO_ASSETS / "robots" / name / f"{name}.urdf"
        return candidate if candidate.is_file() else None


_UNIT_SCALE = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254}


def load_mesh(ref: str, units: str, plan_dir: Path) -> trimesh.Trimesh:
    """A work-object or fixture mesh in metres (through ``planner.workobject`` when present).

    Raises:
        MeshError: the file is missing, unreadable or empty, or its units are unknown.
        NotAvailableError: a ``builtin:`` mesh whose module is not available.
    """
    resolved = resolve_ref(ref, plan_dir)
    try:
        workobject = importlib.import_module("planner.workobject")
    except ImportError:
        workobject = None
    if workobject is not None and hasattr(workobject, "load_work_object"):
        loaded = workobject.load_work_object(resolved, units=units)
        return getattr(loaded, "mesh", loaded)
    if isinstance(resolved, str):
        raise NotAvailableError(f"built-in mesh {ref!r} needs planner.workobject (not available)")
    # minimal loader until planner.workobject exists: explicit units only
    if units not in _UNIT_SCALE:
        raise MeshError(f"{resolved}: units {units!r} need planner.workobject; use m, cm, mm, in")
    if not resolved.is_file():
        raise MeshError(f"mesh file not found: {resolved}")
    try:
        mesh = trimesh.load(resolved, force="mesh")
    except Exception as exc:
        raise MeshError(f"{resolved}: cannot read the mesh ({exc})") from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise MeshError(f"{resolved}: the file holds no triangles")
    mesh.apply_scale(_UNIT_SCALE[units])
    return mesh


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
        )
        self.cell: Any = None
        self.cell_error = ""
        try:
            self.cell = self._build_cell()
        except NotAvailableError as exc:
            self.cell_error = str(exc)
            logger.warning("%s", exc)

    def _build_cell(self) -> Any:
        cell_mod = optional_import("planner.cell", "the cell (feasibility checks)")
        plan = self.plan
        cell = cell_mod.Cell(robot=plan.cell.robot.urdf, tool=plan.cell.tool.name)
        cell.set_work_object(self.view.wobj_mesh, units="m", T_world_wobj=self.view.T_world_wobj)
        return cell

    def check_points(self, points: list[ProbePoint]) -> list[PointCheck]:
        """Check the probe poses and search paths of ``points`` (wobj frame) in the cell."""
        if not points:
            return []
        if self.cell is None:
            msg = self.cell_error or "the cell is not available"
            return [PointCheck(p.id, "unknown", msg) for p in points]
        t0 = time.perf_counter()
        P = np.array([p.position_m for p in points], dtype=np.float64)
        N = np.array([p.normal for p in points], dtype=np.float64)
        results = self.cell.check_probes(P, N, tcp=self.plan.cell.tool.tcp)
        out = []
        for point, res in zip(points, results, strict=True):
            out.append(self._combine(point, res, t0))
        return out

    def _combine(self, point: ProbePoint, res: Any, t0: float) -> PointCheck:
        status, reason = str(res.status), str(res.reason or "")
        q = None if res.q is None else np.asarray(res.q, dtype=np.float64)
        q_path = None
        if status != "infeasible":
            cmd = SearchCommand.from_point(point, self.view.T_base_wobj)
            path = self.cell.check_search(cmd)
            q_path = None if path.q_path is None else np.asarray(path.q_path, dtype=np.float64)
            if not path.feasible:
                status = "infeasible"
                at = getattr(path, "fail_at_m", float("nan"))
                where = f" at {at * 1000:.0f} mm" if at is not None and np.isfinite(at) else ""
                reason = f"search path{where}: {path.reason}"
        return PointCheck(
            point_id=point.id,
            status=status,  # type: ignore[arg-type]
            reason=reason,
            q=q,
            q_path=q_path,
            clearance_m=float(getattr(res, "clearance_m", float("nan"))),
            elapsed_s=time.perf_counter() - t0,
        )

    def reachability(self, n_samples: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Surface samples ``(M, 3)`` (wobj frame) and their reachability score in [0, 1]."""
        if self.cell is None or not hasattr(self.cell, "reachability_map"):
            raise NotAvailableError(f"the reachability map is not available: {self.cell_error}")
        rmap = self.cell.reachability_map(n_samples, np.random.default_rng(0))
        points = np.asarray(getattr(rmap, "points_wobj", getattr(rmap, "points", None)), float)
        score = getattr(rmap, "score", None)
        if score is None:
            score = np.asarray(getattr(rmap, "feasible", np.zeros(len(points))), float)
        return points, np.asarray(score, float)

    def close(self) -> None:
        """Release the PyBullet client."""
        if self.cell is not None and hasattr(self.cell, "close"):
            self.cell.close()
        self.cell = None
