"""PyBullet bodies of the cell: URDF loading, static mesh bodies and pose conversions.

Every function takes the ``client`` (a PyBullet ``physicsClientId``) explicitly; there is no
module-level client. PyBullet places a body by its base *inertial* frame; these helpers take
and return URDF link frames (``T_world_link``) and convert at this one place.
"""

from __future__ import annotations

import logging
import math
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh
from numpy.typing import NDArray

from calib.frames import invert_transform
from planner.cell.scene.pybullet_client import native_chatter_filtered, pb
from planner.errors import MeshError, URDFError

FloatArray = NDArray[np.float64]
log = logging.getLogger(__name__)

#: Above this many vertices a mesh goes to PyBullet through a temporary OBJ file (the in-memory
#: ``vertices=`` path of ``createCollisionShape`` fails somewhere between 49k and 98k vertices).
MAX_INLINE_VERTICES = 40_000
#: PyBullet answers pose queries (``getBasePositionAndOrientation``, ``getLinkState``) of a body
#: of at most this many links, base included; beyond, they fail with a bare
#: ``GetBasePositionAndOrientation failed`` (measured: 128 links pass, 129 fail, whatever the
#: joint types).
PYBULLET_MAX_LINKS = 128


@dataclass(frozen=True)
class BodyLinks:
    """A PyBullet body and the names of its links.

    Attributes:
        body_id: PyBullet body unique id.
        names: link index -> link name; index ``-1`` is the base link.
        T_link_inertial: ``(4, 4)`` the base link's inertial frame in its link frame, m.
    """

    body_id: int
    names: dict[int, str]
    T_link_inertial: FloatArray

    def index(self, name: str) -> int:
        """Link index of ``name`` (``-1`` for the base); ``KeyError`` when unknown."""
        for i, n in self.names.items():
            if n == name:
                return i
        raise KeyError(name)


def pb_pose(T: FloatArray) -> tuple[list[float], list[float]]:
    """PyBullet ``(position, quat_xyzw)`` of a transform ``(4, 4)``.

    Scalar Shepperd method on Python floats: this runs once per candidate pose in the
    feasibility loop, where ``scipy.spatial.transform`` costs ~30x more per call.
    """
    (r00, r01, r02, px), (r10, r11, r12, py), (r20, r21, r22, pz) = T[:3].tolist()
    tr = r00 + r11 + r22
    if tr > 0.0:
        s = 2.0 * math.sqrt(tr + 1.0)
        q = [(r21 - r12) / s, (r02 - r20) / s, (r10 - r01) / s, 0.25 * s]
    elif r00 >= r11 and r00 >= r22:
        s = 2.0 * math.sqrt(max(1.0 + r00 - r11 - r22, 1e-300))
        q = [0.25 * s, (r01 + r10) / s, (r02 + r20) / s, (r21 - r12) / s]
    elif r11 >= r22:
        s = 2.0 * math.sqrt(max(1.0 + r11 - r00 - r22, 1e-300))
        q = [(r01 + r10) / s, 0.25 * s, (r12 + r21) / s, (r02 - r20) / s]
    else:
        s = 2.0 * math.sqrt(max(1.0 + r22 - r00 - r11, 1e-300))
        q = [(r02 + r20) / s, (r12 + r21) / s, 0.25 * s, (r10 - r01) / s]
    return [px, py, pz], q


def pb_transform(pos: Sequence[float], quat_xyzw: Sequence[float]) -> FloatArray:
    """``(4, 4)`` transform of a PyBullet ``(position, quat_xyzw)`` pair."""
    T = np.eye(4)
    T[:3, :3] = np.reshape(pb.getMatrixFromQuaternion(quat_xyzw), (3, 3))
    T[:3, 3] = pos
    return T


def _body_links(client: int, body: int) -> BodyLinks:
    names = {-1: pb.getBodyInfo(body, physicsClientId=client)[0].decode()}
    for j in range(pb.getNumJoints(body, physicsClientId=client)):
        names[j] = pb.getJointInfo(body, j, physicsClientId=client)[12].decode()
    info = pb.getDynamicsInfo(body, -1, physicsClientId=client)
    return BodyLinks(body, names, pb_transform(info[3], info[4]))


def load_urdf_body(client: int, path: Path, T_world_root: FloatArray, what: str) -> BodyLinks:
    """Load a URDF as a fixed-base body with its root link frame at ``T_world_root``.

    Cylinders stay true cylinders (``URDF_USE_IMPLICIT_CYLINDER``; PyBullet otherwise swaps
    them for coarse convex hulls that under-report distances by millimetres).

    Args:
        client: PyBullet client id.
        path: URDF file.
        T_world_root: ``(4, 4)`` pose of the URDF root link, world frame, m.
        what: ``"robot"`` or ``"tool"``, for error messages.

    Raises:
        URDFError: the file is missing, PyBullet cannot parse it, or it has more links than
            PyBullet can pose (:data:`PYBULLET_MAX_LINKS`); the message names it.
    """
    if not path.is_file():
        raise URDFError(f"{what} URDF not found: {path}")
    pos, quat = pb_pose(T_world_root)
    try:
        with native_chatter_filtered():
            body = pb.loadURDF(
                str(path),
                pos,
                quat,
                useFixedBase=True,
                flags=pb.URDF_USE_IMPLICIT_CYLINDER,
                physicsClientId=client,
            )
    except pb.error as exc:
        raise URDFError(f"cannot load {what} URDF {path}: {exc} (malformed XML?)") from None
    n_links = pb.getNumJoints(body, physicsClientId=client) + 1
    if n_links > PYBULLET_MAX_LINKS:
        pb.removeBody(body, physicsClientId=client)
        raise URDFError(
            f"{what} URDF {path}: {n_links:,} links; PyBullet, the collision engine, keeps the "
            f"state of at most {PYBULLET_MAX_LINKS} links in one body (its pose queries fail "
            "beyond): merge the links joined by fixed joints (a robot arm needs about ten)"
        )
    return _body_links(client, body)


def set_link_pose(client: int, links: BodyLinks, T_world_link: FloatArray) -> None:
    """Move a body so that its base link frame is at ``T_world_link`` (4, 4)."""
    pos, quat = pb_pose(T_world_link @ links.T_link_inertial)
    pb.resetBasePositionAndOrientation(links.body_id, pos, quat, physicsClientId=client)


def world_link_pose(client: int, links: BodyLinks, index: int) -> FloatArray:
    """``T_world_link`` (4, 4) of link ``index`` (``-1``: base) in the current state."""
    if index == -1:
        pos, quat = pb.getBasePositionAndOrientation(links.body_id, physicsClientId=client)
        T_world_inertial = pb_transform(pos, quat)
        return T_world_inertial @ invert_transform(links.T_link_inertial)
    state = pb.getLinkState(
        links.body_id, index, computeForwardKinematics=True, physicsClientId=client
    )
    return pb_transform(state[4], state[5])


def mesh_collision_shape(client: int, mesh: trimesh.Trimesh, concave: bool, source: str) -> int:
    """A PyBullet collision shape of ``mesh`` (metres, body frame).

    Args:
        client: PyBullet client id.
        mesh: the triangle mesh.
        concave: ``True``: an exact static triangle mesh (``GEOM_FORCE_CONCAVE_TRIMESH``, only
            for bodies of mass 0); ``False``: its convex hull.
        source: file or name for error messages.

    Raises:
        MeshError: PyBullet rejects the mesh.
    """
    flags = pb.GEOM_FORCE_CONCAVE_TRIMESH if concave else 0
    try:
        if not concave:
            hull = mesh.convex_hull
            return pb.createCollisionShape(
                pb.GEOM_MESH, vertices=hull.vertices.tolist(), physicsClientId=client
            )
        if len(mesh.vertices) <= MAX_INLINE_VERTICES:
            return pb.createCollisionShape(
                pb.GEOM_MESH,
                vertices=mesh.vertices.tolist(),
                indices=mesh.faces.ravel().tolist(),
                flags=flags,
                physicsClientId=client,
            )
        with tempfile.TemporaryDirectory(prefix="wobjcal_mesh_") as tmp:
            obj = Path(tmp) / "mesh.obj"
            obj.write_text(trimesh.exchange.obj.export_obj(mesh, include_normals=False))
            return pb.createCollisionShape(
                pb.GEOM_MESH, fileName=str(obj), flags=flags, physicsClientId=client
            )
    except pb.error as exc:
        raise MeshError(f"PyBullet cannot use the mesh {source}: {exc}") from None


def static_body(client: int, shape: int, T_world_body: FloatArray, name: str) -> BodyLinks:
    """A static (mass 0) single-link body of collision ``shape`` at ``T_world_body``."""
    pos, quat = pb_pose(T_world_body)
    body = pb.createMultiBody(
        baseMass=0.0,
        baseCollisionShapeIndex=shape,
        basePosition=pos,
        baseOrientation=quat,
        physicsClientId=client,
    )
    return BodyLinks(body, {-1: name}, np.eye(4))
