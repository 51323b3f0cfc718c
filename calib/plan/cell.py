"""The cell and work-object parts of a plan: poses, robot, tool, fixtures, work object.

Poses are ``{"position_m": [x, y, z], "quat_wxyz": [w, x, y, z]}`` meaning ``T_parent_child``;
file references are paths relative to the plan file or ``builtin:NAME``.
"""

from __future__ import annotations

import math
import re

import msgspec
import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.errors import PlanError
from calib.frames import (
    check_transform,
    make_transform,
    matrix_from_quat_wxyz,
    quat_wxyz_from_matrix,
)
from calib.limits import MAX_FIXTURES
from calib.plan.base import MeshUnits, check_sha256
from calib.structs import Strict, Vec3, check_coordinates, check_length, check_unit
from calib.tolerances import COORDINATE_LIMIT_M


class Pose(Strict, frozen=True, kw_only=True):
    """A rigid transform ``T_parent_child``.

    Attributes:
        position_m: ``(3,)`` origin of the child frame in the parent frame, metres.
        quat_wxyz: ``(4,)`` unit quaternion (w, x, y, z) of the child's rotation in the parent.
    """

    position_m: Vec3 = (0.0, 0.0, 0.0)
    quat_wxyz: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        check_coordinates(self.position_m, "position_m")
        check_unit(self.quat_wxyz, "quat_wxyz")

    def matrix(self) -> NDArray[np.float64]:
        """The 4x4 transform ``T_parent_child``."""
        return make_transform(matrix_from_quat_wxyz(self.quat_wxyz), self.position_m)

    @classmethod
    def from_matrix(cls, T: ArrayLike) -> Pose:
        """The pose of a 4x4 rigid transform (quaternion with ``w >= 0``)."""
        T_arr = check_transform(T, "T")
        q = quat_wxyz_from_matrix(T_arr[:3, :3])
        p = T_arr[:3, 3]
        return cls(
            position_m=(float(p[0]), float(p[1]), float(p[2])),
            quat_wxyz=(float(q[0]), float(q[1]), float(q[2]), float(q[3])),
        )


class RobotSpec(Strict, frozen=True, kw_only=True):
    """The robot: ``urdf`` is a path relative to the plan or ``builtin:irb4400``.

    Attributes:
        urdf: URDF file, xacro file (``.xacro``, expanded when the cell is built) or built-in
            name.
        T_world_base: pose of the robot base in the cell (world) frame.
        base_link: URDF base link (``None``: the URDF's root).
        tip_link: URDF flange link (``None``: ``tool0`` or the single leaf).
        package_path: where ``$(find pkg)`` and ``package://pkg/...`` look for ROS packages:
            folders separated by ``:`` as in ``ROS_PACKAGE_PATH`` (relative ones from the
            plan's folder). Left out (default): ``ROS_PACKAGE_PATH``. Read it through
            :attr:`packages`.
        xacro_args: values of the xacro file's ``<xacro:arg>`` arguments, as strings (as on
            the ``xacro`` command line); only for a ``.xacro`` file. Left out (default): every
            argument takes its default. Read it through :attr:`args`.
    """

    urdf: str = "builtin:irb4400"
    T_world_base: Pose = Pose()
    base_link: str | None = None
    tip_link: str | None = None
    package_path: str | msgspec.UnsetType = msgspec.UNSET
    xacro_args: dict[str, str] | msgspec.UnsetType = msgspec.UNSET

    def __post_init__(self) -> None:
        path = self.packages
        if path is not None and (len(path) > 4096 or path.count(":") >= 64):
            raise PlanError(
                "package_path: at most 64 folders and 4,096 characters (a workspace names a "
                f"few), got {path.count(':') + 1:,} folders, {len(path):,} characters"
            )
        args = self.args
        if not args:
            return
        if not self.urdf.lower().endswith(".xacro"):
            raise PlanError(f"xacro_args: given, but urdf {self.urdf!r} is not a .xacro file")
        if len(args) > 64:
            raise PlanError(f"xacro_args: {len(args):,} arguments, at most 64")
        for name, value in args.items():
            if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]{0,63}", name):
                raise PlanError(
                    f"xacro_args: {name!r} is not an argument name (letters, digits and _, "
                    "not starting with a digit, at most 64)"
                )
            if len(value) > 4096:
                raise PlanError(f"xacro_args.{name}: {len(value):,} characters, at most 4,096")

    @property
    def packages(self) -> str | None:
        """``package_path`` when the plan sets it, else ``None`` (``ROS_PACKAGE_PATH``)."""
        return self.package_path if isinstance(self.package_path, str) else None

    @property
    def args(self) -> dict[str, str]:
        """``xacro_args`` when the plan sets them, else ``{}`` (every default)."""
        return self.xacro_args if isinstance(self.xacro_args, dict) else {}


class ToolSpec(Strict, frozen=True, kw_only=True):
    """The robot-held tool.

    Attributes:
        name: a tool URDF or description path, or ``builtin:cable_feeder``.
        tcp: the probing TCP (the proximity sensor at its sensing distance).
        T_flange_tool: the tool's mount: its root frame (+z out of the flange) in the robot's
            tip-link frame (``tool0``). Left out (default): along the last joint's axis,
            whichever axis of the tip frame that is (some vendor URDFs have x out of the
            flange); give it when the cell cannot tell (it says so, naming this field), or to
            add an adapter plate. Read it through :attr:`mount`.
    """

    name: str = "builtin:cable_feeder"
    tcp: str = "sensor"
    T_flange_tool: Pose | msgspec.UnsetType = msgspec.UNSET

    @property
    def mount(self) -> Pose | None:
        """``T_flange_tool`` when the plan sets it, else ``None`` (found from the robot)."""
        return self.T_flange_tool if isinstance(self.T_flange_tool, Pose) else None


class FixtureSpec(Strict, frozen=True, kw_only=True):
    """A fixed obstacle (table, fixture) for collision checks: a mesh, a box or a cylinder.

    Attributes:
        name: unique fixture name.
        mesh: mesh file (relative to the plan) or ``builtin:NAME``; ``None`` for a box or a
            cylinder.
        box_size_m: ``(3,)`` edge lengths of a box centred on its frame, m; ``None`` for a mesh
            or a cylinder.
        units: length unit of the mesh file.
        sha256: hex digest of the mesh file, checked on load (``None``: not checked).
        T_world_fixture: pose of the mesh (or box or cylinder centre) frame in the world frame.
        cylinder_m: ``(radius, length)`` of a cylinder about its frame's z axis, centred on its
            frame, m. Left out (default) for a mesh or a box, so plans written before it keep
            their bytes and digest. Read it through :attr:`cylinder`.
    """

    name: str
    mesh: str | None = None
    box_size_m: Vec3 | None = None
    units: MeshUnits = "m"
    sha256: str | None = None
    T_world_fixture: Pose = Pose()
    cylinder_m: tuple[float, float] | msgspec.UnsetType = msgspec.UNSET

    def __post_init__(self) -> None:
        given = [self.mesh is not None, self.box_size_m is not None, self.cylinder is not None]
        if sum(given) != 1:
            raise PlanError("mesh: give exactly one of mesh, box_size_m and cylinder_m")
        if self.mesh is not None:
            check_sha256(self.sha256, self.mesh, "sha256")
            return
        if self.box_size_m is not None:
            _check_lengths(self.box_size_m, "box_size_m", "3 lengths")
        if self.cylinder is not None:
            _check_lengths(self.cylinder, "cylinder_m", "(radius, length)")
        if self.sha256 is not None:
            raise PlanError(f"sha256: must be null for a {self.shape}")

    @property
    def cylinder(self) -> tuple[float, float] | None:
        """``(radius, length)``, m, when the fixture is a cylinder, else ``None``."""
        return None if isinstance(self.cylinder_m, msgspec.UnsetType) else self.cylinder_m

    @property
    def shape(self) -> str:
        """``"mesh"``, ``"box"`` or ``"cylinder"``."""
        if self.mesh is not None:
            return "mesh"
        return "box" if self.box_size_m is not None else "cylinder"


def _check_lengths(values: tuple[float, ...], field: str, what: str) -> None:
    """Raise :class:`PlanError` unless every value is a length > 0 and at most the coordinate
    limit, m."""
    if not all(math.isfinite(v) and 0 < v <= COORDINATE_LIMIT_M for v in values):
        raise PlanError(
            f"{field}: must be {what} > 0 and <= {COORDINATE_LIMIT_M:g} m, got {list(values)}"
        )


class CellSpec(Strict, frozen=True, kw_only=True):
    """Robot, tool and fixtures of the cell."""

    robot: RobotSpec = RobotSpec()
    tool: ToolSpec = ToolSpec()
    fixtures: list[FixtureSpec] = []  # noqa: RUF012 (msgspec copies empty defaults)

    def __post_init__(self) -> None:
        check_length(
            self.fixtures,
            "fixtures",
            MAX_FIXTURES,
            "fixtures",
            "a cell has a handful (table, clamps, pallet), each a body of the cell",
        )


class WorkObjectSpec(Strict, frozen=True, kw_only=True):
    """The work object: its mesh, the mesh unit, the file digest and its nominal pose.

    Attributes:
        mesh: mesh file (relative to the plan) or ``builtin:stator_section``.
        units: length unit of the mesh file (``auto`` lets the loader guess; a CAD file
            declares its own, and ``units`` must be ``auto`` or that unit).
        sha256: hex digest of the mesh file; a mismatch on load is an error naming the file.
        T_world_wobj: nominal pose of the work-object frame (WOCS) in the world frame.
        T_wobj_mesh: the mesh file's frame in the work-object frame (metres, after ``units``),
            e.g. from a 3-point user frame taught on the part. Left out (default): identity,
            the work-object frame is the file's. Read it through :meth:`mesh_matrix`.
        body: for a CAD file (STEP/IGES) of several bodies, the one that is the work object:
            its name, its 0-based index, or ``"all"`` (the bodies as one rigid part). Left out
            (default): the file must hold one body. Read it through :attr:`body_choice`.
    """

    mesh: str = "builtin:stator_section"
    units: MeshUnits = "m"
    sha256: str | None = None
    T_world_wobj: Pose = Pose()
    T_wobj_mesh: Pose | msgspec.UnsetType = msgspec.UNSET
    body: str | int | msgspec.UnsetType = msgspec.UNSET

    def __post_init__(self) -> None:
        check_sha256(self.sha256, self.mesh, "sha256")
        body = self.body_choice
        if isinstance(body, int) and body < 0:
            raise PlanError(f"body: an index counts from 0, got {body}")
        if isinstance(body, str) and not 0 < len(body) <= 200:
            raise PlanError(f"body: a name of 1 to 200 characters, got {len(body)}")

    @property
    def body_choice(self) -> str | int | None:
        """``body`` when the plan sets it, else ``None`` (the file must hold one body)."""
        return None if isinstance(self.body, msgspec.UnsetType) else self.body

    @property
    def mesh_pose(self) -> Pose | None:
        """``T_wobj_mesh`` when the plan sets it, else ``None`` (the identity)."""
        return self.T_wobj_mesh if isinstance(self.T_wobj_mesh, Pose) else None

    def mesh_matrix(self) -> NDArray[np.float64]:
        """``(4, 4)`` ``T_wobj_mesh``: the mesh file's frame in the work-object frame."""
        pose = self.mesh_pose
        return np.eye(4) if pose is None else pose.matrix()
