"""The robot in a PyBullet client: joint indices, flange link, static links, adjacency.

PyBullet numbers joints and links its own way; :func:`load_robot_body` maps the kinematic
chain's joint names and base/tip links onto them once, places the chain's base link at
``T_world_base``, and finds which links no joint moves (the base) and which links are parent
and child (always allowed to touch).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from calib.frames import invert_transform
from planner.cell.scene.acl import Pair, pair
from planner.cell.scene.bodies import BodyLinks, load_urdf_body, set_link_pose, world_link_pose
from planner.cell.scene.pybullet_client import pb
from planner.errors import URDFError
from planner.robot.kinematics.chain import KinematicChain

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class RobotBody:
    """A robot loaded into PyBullet.

    Attributes:
        links: the PyBullet body and its link names.
        joint_index: PyBullet joint index of each chain joint, in chain order, ``(n,)``.
        flange_index: PyBullet link index of the chain's tip link (the flange).
        parent: link index -> parent link index (``-1``: the base link).
        fixed: link indices attached to their parent by a fixed joint.
        static_links: link indices that no joint moves (the base and what is fixed to it).
    """

    links: BodyLinks
    joint_index: tuple[int, ...]
    flange_index: int
    parent: dict[int, int]
    fixed: frozenset[int]
    static_links: frozenset[int]

    @property
    def body_id(self) -> int:
        """PyBullet body unique id."""
        return self.links.body_id

    def set_q(self, client: int, q: FloatArray) -> None:
        """Reset the chain joints to ``q (n,)`` rad (no checks: validate before)."""
        for j, v in zip(self.joint_index, q.tolist()):
            pb.resetJointState(self.links.body_id, j, v, physicsClientId=client)

    def mount_links(self) -> tuple[str, ...]:
        """The links the tool is mounted on: the flange link and the links it is fixed to,
        up to the first moving joint (e.g. ``tool0`` and ``link_6``)."""
        names = self.links.names
        out, link = [], self.flange_index
        while link >= 0:
            out.append(names[link])
            if link not in self.fixed:
                break
            link = self.parent[link]
        return tuple(out)

    def adjacent_pairs(self, tool_root: str | None = None) -> list[Pair]:
        """Parent-child link pairs, plus the tool's root link with the flange link and the
        links the flange is fixed to (up to the first moving joint)."""
        names = self.links.names
        out = [pair(names[i], names[p]) for i, p in self.parent.items()]
        link = self.flange_index
        while tool_root is not None and link >= 0:
            out.append(pair(tool_root, names[link]))
            if link not in self.fixed:
                break
            link = self.parent[link]
        return out


def load_robot_body(
    client: int, path: Path, chain: KinematicChain, T_world_base: FloatArray
) -> RobotBody:
    """Load the robot URDF so that the chain's base link lies at ``T_world_base``.

    Raises:
        URDFError: PyBullet cannot load the file, or lacks a joint or link of the chain.
    """
    links = load_urdf_body(client, path, np.eye(4), "robot")
    bid = links.body_id
    infos = [pb.getJointInfo(bid, j, physicsClientId=client) for j in links.names if j >= 0]
    by_name = {info[1].decode(): info[0] for info in infos}
    missing = [n for n in chain.joint_names if n not in by_name]
    if missing:
        raise URDFError(f"robot URDF {path}: PyBullet did not load joints {missing}")
    try:
        base = links.index(chain.base_link)
        flange = links.index(chain.tip_link)
    except KeyError as exc:
        raise URDFError(f"robot URDF {path}: PyBullet has no link {exc}") from None
    T_root_base = world_link_pose(client, links, base)
    set_link_pose(client, links, T_world_base @ invert_transform(T_root_base))
    parent = {info[0]: info[16] for info in infos}
    fixed = frozenset(info[0] for info in infos if info[2] == pb.JOINT_FIXED)
    moving: set[int] = set()
    for info in infos:  # PyBullet lists parents before children
        if info[0] not in fixed or info[16] in moving:
            moving.add(info[0])
    return RobotBody(
        links=links,
        joint_index=tuple(by_name[n] for n in chain.joint_names),
        flange_index=flange,
        parent=parent,
        fixed=fixed,
        static_links=frozenset(set(links.names) - moving),
    )
