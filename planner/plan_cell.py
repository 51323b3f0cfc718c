"""Turn a plan into live objects: nominal frames, resolved files, the cell and the tool data.

The cell (PyBullet) is opened only by :func:`open_cell`, which imports it there: the command
line imports this module, and ``wobjcal --help`` must not load PyBullet. The calibration from
measured points is in :mod:`planner.calibrate.job`.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec
import numpy as np
from numpy.typing import NDArray

from calib.frames import invert_transform
from calib.limits import MAX_CELL_TRIANGLES
from calib.plan.file import Plan, resolve_ref

if TYPE_CHECKING:
    from planner.cell.cell import Cell
    from planner.cell.scene import WorkObject
    from planner.robot.controller_base import ControllerBase

FloatArray = NDArray[np.float64]


def T_base_world(plan: Plan) -> FloatArray:
    """``(4, 4)`` the world frame in the robot base frame: ``inv(T_world_base)``."""
    return invert_transform(plan.cell.robot.T_world_base.matrix())


def nominal_T_base_wobj(plan: Plan) -> FloatArray:
    """``(4, 4)`` the nominal work object in the robot base frame."""
    return T_base_world(plan) @ plan.work_object.T_world_wobj.matrix()


#: The cell of a plan file without a ``cell`` section: msgspec fills a missing field with this
#: very object (``tests/test_messages.py`` holds it to that), so ``plan.cell is _DEFAULT_CELL``
#: tells a missing section from one given, even one that spells the defaults out.
_DEFAULT_CELL = next(f.default for f in msgspec.structs.fields(Plan) if f.name == "cell")


def default_cell_note(plan: Plan) -> str:
    """One line when the plan file has no ``cell`` section (``""`` otherwise): the commands say
    which robot, tool and fixtures they take instead of taking them silently."""
    if plan.cell is not _DEFAULT_CELL:
        return ""
    robot, tool = plan.cell.robot, plan.cell.tool
    return (
        "plan has no cell section: using the built-in robot "
        f"{robot.urdf.removeprefix('builtin:')} with its base at the world origin, the built-in "
        f"tool {tool.name.removeprefix('builtin:')} (TCP {tool.tcp!r}) and no fixtures; give "
        "the cell (cell.robot, cell.tool, cell.fixtures) to check the real one"
    )


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


def plan_robot_urdf(plan: Plan, plan_dir: Path) -> Path:
    """The URDF file of the plan's robot that the cell and the kinematics read.

    A built-in's bundled URDF; a ``.urdf`` as it is, or, when a ROS package path is set
    (``cell.robot.package_path``, else ``ROS_PACKAGE_PATH``), prepared with its
    ``package://`` meshes found there; a ``.xacro`` expanded with ``cell.robot.xacro_args``
    (:func:`planner.robot.description.robot_description`).

    Raises:
        URDFError: the robot file cannot be read, expanded or resolved (the message names it,
            and the package path searched when a package is missing).
    """
    from planner.builtins import is_builtin, robot_urdf
    from planner.robot.description import robot_description
    from planner.robot.ros_packages import package_path

    spec = plan.cell.robot
    if is_builtin(spec.urdf):
        return Path(robot_urdf(spec.urdf))
    source = Path(resolve_ref(spec.urdf, plan_dir))
    return robot_description(source, package_path(spec.packages, plan_dir), spec.args)


def plan_work_object(plan: Plan, plan_dir: Path, reach_m: float | None = None) -> WorkObject:
    """The plan's work object in the work-object frame, metres: the one place every job (check,
    validate, suggest, export, the UI) loads the part.

    The mesh file (or built-in) is loaded in its ``units`` (a CAD file: the unit it
    declares, and the plan's ``body``) and lightly repaired
    (:func:`planner.cell.scene.load_work_object`), then put at
    ``work_object.T_wobj_mesh`` (identity when the plan leaves it out).

    Args:
        plan: the plan.
        plan_dir: the folder relative references resolve against.
        reach_m: the robot's reach, m, for ``units: auto`` (default: the loader's).

    Raises:
        MeshError: the mesh cannot be loaded (the message names the file).
    """
    from planner.cell.scene import WorkObject, load_work_object

    wo = plan.work_object
    loaded = load_work_object(
        resolve_ref(wo.mesh, plan_dir), units=wo.units, reach_m=reach_m, body=wo.body_choice
    )
    if wo.mesh_pose is None:
        return loaded
    mesh = loaded.mesh.copy()
    mesh.apply_transform(wo.mesh_matrix())
    return WorkObject(name=loaded.name, mesh=mesh, report=loaded.report)


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
    mount = plan.cell.tool.mount
    cell = Cell(
        robot=str(plan_robot_urdf(plan, plan_dir)),
        tool=str(refs["tool"]),
        T_world_base=robot.T_world_base.matrix(),
        base_link=robot.base_link,
        tip_link=robot.tip_link,
        T_flange_tool=None if mount is None else mount.matrix(),
    )
    try:
        wobj = plan_work_object(plan, plan_dir, reach_m=cell.reach_model.reach_m)
        cell.set_work_object(wobj, T_world_wobj=plan.work_object.T_world_wobj.matrix())
        left = MAX_CELL_TRIANGLES - len(wobj.mesh.faces)  # the cell's meshes share one budget
        for f in plan.cell.fixtures:
            T = f.T_world_fixture.matrix()
            cylinder = f.cylinder
            if f.box_size_m is not None:
                cell.add_fixture(f.name, size_m=f.box_size_m, T_world_fixture=T)
            elif cylinder is not None:
                radius, length = cylinder
                cell.add_fixture(f.name, radius_m=radius, height_m=length, T_world_fixture=T)
            else:
                mesh = resolve_ref(f.mesh or "", plan_dir)
                fixture = cell.add_fixture(
                    f.name, mesh=str(mesh), units=f.units, T_world_fixture=T, max_triangles=left
                )
                left -= 0 if fixture.mesh is None else len(fixture.mesh.faces)
    except BaseException:
        cell.close()
        raise
    return cell


def plan_controller_base(plan: Plan, plan_dir: Path) -> ControllerBase:
    """The robot controller's base frame for the plan's robot
    (:func:`planner.robot.controller_base.controller_base`): the frame the exported programs, the
    lines to paste and the controllers' results measure from.

    Raises:
        URDFError: the robot file cannot be read (named in the message).
    """
    from planner.robot.controller_base import controller_base
    from planner.robot.urdf import load_urdf

    model = load_urdf(plan_robot_urdf(plan, plan_dir), check_meshes=False)
    return controller_base(model, plan.cell.robot.base_link)


def controller_T_flange_tool(plan: Plan, plan_dir: Path) -> FloatArray:
    """``(4, 4)`` the tool's root frame in the robot controller's flange frame, m.

    Controllers put the flange's +z out of the flange; the tool's mount
    (:func:`planner.cell.scene.tool_mount`) turns the URDF's tip frame that way. The controller's
    flange is the tip frame turned by the mount's rotation, so what is left is the mount's
    offset (an adapter plate): ``[I, R_m^T t_m]`` (identity for a mount found from the axis).

    Raises:
        ToolMountError: the mount cannot be worked out (names ``cell.tool.T_flange_tool``).
    """
    from planner.cell.scene import tool_mount
    from planner.robot.kinematics.chain import KinematicChain

    urdf = plan_robot_urdf(plan, plan_dir)
    chain = KinematicChain.from_urdf(urdf, plan.cell.robot.base_link, plan.cell.robot.tip_link)
    given = plan.cell.tool.mount
    mount = tool_mount(chain, None if given is None else given.matrix())
    offset = np.eye(4)
    offset[:3, 3] = mount[:3, :3].T @ mount[:3, 3]
    return offset


def tool_data(plan: Plan, plan_dir: Path) -> tuple[Any, str]:
    """The sensor tool for exports: TCP, mass and centre of gravity (from the tool's URDF) in
    the controller's flange frame (:func:`controller_T_flange_tool`).

    Returns:
        A :class:`planner.export.job.ToolData` and a note (``""``, or what was estimated).
    """
    from planner.cell.scene import load_tool
    from planner.export.job import ToolData
    from planner.robot.urdf import load_urdf

    tool = load_tool(str(resolved_refs(plan, plan_dir)["tool"]))
    offset = controller_T_flange_tool(plan, plan_dir)
    T_flange_tcp = offset @ tool.T_flange_tcp(plan.cell.tool.tcp)
    mass, cog = 0.0, (0.0, 0.0, 0.1)  # a mesh tool, or a URDF without masses: placeholders
    if tool.urdf_path is not None:
        kg, com = load_urdf(tool.urdf_path, check_meshes=False).mass_and_com()
        if kg > 0.0:
            c = np.asarray(com, dtype=np.float64) + offset[:3, 3]
            mass, cog = kg, (float(c[0]), float(c[1]), float(c[2]))
    note = ""
    if mass < 1.0:
        note = (
            f"tool URDF mass {mass:.2f} kg is a placeholder: the programs use 5 kg; identify "
            "the real load on the robot"
        )
        mass = 5.0
    return ToolData(T_flange_tcp=T_flange_tcp, mass_kg=mass, cog_m=cog), note


__all__ = [
    "T_base_world",
    "default_cell_note",
    "nominal_T_base_wobj",
    "open_cell",
    "plan_controller_base",
    "plan_robot_urdf",
    "plan_work_object",
    "resolved_refs",
    "tool_data",
]
