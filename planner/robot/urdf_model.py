"""The data model of a parsed URDF: links, joints, shapes, inertials, the validated tree (frozen).

Built by :func:`planner.robot.urdf.parse_urdf` and :func:`planner.robot.urdf.load_urdf` (importable
from :mod:`planner.robot.urdf` as well); callers never see the parser's own objects. Angles follow
URDF: ``rpy`` is roll, pitch, yaw about fixed x, y, z, ``R = Rz(yaw) Ry(pitch) Rx(roll)``; lengths
are metres, masses kilograms.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from planner.errors import URDFError

FloatArray = NDArray[np.float64]

#: Joint types of the URDF specification.
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")


def matrix_from_rpy(rpy: tuple[float, float, float]) -> FloatArray:
    """Rotation ``Rz(yaw) @ Ry(pitch) @ Rx(roll)`` (3, 3) of a URDF ``rpy`` triple (rad)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def transform_from_xyz_rpy(
    xyz: tuple[float, float, float], rpy: tuple[float, float, float]
) -> FloatArray:
    """Homogeneous transform (4, 4) of a URDF ``<origin xyz rpy>`` (m, rad)."""
    T = np.eye(4)
    T[:3, :3] = matrix_from_rpy(rpy)
    T[:3, 3] = xyz
    return T


@dataclass(frozen=True)
class Geometry:
    """One geometry element of a visual or collision shape.

    Attributes:
        kind: ``"box"``, ``"cylinder"``, ``"sphere"`` or ``"mesh"``.
        size: box edge lengths (3,), metres; zeros for other kinds.
        radius: cylinder or sphere radius, metres.
        length: cylinder length along its local z, metres.
        filename: the mesh URI as written in the URDF (``""`` for primitives).
        mesh_path: the resolved mesh file, or ``None`` when not a mesh or not found.
        scale: mesh scale factors (3,).
    """

    kind: str
    size: tuple[float, float, float] = (0.0, 0.0, 0.0)
    radius: float = 0.0
    length: float = 0.0
    filename: str = ""
    mesh_path: Path | None = None
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)


@dataclass(frozen=True)
class Shape:
    """A visual or collision shape of a link.

    Attributes:
        xyz: origin of the shape in the link frame, metres.
        rpy: orientation of the shape in the link frame (URDF roll, pitch, yaw), radians.
        geometry: what the shape is.
        rgba: colour (visuals with a ``<material><color>``), else ``None``.
    """

    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    geometry: Geometry
    rgba: tuple[float, float, float, float] | None = None


@dataclass(frozen=True)
class Inertial:
    """The ``<inertial>`` of a link: mass, centre of mass and inertia about it.

    Attributes:
        mass: kg (``>= 0``).
        xyz: centre of mass in the link frame, metres.
        rpy: orientation of the inertia frame in the link frame, radians.
        inertia: ``(ixx, ixy, ixz, iyy, iyz, izz)`` about the centre of mass in the inertia
            frame, kg m^2.
    """

    mass: float
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    inertia: tuple[float, float, float, float, float, float] = (0.0,) * 6

    @property
    def T_link_com(self) -> FloatArray:
        """The centre-of-mass (inertia) frame in the link frame, (4, 4)."""
        return transform_from_xyz_rpy(self.xyz, self.rpy)

    @property
    def inertia_matrix(self) -> FloatArray:
        """The symmetric inertia tensor (3, 3) in the inertia frame, kg m^2."""
        ixx, ixy, ixz, iyy, iyz, izz = self.inertia
        return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])


@dataclass(frozen=True)
class Link:
    """A URDF link: a name, its shapes and its inertial (all in the link frame)."""

    name: str
    visuals: tuple[Shape, ...] = ()
    collisions: tuple[Shape, ...] = ()
    inertial: Inertial | None = None


@dataclass(frozen=True)
class JointLimit:
    """Joint limits: position in rad (revolute) or m (prismatic), effort, velocity."""

    lower: float
    upper: float
    effort: float = 0.0
    velocity: float = 0.0


@dataclass(frozen=True)
class Joint:
    """A URDF joint.

    Attributes:
        name: joint name.
        type: one of :data:`JOINT_TYPES`.
        parent: parent link name.
        child: child link name.
        xyz: origin of the joint frame in the parent link frame, metres.
        rpy: orientation of the joint frame in the parent link frame, radians.
        axis: unit joint axis (3,) in the joint frame (default x, as in the URDF spec).
        limit: position limits; ``None`` for continuous, fixed, floating and planar joints.
    """

    name: str
    type: str
    parent: str
    child: str
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    axis: tuple[float, float, float] = (1.0, 0.0, 0.0)
    limit: JointLimit | None = None

    @property
    def T_parent_joint(self) -> FloatArray:
        """The joint frame at zero joint value in the parent link frame, (4, 4)."""
        return transform_from_xyz_rpy(self.xyz, self.rpy)

    @property
    def is_moving(self) -> bool:
        """True for revolute, continuous and prismatic joints."""
        return self.type in ("revolute", "continuous", "prismatic")


@dataclass(frozen=True)
class URDFModel:
    """A parsed, validated URDF: one tree of links and joints.

    Attributes:
        name: the robot name.
        path: the URDF file (``None`` when parsed from a string).
        links: the links in file order.
        joints: the joints in file order.
        root: the one link that is no joint's child.
    """

    name: str
    path: Path | None
    links: tuple[Link, ...]
    joints: tuple[Joint, ...]
    root: str
    _by_child: dict[str, Joint] = field(default_factory=dict, repr=False, compare=False)

    @property
    def link_names(self) -> tuple[str, ...]:
        """All link names in file order."""
        return tuple(link.name for link in self.links)

    def link(self, name: str) -> Link:
        """The link called ``name`` (raises :class:`URDFError` listing valid names)."""
        for link in self.links:
            if link.name == name:
                return link
        raise URDFError(f"{self._where()}: no link {name!r}; links are {list(self.link_names)}")

    def parent_joint(self, link: str) -> Joint | None:
        """The joint whose child is ``link`` (``None`` for the root)."""
        return self._by_child.get(link)

    def children(self, link: str) -> tuple[Joint, ...]:
        """Joints whose parent is ``link``, in file order."""
        return tuple(j for j in self.joints if j.parent == link)

    def joints_between(self, base: str, tip: str) -> tuple[Joint, ...]:
        """Joints from ``base`` down to ``tip`` (empty when equal).

        Raises:
            URDFError: ``tip`` is not below ``base`` in the tree.
        """
        chain: list[Joint] = []
        link = tip
        while link != base:
            joint = self._by_child.get(link)
            if joint is None:
                raise URDFError(f"{self._where()}: link {tip!r} is not below link {base!r}")
            chain.append(joint)
            link = joint.parent
        return tuple(reversed(chain))

    def link_poses_at_zero(self, root: str | None = None) -> dict[str, FloatArray]:
        """``T_root_link`` (4, 4) of ``root`` and every link below it, every joint at zero.

        Args:
            root: the frame of the poses; default the URDF's root link.

        Returns:
            ``{link name: T_root_link}``, ``root`` first, then breadth-first in joint file order.
            Moving joints count at zero (their origin only); floating and planar joints too.

        Raises:
            URDFError: ``root`` is not a link.
        """
        return self._poses_below(root, fixed_only=False)

    def fixed_link_poses(self, root: str | None = None) -> dict[str, FloatArray]:
        """Like :meth:`link_poses_at_zero`, for a tree of fixed joints (a tool, a fixture).

        Raises:
            URDFError: a joint below ``root`` is not fixed (the message names it), or ``root``
                is not a link.
        """
        return self._poses_below(root, fixed_only=True)

    def mass_and_com(self, root: str | None = None) -> tuple[float, FloatArray]:
        """Total mass (kg) and centre of mass (3,) in the ``root`` frame (m), joints at zero.

        Sums the ``<inertial>`` of ``root`` (default the URDF's root link) and of every link
        below it, posed by :meth:`link_poses_at_zero`. Links without an inertial weigh nothing.

        Returns:
            ``(mass, com)``; ``(0.0, zeros(3))`` when nothing below ``root`` has mass.
        """
        by_name = {link.name: link for link in self.links}
        total, moment = 0.0, np.zeros(3)
        for name, T_root_link in self.link_poses_at_zero(root).items():
            inertial = by_name[name].inertial
            if inertial is None or inertial.mass == 0.0:
                continue
            total += inertial.mass
            moment += inertial.mass * (T_root_link @ inertial.T_link_com)[:3, 3]
        return total, (moment / total if total > 0.0 else np.zeros(3))

    def _poses_below(self, root: str | None, fixed_only: bool) -> dict[str, FloatArray]:
        start = self.root if root is None else self.link(root).name
        poses = {start: np.eye(4)}
        frontier = [start]
        while frontier:
            parent = frontier.pop(0)
            for j in self.children(parent):
                if fixed_only and j.type != "fixed":
                    raise URDFError(
                        f"{self._where()}: <joint name={j.name!r}> is {j.type}, not fixed; "
                        f"every joint below link {start!r} must be fixed"
                    )
                poses[j.child] = poses[parent] @ j.T_parent_joint
                frontier.append(j.child)
        return poses

    def missing_meshes(self) -> list[tuple[str, str]]:
        """``(link name, mesh URI)`` of every referenced mesh file that was not found."""
        out = []
        for link in self.links:
            for shape in (*link.visuals, *link.collisions):
                g = shape.geometry
                if g.kind == "mesh" and g.mesh_path is None:
                    out.append((link.name, g.filename))
        return out

    def _where(self) -> str:
        return str(self.path) if self.path is not None else f"URDF {self.name!r}"
