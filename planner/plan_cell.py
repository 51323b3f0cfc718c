"""Turn a plan into live objects: nominal frames, resolved files, the cell and the tool data.

The cell (PyBullet) is opened only by :func:`open_cell`, which imports it there: the command
line imports this module, and ``wobjcal --help`` must not load PyBullet. The calibration from
measured points is in :mod:`planner.calibrate`.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from calib.frames import invert_transform
from calib.plan.file import Plan, resolve_ref

if TYPE_CHECKING:
    from planner.cell.cell import Cell

FloatArray = NDArray[np.float64]


def T_base_world(plan: Plan) -> FloatArray:
    """``(4, 4)`` the world frame in the robot base frame: ``inv(T_world_base)``."""
    return invert_transform(plan.cell.robot.T_world_base.matrix())


def nominal_T_base_wobj(plan: Plan) -> FloatArray:
    """``(4, 4)`` the nominal work object in the robot base frame."""
    return T_base_world(plan) @ plan.work_object.T_world_wobj.matrix()


def plan_dir_of(path: str | Path) -> Path:
    """The directory that relative references of the plan at ``path`` resolve against."""
    return Path(path).resolve().parent


def resolved_refs(plan: Plan, plan_dir: Path) -> dict[str, str | Path]:
    """The plan's robot, tool and work-object references resolved against ``plan_dir``."""
    return {
        "robot": resolve_ref(plan.cell.robot.urdf, plan_dir),
        "tool": resolve_ref(plan.cell.tool.name, plan_dir),
        "work_object": resolve_ref(plan.work_object.mesh, plan_dir),
    }


def open_cell(plan: Plan, plan_dir: Path) -> Cell:
    """Build the plan's :class:`planner.cell.cell.Cell` (robot, tool, work object, fixtures).

    Use it as a context manager (``with open_cell(plan, d) as cell:``) so its PyBullet client
    is released.

    Raises:
        InputError: a file of the plan cannot be loaded (named in the message).
    """
    from planner.cell.cell import Cell  # PyBullet: imported when a cell is opened
    refs = resolved_refs(plan, plan_dir)
    robot = plan.cell.robot
    cell = Cell(
        robot=str(refs["robot"]),
        tool=str(refs["tool"]),
        T_world_base=robot.T_world_base.matrix(),
        base_link=robot.base_link,
        tip_link=robot.tip_link,
    )
    try:
        wo = plan.work_object
        cell.set_work_object(
            str(refs["work_object"]), units=wo.units, T_world_wobj=wo.T_world_wobj.matrix()
        )
        for f in plan.cell.fixtures:
            T = f.T_world_fixture.matrix()
            if f.box_size_m is not None:
                cell.add_fixture(f.name, size_m=f.box_size_m, T_world_fixture=T)
            else:
                mesh = resolve_ref(f.mesh or "", plan_dir)
                cell.add_fixture(f.name, mesh=str(mesh), units=f.units, T_world_fixture=T)
    except BaseException:
        cell.close()
        raise
    return cell


def tool_data(plan: Plan, plan_dir: Path) -> tuple[Any, str]:
    """The sensor tool for exports: TCP from the tool, mass and centre of gravity from its URDF.

    Returns:
        A :class:`planner.export.job.ToolData` and a note (``""``, or what was estimated).
    """
    from planner.cell.tool import load_tool
    from planner.export.job import ToolData

    tool = load_tool(str(resolved_refs(plan, plan_dir)["tool"]))
    T_flange_tcp = tool.T_flange_tcp(plan.cell.tool.tcp)
    mass, cog = _urdf_mass(getattr(tool, "urdf_path", None))
    note = ""
    if mass < 1.0:
        note = (
            f"tool URDF mass {mass:.2f} kg is a placeholder: the programs use 5 kg; identify "
            "the real load on the robot"
        )
        mass = 5.0
    return ToolData(T_flange_tcp=T_flange_tcp, mass_kg=mass, cog_m=cog), note


def _urdf_origin(elem: Any) -> FloatArray:
    """``T_parent_child`` of a URDF ``<origin xyz rpy>`` (rpy: fixed-axis roll, pitch, yaw)."""
    from scipy.spatial.transform import Rotation

    from calib.frames import make_transform

    if elem is None:
        return np.eye(4)
    xyz = [float(v) for v in elem.get("xyz", "0 0 0").split()]
    rpy = [float(v) for v in elem.get("rpy", "0 0 0").split()]
    return make_transform(Rotation.from_euler("xyz", rpy).as_matrix(), xyz)


def _urdf_mass(path: Path | None) -> tuple[float, tuple[float, float, float]]:
    """Total mass (kg) and centre of gravity (root = flange frame, m) of a fixed-joint URDF."""
    import xml.etree.ElementTree as ET

    if path is None or not Path(path).is_file():
        return 0.0, (0.0, 0.0, 0.1)
    root = ET.parse(path).getroot()
    parent_of: dict[str, tuple[str, FloatArray]] = {}
    for j in root.findall("joint"):
        parent, child = j.find("parent"), j.find("child")
        if parent is not None and child is not None:
            parent_of[child.get("link", "")] = (
                parent.get("link", ""),
                _urdf_origin(j.find("origin")),
            )

    def pose(link: str) -> FloatArray:
        T = np.eye(4)
        while link in parent_of:
            link, T_parent_child = parent_of[link]
            T = T_parent_child @ T
        return T

    total, moment = 0.0, np.zeros(3)
    for link in root.findall("link"):
        inertial = link.find("inertial")
        m = None if inertial is None else inertial.find("mass")
        if inertial is None or m is None:
            continue
        mass = float(m.get("value", "0"))
        c = pose(link.get("name", "")) @ _urdf_origin(inertial.find("origin"))
        total += mass
        moment += mass * c[:3, 3]
    if total <= 0:
        return 0.0, (0.0, 0.0, 0.1)
    cog = moment / total
    return total, (float(cog[0]), float(cog[1]), float(cog[2]))


__all__ = [
    "T_base_world",
    "nominal_T_base_wobj",
    "open_cell",
    "resolved_refs",
    "tool_data",
]
