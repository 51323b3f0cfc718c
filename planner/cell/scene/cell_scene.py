"""The cell's scene: one PyBullet DIRECT client holding robot, tool, work object, fixtures.

:class:`CellScene` builds the bodies, the allowed-collision list and the clearance query, and
keeps the state (joint values, work-object and fixture poses). The queries that use it
(probe-pose feasibility, search paths, the reachability map) take a scene and live in their own
modules; :class:`planner.cell.cell.Cell` is the scene with those queries as methods.

A scene owns its client (``physicsClientId`` on every call, no global client); ``close()`` or
``with`` releases it. It is not thread-safe: serialize access (one lock or one worker). The
robot stands with its chain base link at ``T_world_base``; the tool's root link sits on the
chain's tip link (the flange, ``tool0``) at the mount ``T_flange_tool``
(:func:`planner.cell.scene.tool_mount`: along the last joint's axis, whichever axis of the tip
frame that is, or as the plan sets it). Poses follow :mod:`calib.frames`.
"""

from __future__ import annotations

import contextlib
import logging
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_shape
from calib.errors import ShapeError
from calib.frames import check_transform, invert_transform
from planner.builtins import is_builtin, robot_urdf
from planner.cell.scene.acl import acl_key, compute_acl, sample_configurations
from planner.cell.scene.bodies import BodyLinks, set_link_pose, world_link_pose
from planner.cell.scene.collision import (
    DEFAULT_MARGIN_M,
    DEFAULT_SELF_MARGIN_M,
    Clearance,
    CollisionChecker,
)
from planner.cell.scene.fixtures import Fixture, fixture_from_spec
from planner.cell.scene.pybullet_client import connect_direct, pb
from planner.cell.scene.robot_body import load_robot_body
from planner.cell.scene.tool import FLANGE, Tool, load_tool, tool_mount
from planner.cell.scene.workobject import WorkObject, load_work_object
from planner.errors import UnknownFrameError
from planner.robot.controller_base import ControllerBase, controller_base
from planner.robot.kinematics.chain import KinematicChain
from planner.robot.kinematics.solver import IKSolver, make_ik_solver
from planner.robot.reach import ReachModel, cell_reach_model
from planner.robot.urdf import load_urdf

FloatArray = NDArray[np.float64]
log = logging.getLogger(__name__)


class CellScene:
    """A robot cell in its own PyBullet DIRECT client: bodies, state and the clearance query.

    Args:
        robot: ``"builtin:irb4400"`` or a URDF path (fixed base; limits from the URDF).
        tool: ``"builtin:cable_feeder"``, a tool description JSON, a tool URDF, a
            :class:`planner.cell.scene.Tool`, or ``None`` for a bare flange.
        T_world_base: ``(4, 4)`` pose of the robot base link in the world; default identity.
        base_link: chain base link (default the URDF root); tip_link: the flange (default
            ``tool0`` or the end of the longest chain).
        T_flange_tool: ``(4, 4)`` the tool's root in the flange frame (the plan's
            ``cell.tool.T_flange_tool``); ``None`` mounts it along the last joint's axis.
        self_margin_m: clearance between robot/tool links not in the ACL, m.
        acl_samples: random configurations sampled for the allowed-collision list.
        acl_rng: generator of those samples (default seeded, so the ACL is reproducible).
        use_acl_cache: read/write the ACL cache (see :mod:`planner.cell.scene.collision`).

    Raises:
        URDFError: missing or malformed robot/tool URDF (the message names the file).
        UnknownBuiltinError: unknown built-in name.
        UnknownFrameError: unknown base or tip link.
        ToolMountError: the tool cannot be mounted without ``T_flange_tool`` (named).
    """

    def __init__(
        self,
        robot: str | Path = "builtin:irb4400",
        tool: str | Path | Tool | None = "builtin:cable_feeder",
        T_world_base: ArrayLike | None = None,
        *,
        base_link: str | None = None,
        tip_link: str | None = None,
        T_flange_tool: ArrayLike | None = None,
        self_margin_m: float = DEFAULT_SELF_MARGIN_M,
        acl_samples: int = 1000,
        acl_rng: np.random.Generator | None = None,
        use_acl_cache: bool = True,
    ) -> None:
        if int(acl_samples) < 1:
            raise ShapeError(f"acl_samples must be >= 1, got {acl_samples}")
        path = robot_urdf(str(robot)) if is_builtin(robot) else Path(robot)
        model = load_urdf(path)
        self.chain: KinematicChain = KinematicChain.from_model(model, base_link, tip_link)
        #: the robot controller's base frame on the chain's base link (a UR arm's Base)
        self.controller_base: ControllerBase = controller_base(model, self.chain.base_link)
        self.solver: IKSolver = make_ik_solver(self.chain)
        self.tool: Tool | None = None if tool is None else load_tool(tool)
        #: ``(4, 4)`` the tool's root frame in the flange (tip-link) frame.
        self.T_flange_tool: FloatArray = (
            np.eye(4) if self.tool is None else tool_mount(self.chain, T_flange_tool)
        )
        if not np.allclose(self.T_flange_tool, np.eye(4)):
            log.info("tool mounted on %s at\n%s", self.chain.tip_link, self.T_flange_tool)
        self.self_margin_m = float(self_margin_m)
        self._T_world_base = (
            np.eye(4) if T_world_base is None else check_transform(T_world_base, "T_world_base")
        )
        self._T_world_wobj = np.eye(4)
        self._reach: ReachModel | None = None
        self.work_object: WorkObject | None = None
        self._wobj_links: BodyLinks | None = None
        #: structures the query modules build once per scene and keep here (e.g. the broad
        #: phase of :mod:`planner.cell.broad.broad_phase`); they read the environment afresh.
        self.query_cache: dict[str, object] = {}
        self.fixtures: dict[str, Fixture] = {}
        self._client: int | None = connect_direct()
        try:
            self._load_bodies(path)
            self._build_checker(path, acl_samples, acl_rng, use_acl_cache)
        except BaseException:
            self.close()
            raise

    # ----------------------------------------------------------------- construction
    def _load_bodies(self, path: Path) -> None:
        c = self.client
        self.robot_body = load_robot_body(c, path, self.chain, self._T_world_base)
        self.robot: BodyLinks = self.robot_body.links
        self._names: dict[tuple[int, int], str] = {
            (self.robot.body_id, i): n for i, n in self.robot.names.items()
        }
        self.tool_body: BodyLinks | None = None
        if self.tool is not None:
            self.tool_body = self.tool.create_body(c)
            robot_names = set(self.robot.names.values())
            for i, n in self.tool_body.names.items():
                self._names[(self.tool_body.body_id, i)] = f"tool:{n}" if n in robot_names else n
        self.set_joint_positions(self.home_q)

    def _build_checker(
        self, path: Path, n: int, rng: np.random.Generator | None, use_cache: bool
    ) -> None:
        rng = rng if rng is not None else np.random.default_rng(0)
        samples = sample_configurations(self.chain.lower, self.chain.upper, n, rng)
        texts = [path.read_bytes()]
        root, sensor_links = None, frozenset[int]()
        if self.tool_body is not None and self.tool is not None:
            root = self._names[(self.tool_body.body_id, -1)]
            sensor_links = frozenset(
                i for i, name in self.tool_body.names.items() if name in self.tool.sensor_links
            )
            texts.append(self.tool.fingerprint())
        mount = ",".join(f"{v:.9f}" for v in self.T_flange_tool[:3].ravel())
        settings = (
            f"{self.chain.base_link}>{self.chain.tip_link}:{n}:{self.self_margin_m:.6f}:{mount}"
        )
        with self.saved_state():
            acl = compute_acl(
                self.client,
                self.robot,
                self.tool_body,
                self._name,
                self.set_joint_positions,
                samples,
                self.robot_body.adjacent_pairs(root),
                self.self_margin_m,
                acl_key(texts, settings),
                use_cache,
                mount_links=self.robot_body.mount_links(),
            )
        self.checker = CollisionChecker(
            self.client,
            self.robot,
            self.tool_body,
            self._name,
            self.robot_body.static_links,
            acl,
            sensor_links,
        )

    def _name(self, body: int, link: int) -> str:
        return self._names[(body, link)]

    # ----------------------------------------------------------------- life cycle
    @property
    def client(self) -> int:
        """The PyBullet ``physicsClientId`` (raises when the cell is closed)."""
        if self._client is None:
            raise RuntimeError("the cell is closed")
        return self._client

    def close(self) -> None:
        """Disconnect the PyBullet client (idempotent)."""
        if self._client is not None:
            with contextlib.suppress(pb.error):
                pb.disconnect(self._client)
            self._client = None

    def __enter__(self) -> CellScene:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        with contextlib.suppress(Exception):
            self.close()

    @contextlib.contextmanager
    def saved_state(self) -> Iterator[None]:
        """Restore the joint positions (and so the tool pose) on exit."""
        q = self.joint_positions
        try:
            yield
        finally:
            self.set_joint_positions(q)

    # ----------------------------------------------------------------- frames
    @property
    def T_world_base(self) -> FloatArray:
        """``(4, 4)`` robot base link in the world, m."""
        return self._T_world_base.copy()

    @property
    def T_world_wobj(self) -> FloatArray:
        """``(4, 4)`` work-object frame in the world, m."""
        return self._T_world_wobj.copy()

    @property
    def T_base_wobj(self) -> FloatArray:
        """``(4, 4)`` work-object frame in the robot base frame, m."""
        return invert_transform(self._T_world_base) @ self._T_world_wobj

    @property
    def reach_model(self) -> ReachModel:
        """Shoulder and reach of the robot (computed once, seeded)."""
        if self._reach is None:
            self._reach = cell_reach_model(self.chain)
        return self._reach

    @property
    def joint_indices(self) -> list[int]:
        """PyBullet joint indices of the chain's joints, in chain order."""
        return list(self.robot_body.joint_index)

    @property
    def flange_index(self) -> int:
        """PyBullet link index of the flange (the chain's tip link) in ``self.robot``."""
        return self.robot_body.flange_index

    @property
    def home_q(self) -> FloatArray:
        """``(n,)`` a reference configuration: 0 clipped into the limits, rad."""
        return np.clip(np.zeros(self.chain.n_joints), self.chain.lower, self.chain.upper)

    @property
    def joint_positions(self) -> FloatArray:
        """``(n,)`` current joint values, rad."""
        return np.array(
            [
                pb.getJointState(self.robot.body_id, j, physicsClientId=self.client)[0]
                for j in self.robot_body.joint_index
            ]
        )

    def set_joint_positions(self, q: ArrayLike) -> None:
        """Put the robot in configuration ``q (n,)`` (rad) and move the tool with the flange.

        Raises:
            ShapeError, NonFiniteError: ``q`` is not a finite ``(n,)`` vector.
        """
        self.place_robot(check_shape(q, (self.chain.n_joints,), "q"))

    def place_robot(self, q: FloatArray) -> None:
        """:meth:`set_joint_positions` without the checks, for hot loops whose ``q (n,)``
        (rad, float64, finite) is already checked."""
        c = self.client
        self.robot_body.set_q(c, q)
        if self.tool_body is not None:
            flange = world_link_pose(c, self.robot, self.robot_body.flange_index)
            set_link_pose(c, self.tool_body, flange @ self.T_flange_tool)

    def link_poses(self) -> dict[str, FloatArray]:
        """``T_world_link (4, 4)`` of every robot and tool link in the current state."""
        out = {}
        for (body, i), name in self._names.items():
            links = self.robot if body == self.robot.body_id else self.tool_body
            if links is not None:
                out[name] = world_link_pose(self.client, links, i)
        return out

    def T_flange_tcp(self, tcp: str) -> FloatArray:
        """``(4, 4)`` TCP ``tcp`` in the flange frame, through the tool's mount
        (``"flange"`` is always valid: identity).

        Raises:
            UnknownFrameError: unknown TCP (the message lists the valid names).
        """
        if self.tool is None:
            if tcp != "flange":
                raise UnknownFrameError(f"tcp {tcp!r}: the cell has no tool; valid: ['flange']")
            return np.eye(4)
        if tcp == FLANGE:
            return np.eye(4)
        return self.T_flange_tool @ self.tool.T_flange_tcp(tcp)

    # ----------------------------------------------------------------- scene
    def set_work_object(
        self,
        mesh: str | Path | trimesh.Trimesh | WorkObject,
        units: str = "auto",
        T_world_wobj: ArrayLike | None = None,
        name: str | None = None,
    ) -> WorkObject:
        """Load (or replace) the work object, as a concave static body at ``T_world_wobj``.

        Raises:
            MeshError: missing, unreadable or empty mesh (the message names the file).
        """
        wobj = (
            mesh
            if isinstance(mesh, WorkObject)
            else load_work_object(mesh, units, name, reach_m=self.reach_model.reach_m)
        )
        T = np.eye(4) if T_world_wobj is None else check_transform(T_world_wobj, "T_world_wobj")
        if self.checker.wobj_body is not None:
            pb.removeBody(self.checker.wobj_body, physicsClientId=self.client)
            self.checker.environment.pop(self.checker.wobj_body, None)
        body = wobj.create_body(self.client, T)
        self.checker.wobj_body = body.body_id
        self.checker.environment[body.body_id] = wobj.name
        self.work_object, self._T_world_wobj, self._wobj_links = wobj, T, body
        self.checker.log_static_contacts(body.body_id)
        return wobj

    def move_work_object(self, T_world_wobj: ArrayLike) -> None:
        """Move the loaded work object to ``T_world_wobj`` without rebuilding its mesh body
        (the Monte Carlo validation moves the part every trial).

        Raises:
            UnknownFrameError: no work object is loaded.
        """
        if self.work_object is None or self._wobj_links is None:
            raise UnknownFrameError("move_work_object: the cell has no work object yet")
        T = check_transform(T_world_wobj, "T_world_wobj")
        set_link_pose(self.client, self._wobj_links, T)
        self._T_world_wobj = T

    def add_fixture(self, fixture: Fixture | str, **kwargs: Any) -> Fixture:
        """Add a fixture: a :class:`Fixture`, or a name and ``size_m=`` (box), ``radius_m=`` +
        ``height_m=`` (cylinder) or ``mesh=`` (+ ``units=``), with ``T_world_fixture=``.

        Raises:
            ShapeError: bad sizes or pose, or a name already used; MeshError: bad mesh.
        """
        if isinstance(fixture, str):
            fixture = fixture_from_spec(fixture, **kwargs)
        if fixture.name in self.fixtures:
            raise ShapeError(f"a fixture named {fixture.name!r} already exists")
        body = fixture.create_body(self.client)
        self.checker.environment[body.body_id] = fixture.name
        self.fixtures[fixture.name] = fixture
        self.checker.log_static_contacts(body.body_id)
        return fixture

    def remove_fixture(self, name: str) -> None:
        """Remove the fixture ``name``.

        Raises:
            UnknownFrameError: no such fixture (the message lists the fixtures).
        """
        if name not in self.fixtures:
            raise UnknownFrameError(f"no fixture {name!r}; fixtures: {sorted(self.fixtures)}")
        body = next(
            b
            for b, n in self.checker.environment.items()
            if n == name and b != self.checker.wobj_body
        )
        pb.removeBody(body, physicsClientId=self.client)
        del self.checker.environment[body]
        del self.fixtures[name]

    # ----------------------------------------------------------------- queries
    def clearance(
        self,
        margin_m: float = DEFAULT_MARGIN_M,
        sensor_wobj_allowed: bool = True,
        skip_wobj: bool = False,
    ) -> Clearance:
        """Clearance of the current state (see :meth:`CollisionChecker.query`)."""
        return self.checker.query(
            margin_m, self.self_margin_m, None, sensor_wobj_allowed, skip_wobj
        )
