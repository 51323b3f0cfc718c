"""The tool on the robot flange and its TCP frames.

A :class:`Tool` is either a URDF (links joined by fixed joints, root link = the flange mount;
TCPs are named links) or a mesh in the flange frame with a dict of TCP frames. The built-in
``builtin:cable_feeder`` models the paper's cable-feeder tool (Hultman & Leijon 2013, Fig. 5):
a body on the flange with two cable guiding tubes and an 18 mm cylindrical proximity sensor
(8 mm sensing distance) on top. Its dimensions are assumed (see ``docs/cell.md``).

The ``sensor`` TCP lies at the sensing distance in front of the sensor face; its +z axis is
the sensor axis, pointing from the sensor into the surface (``calib.frames`` conventions).

Mounting (:func:`tool_mount`): a tool's root frame has +z out of the flange, along the last
joint's axis. Most URDFs put the tip link (``tool0``) that way, but some vendor descriptions
(ROS-Industrial's ABB arms) have its **x** axis out of the flange. The mount ``T_flange_tool``
(the tool's root in the tip-link frame) is therefore worked out from the chain: the last joint's
axis in the tip frame, signed to point away from the wrist, must lie along one of the tip
frame's axes, and the tool is turned from z onto it by the smallest rotation. When it does not
(a tilted flange, a tip on the axis of every joint), the cell refuses with a message naming the
plan field that sets the mount, ``cell.tool.T_flange_tool``.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import msgspec
import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray

from calib.errors import InputError
from calib.frames import check_transform, make_transform, matrix_from_rotvec
from calib.plan.cell import Pose
from calib.plan.json_io import reword_validation_error
from calib.reading import MAX_JSON_BYTES, read_bytes_capped
from calib.tolerances import ROLE_NORMAL_TOL_RAD
from planner.builtins import is_builtin, tool_description
from planner.cell.scene.bodies import BodyLinks, load_urdf_body, mesh_collision_shape, static_body
from planner.cell.scene.workobject import load_work_object
from planner.errors import MeshError, ToolMountError, UnknownFrameError, URDFError
from planner.robot.kinematics.chain import KinematicChain
from planner.robot.urdf import load_urdf

FloatArray = NDArray[np.float64]
logger = logging.getLogger(__name__)

#: Name of the flange frame; always a valid TCP (identity).
FLANGE = "flange"
#: The plan field that sets the tool's mount on the flange (named in mount errors).
MOUNT_FIELD = "cell.tool.T_flange_tool"
#: A wrist point nearer than this to the flange axis cannot tell which way is out, m.
_AXIS_SIGN_MIN_M = 1e-3


def flange_axis(chain: KinematicChain) -> FloatArray | None:
    """``(3,)`` the last joint's unit axis in the tip-link frame, pointing out of the flange
    (away from the wrist), or ``None`` when no joint origin lies off the axis to tell the sign.

    The sign comes from the joints before the last (at the chain's reference pose, zero clipped
    into the limits): the tip lies on the far side of the last joint from them.
    """
    q0 = np.clip(np.zeros(chain.n_joints), chain.lower, chain.upper)
    frames = chain.joint_frames(q0)[0]
    T_base_tip = frames[-1] @ chain.T_last_tip
    axis_base = frames[-1][:3, :3] @ chain.axes[-1]
    axis_base = axis_base / np.linalg.norm(axis_base)
    for k in range(chain.n_joints - 1, -1, -1):
        along = float(axis_base @ (T_base_tip[:3, 3] - frames[k][:3, 3]))
        if abs(along) > _AXIS_SIGN_MIN_M:
            return np.asarray(T_base_tip[:3, :3].T @ (np.sign(along) * axis_base))
    return None


def tool_mount(chain: KinematicChain, T_flange_tool: ArrayLike | None = None) -> FloatArray:
    """``(4, 4)`` the tool's root frame in the tip-link (flange) frame (see the module docstring).

    Args:
        chain: the robot chain; its tip link is the flange.
        T_flange_tool: the mount the plan gives (``cell.tool.T_flange_tool``), used as is;
            ``None`` works it out from the last joint's axis.

    Raises:
        ToolMountError: no mount given and the axis is not along an axis of the tip frame,
            or its direction out of the flange cannot be told; the message names the plan field.
    """
    if T_flange_tool is not None:
        return check_transform(T_flange_tool, MOUNT_FIELD)
    joint = chain.joint_names[-1]
    u = flange_axis(chain)
    if u is None:
        raise ToolMountError(
            f"cannot tell which way the last joint {joint!r} points out of the flange "
            f"{chain.tip_link!r} (every joint origin lies on its axis); set {MOUNT_FIELD} "
            "(the tool's mount pose in the flange frame, +z out of the flange)"
        )
    k = int(np.argmax(np.abs(u)))
    if abs(u[k]) < np.cos(ROLE_NORMAL_TOL_RAD):
        shown = ", ".join(f"{v:.3f}" for v in u)
        raise ToolMountError(
            f"the last joint {joint!r} turns about ({shown}) in the tip frame "
            f"{chain.tip_link!r}, not along one of its axes, so the tool's mount cannot be "
            f"guessed; set {MOUNT_FIELD} (the tool's mount pose in the flange frame, +z out of "
            "the flange)"
        )
    out = np.zeros(3)
    out[k] = np.sign(u[k])
    if out[2] > 0.5:
        return np.eye(4)
    if out[2] < -0.5:  # half a turn about x
        return make_transform(np.diag([1.0, -1.0, -1.0]), np.zeros(3))
    axis = np.cross([0.0, 0.0, 1.0], out)  # the smallest rotation taking z onto the axis
    return make_transform(matrix_from_rotvec(axis * (np.pi / 2)), np.zeros(3))


@dataclass(frozen=True)
class Tool:
    """A tool on the flange.

    Attributes:
        name: tool name, e.g. ``"cable_feeder"``.
        tcps: TCP name -> ``T_flange_tcp`` (4, 4), m. Does not list ``"flange"`` (always valid).
        urdf_path: the tool URDF (root link frame = flange frame), or ``None`` for a mesh tool.
        mesh: the tool mesh in the flange frame, m (mesh tools; collision uses its convex hull).
        sensor_tcp: name of the proximity-sensor TCP, or ``None`` when the tool has no sensor.
        sensor_links: links of the sensor body; they may come closer to the work object than
            the clearance margin (down to contact), as the sensor face must be within its
            sensing distance of the surface.
    """

    name: str
    tcps: Mapping[str, FloatArray]
    urdf_path: Path | None = None
    mesh: trimesh.Trimesh | None = field(default=None, repr=False)
    sensor_tcp: str | None = None
    sensor_links: tuple[str, ...] = ()

    @property
    def tcp_names(self) -> list[str]:
        """Valid TCP names: ``"flange"`` and the tool's TCPs, sorted."""
        return sorted({FLANGE, *self.tcps})

    def T_flange_tcp(self, tcp: str) -> FloatArray:
        """``T_flange_tcp`` (4, 4) of TCP ``tcp``.

        Raises:
            UnknownFrameError: no such TCP (the message lists the valid names).
        """
        if tcp == FLANGE:
            return np.eye(4)
        if tcp not in self.tcps:
            raise UnknownFrameError(
                f"tcp {tcp!r} is not a TCP of tool {self.name!r}; valid: {self.tcp_names}"
            )
        return self.tcps[tcp].copy()

    @classmethod
    def from_urdf(
        cls,
        path: str | Path,
        tcps: list[str] | None = None,
        sensor_tcp: str | None = None,
        sensor_links: tuple[str, ...] = (),
    ) -> Tool:
        """A tool from a URDF whose links are joined by fixed joints; TCPs are named links.

        Args:
            path: the URDF; its root link frame is the flange frame.
            tcps: link names to offer as TCPs; default every link but the root.
            sensor_tcp: the proximity-sensor TCP, if any.
            sensor_links: links of the sensor body (may approach the work object to contact).

        Raises:
            URDFError: missing, malformed, not a tree of fixed joints, or a TCP name is not a link.
        """
        path = Path(path)
        poses = load_urdf(path, check_meshes=False).fixed_link_poses()
        names = list(poses)[1:] if tcps is None else list(tcps)
        for n in [*names, *sensor_links, *([sensor_tcp] if sensor_tcp else [])]:
            if n not in poses:
                raise URDFError(f"tool URDF {path} has no link {n!r}; links: {sorted(poses)}")
        return cls(
            name=path.stem,
            tcps=MappingProxyType({n: poses[n] for n in names}),
            urdf_path=path,
            sensor_tcp=sensor_tcp,
            sensor_links=tuple(sensor_links),
        )

    @classmethod
    def from_mesh(
        cls,
        mesh: trimesh.Trimesh,
        tcps: Mapping[str, ArrayLike],
        name: str = "tool",
        sensor_tcp: str | None = None,
    ) -> Tool:
        """A tool from a mesh in the flange frame (metres) and TCP frames ``T_flange_tcp``.

        Collision checking uses the mesh's convex hull, so give a mesh whose hull is a fair
        stand-in, or write a URDF with several parts.

        Raises:
            MeshError: the mesh is empty or not finite.
            ShapeError, NonFiniteError, DegenerateGeometryError: a TCP frame is not a transform.
        """
        if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
            raise MeshError(f"tool mesh {name!r} is empty or not a trimesh.Trimesh")
        if not np.all(np.isfinite(mesh.vertices)):
            raise MeshError(f"tool mesh {name!r} holds NaN or infinite vertices")
        frames = {k: check_transform(v, f"tcps[{k!r}]") for k, v in tcps.items()}
        if sensor_tcp is not None and sensor_tcp not in frames:
            raise UnknownFrameError(f"sensor_tcp {sensor_tcp!r} is not in tcps {sorted(frames)}")
        return cls(
            name=name,
            tcps=MappingProxyType(frames),
            mesh=mesh,
            sensor_tcp=sensor_tcp,
        )

    def fingerprint(self) -> bytes:
        """Bytes that change when the tool's geometry changes (for cache keys)."""
        if self.urdf_path is not None:
            return self.urdf_path.read_bytes()
        if self.mesh is None:
            return b""
        return self.mesh.vertices.tobytes() + self.mesh.faces.tobytes()

    def create_body(self, client: int) -> BodyLinks:
        """Load the tool into PyBullet client ``client`` at the world origin."""
        if self.urdf_path is not None:
            return load_urdf_body(client, self.urdf_path, np.eye(4), "tool")
        if self.mesh is None:
            raise MeshError(f"tool {self.name!r} has neither a URDF nor a mesh")
        shape = mesh_collision_shape(client, self.mesh, concave=False, source=f"tool {self.name}")
        return static_body(client, shape, np.eye(4), self.name)


#: The tool description's schema tag (optional in the file).
TOOL_SCHEMA = "wobjcal.tool/1"
#: The keys a tool description JSON may hold (any other is refused, naming it).
DESCRIPTION_KEYS = (
    "schema",
    "name",
    "urdf",
    "tcps",
    "sensor_tcp",
    "sensor_links",
    "mesh",
    "units",
    "tcp_frames",
)


def load_tool(spec: str | Path | Tool) -> Tool:
    """A tool from ``"builtin:<name>"``, a tool description ``.json``, a ``.urdf`` or a Tool.

    A description JSON (``"schema": "wobjcal.tool/1"``, optional) describes either

    - a URDF tool: ``urdf`` (relative to the JSON), ``tcps`` (link names), ``sensor_tcp``
      and ``sensor_links``; or
    - a mesh tool (:meth:`Tool.from_mesh`): ``mesh`` (a file in the JSON's folder, in the
      flange frame), ``units`` (``m`` default, ``mm``, ``cm``, ``in``, ``auto``),
      ``tcp_frames`` (``{name: {"position_m": [x, y, z], "quat_wxyz": [w, x, y, z]}}``,
      ``T_flange_tcp``), ``sensor_tcp``, and ``sensor_links`` (empty, or the tool's
      ``name``: its whole convex hull may then touch the work object, as a sensor does).

    The sensor itself (sensing distance, face) is the plan's
    :class:`calib.models.ProximitySensor`, not part of the tool.

    Raises:
        UnknownBuiltinError: unknown built-in name.
        UnknownFrameError: a ``sensor_tcp`` that is not a TCP.
        URDFError: the file is missing or malformed (the message names the key).
        MeshError: a mesh tool's mesh is missing, unreadable or empty.
    """
    if isinstance(spec, Tool):
        return spec
    path = tool_description(str(spec)) if is_builtin(spec) else Path(spec)
    if path.suffix.lower() == ".urdf":
        return Tool.from_urdf(path)
    if not path.exists():
        raise URDFError(f"tool description not found: {path}")
    desc = _read_description(path)
    if "mesh" in desc:
        return _mesh_tool(path, desc)
    try:
        tool = Tool.from_urdf(
            path.parent / desc["urdf"],
            tcps=list(desc["tcps"]),
            sensor_tcp=desc.get("sensor_tcp"),
            sensor_links=tuple(desc.get("sensor_links", ())),
        )
    except (KeyError, TypeError, ValueError) as exc:
        if isinstance(exc, URDFError):
            raise
        raise URDFError(f"malformed tool description {path}: {exc!r}") from None
    return Tool(**{**tool.__dict__, "name": desc.get("name", tool.name)})


def _read_description(path: Path) -> dict[str, Any]:
    """The JSON object of a tool description, its keys checked."""
    try:
        desc = json.loads(read_bytes_capped(path, MAX_JSON_BYTES, "tool description", URDFError))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise URDFError(f"tool description {path} is not JSON: {exc}") from None
    if not isinstance(desc, dict):
        raise URDFError(f"tool description {path} must hold a JSON object, got {type(desc)}")
    unknown = sorted(set(desc) - set(DESCRIPTION_KEYS))
    if unknown and "schema" not in desc:  # a description from before wobjcal.tool/1: as read then
        logger.warning(
            "tool description %s: %s ignored (the sensor's numbers are the plan's "
            "validation.sensor; give schema %r to have unknown keys refused)",
            path,
            ", ".join(unknown),
            TOOL_SCHEMA,
        )
        unknown = []
    sensor_keys = [k for k in unknown if k.startswith("sens")]
    if sensor_keys:
        raise URDFError(
            f"tool description {path}: {sensor_keys[0]!r}: the sensor's numbers are the plan's "
            "validation.sensor (the UI's Cell tab, Sensor), not the tool's; leave it out"
        )
    if unknown:
        raise URDFError(
            f"tool description {path}: unknown key {unknown[0]!r} (known: "
            f"{', '.join(DESCRIPTION_KEYS)})"
        )
    if desc.get("schema", TOOL_SCHEMA) != TOOL_SCHEMA:
        raise URDFError(
            f"tool description {path}: schema {desc['schema']!r} is not {TOOL_SCHEMA!r}"
        )
    if "mesh" in desc and ("urdf" in desc or "tcps" in desc):
        raise URDFError(
            f"tool description {path}: give either urdf (with tcps) or mesh (with tcp_frames), "
            "not both"
        )
    if "mesh" not in desc and "urdf" not in desc:
        raise URDFError(
            f"tool description {path}: needs urdf (with tcps) or mesh (with tcp_frames)"
        )
    return desc


def _mesh_tool(path: Path, desc: dict[str, Any]) -> Tool:
    """A mesh tool from its description ``desc`` read from ``path`` (see :func:`load_tool`)."""
    where = f"tool description {path}"
    ref = desc["mesh"]
    if not isinstance(ref, str) or not ref or Path(ref).is_absolute() or ".." in Path(ref).parts:
        raise URDFError(
            f"{where}: mesh must be a file name relative to the description's folder (its "
            f"folder travels with it), got {ref!r}"
        )
    name = desc.get("name", path.stem)
    if not isinstance(name, str) or not name:
        raise URDFError(f"{where}: name must be a non-empty string, got {name!r}")
    frames = desc.get("tcp_frames")
    if not isinstance(frames, dict) or not frames:
        raise URDFError(
            f'{where}: tcp_frames must map TCP names to poses ({{"sensor": {{"position_m": '
            f'[x, y, z], "quat_wxyz": [w, x, y, z]}}}}), got {frames!r}'
        )
    tcps = {}
    for tcp, raw in frames.items():
        try:
            pose = msgspec.convert(raw, Pose, strict=True)
        except msgspec.ValidationError as exc:
            raise URDFError(f"{where}: tcp_frames.{tcp}: {reword_validation_error(exc)}") from None
        except InputError as exc:
            raise URDFError(f"{where}: tcp_frames.{tcp}: {exc}") from None
        if tcp == FLANGE:
            raise URDFError(f"{where}: tcp_frames: {FLANGE!r} is the flange itself, always a TCP")
        tcps[tcp] = pose.matrix()
    sensor_tcp = desc.get("sensor_tcp")
    if sensor_tcp is not None and sensor_tcp not in tcps:
        raise UnknownFrameError(
            f"{where}: sensor_tcp {sensor_tcp!r} is not one of tcp_frames {sorted(tcps)}"
        )
    links = desc.get("sensor_links", [])
    if not isinstance(links, list) or any(link != name for link in links):
        raise URDFError(
            f"{where}: sensor_links of a mesh tool may only name the tool ({name!r}: one body), "
            f"got {links!r}"
        )
    units = desc.get("units", "m")
    if not isinstance(units, str):
        raise URDFError(f"{where}: units must be a string such as 'mm', got {units!r}")
    mesh = load_work_object(path.parent / ref, units=units, name=name).mesh
    tool = Tool.from_mesh(mesh, tcps, name=name, sensor_tcp=sensor_tcp)
    return Tool(**{**tool.__dict__, "sensor_links": tuple(links)})


def mesh_tool_description(
    mesh: str,
    tcps: Mapping[str, ArrayLike],
    units: str = "m",
    sensor_tcp: str | None = None,
    name: str | None = None,
    sensor_links: tuple[str, ...] = (),
) -> str:
    """The JSON text of a mesh tool's description (:func:`load_tool` reads it back).

    Args:
        mesh: the mesh file's name, relative to where the description is written.
        tcps: TCP name -> ``T_flange_tcp`` (4, 4), m.
        units: the mesh file's length unit.
        sensor_tcp: the proximity-sensor TCP (one of ``tcps``), if any.
        name: the tool's name (default: the description file's stem).
        sensor_links: ``()`` or ``(name,)`` (see :func:`load_tool`).

    Raises:
        ShapeError, NonFiniteError, DegenerateGeometryError: a TCP frame is not a transform.
    """
    frames = {
        k: msgspec.to_builtins(Pose.from_matrix(check_transform(T, f"tcps[{k!r}]")))
        for k, T in tcps.items()
    }
    desc: dict[str, Any] = {"schema": TOOL_SCHEMA, "mesh": mesh, "units": units}
    desc["tcp_frames"] = frames
    if sensor_tcp is not None:
        desc["sensor_tcp"] = sensor_tcp
    if name is not None:
        desc["name"] = name
    if sensor_links:
        desc["sensor_links"] = list(sensor_links)
    return json.dumps(desc, sort_keys=True, indent=2) + "\n"
