"""Collision shapes of robot and tool links as PyBullet holds them, in URDF link frames.

The broad phase (:mod:`planner.cell.broad.broad_phase`) covers these shapes with spheres, so they
must be the shapes Bullet checks: read back from the client with ``getCollisionShapeData``
(boxes, implicit cylinders, spheres, capsules, and meshes, which Bullet uses as convex hulls of
their vertices). A shape Bullet holds that is not understood here is ``"unknown"``: its link is
never called clear and always goes to Bullet.

Bullet's shapes differ from the nominal ones by its collision margin (1 mm in PyBullet): boxes
and cylinders are shrunk by it and rounded (Bullet's distances are at least the true ones);
convex hulls and concave triangle meshes are inflated by it (Bullet's distances are up to
1 mm short per inflated side). :attr:`LinkShape.inflation_m` records this for the margins of
the broad phase.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np
import trimesh
from numpy.typing import NDArray

from calib.frames import invert_transform
from planner.cell.scene import BodyLinks, pb, pb_transform, world_link_pose

FloatArray = NDArray[np.float64]
ShapeKind = Literal["box", "cylinder", "sphere", "capsule", "hull", "unknown"]

#: PyBullet's collision margin of convex hulls and concave triangle meshes, m (the URDF
#: importer's ``gUrdfDefaultCollisionMargin``; measured: hull-box distances 1.000 mm short).
BULLET_MESH_MARGIN_M = 0.001
#: How far Bullet's rounded box or cylinder (its shape shrunk by the 1 mm margin, then grown
#: by it again) lies inside the true one at most: ``(sqrt(3) - 1) * 1 mm`` at a box corner,
#: rounded up, m (measured: box-box distances up to 0.727 mm longer than the true ones).
BULLET_ROUNDING_M = 0.00075


@dataclass(frozen=True)
class LinkShape:
    """One collision shape of a link.

    Attributes:
        kind: ``"box"``, ``"cylinder"`` (axis = shape z), ``"sphere"``, ``"capsule"`` (axis =
            shape z), ``"hull"`` (convex hull of ``vertices``) or ``"unknown"``.
        T_link_shape: ``(4, 4)`` shape frame in the URDF link frame, m.
        size_m: box: full extents ``(x, y, z)``; cylinder and capsule: ``(radius, length)``
            (capsule: of the straight part); sphere: ``(radius,)``; hull/unknown: ``()``.
        vertices_m: hull: ``(V, 3)`` vertices in the shape frame, m; else ``None``.
        inflation_m: how far Bullet's shape reaches beyond this one, m.
    """

    kind: ShapeKind
    T_link_shape: FloatArray
    size_m: tuple[float, ...] = ()
    vertices_m: FloatArray | None = None
    inflation_m: float = 0.0


def bullet_excess(shape: LinkShape) -> float:
    """How much Bullet's distance to ``shape`` can exceed the true one, m (rounded corners of
    boxes, cylinders and capsules; 0 for spheres, hulls and meshes, which it grows)."""
    return BULLET_ROUNDING_M if shape.kind in ("box", "cylinder", "capsule") else 0.0


def _link_from_inertial(client: int, links: BodyLinks, index: int) -> FloatArray:
    """``T_link_inertial (4, 4)``: the inertial (centre of mass) frame of a link, link frame."""
    if index == -1:
        return links.T_link_inertial
    state = pb.getLinkState(
        links.body_id, index, computeForwardKinematics=True, physicsClientId=client
    )
    T_world_inertial = pb_transform(state[0], state[1])
    return invert_transform(world_link_pose(client, links, index)) @ T_world_inertial


def _mesh_vertices(filename: bytes, scale: tuple[float, ...]) -> FloatArray | None:
    name = filename.decode(errors="replace")
    path = Path(name)
    if not name or not path.is_file():
        return None
    try:
        mesh = trimesh.load(str(path), force="mesh", process=False)
    except Exception:  # trimesh raises many types for unreadable files
        return None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.vertices) == 0:
        return None
    return np.asarray(mesh.vertices, dtype=float) * np.asarray(scale, dtype=float)


def link_shapes(
    client: int,
    links: BodyLinks,
    index: int,
    hull_vertices: FloatArray | None = None,
) -> tuple[LinkShape, ...]:
    """The collision shapes of link ``index`` of ``links`` (empty when it has none).

    Args:
        client: PyBullet client id.
        links: the body.
        index: link index (``-1``: the base link).
        hull_vertices: ``(V, 3)`` vertices (link frame) of a mesh shape PyBullet made from
            vertices rather than a file (a mesh tool's convex hull).
    """
    data = pb.getCollisionShapeData(links.body_id, index, physicsClientId=client)
    if not data:
        return ()
    T_link_inertial = _link_from_inertial(client, links, index)
    out = []
    for entry in data:
        geom, dims, filename = entry[2], entry[3], entry[4]
        T = T_link_inertial @ pb_transform(entry[5], entry[6])
        if geom == pb.GEOM_BOX:
            out.append(LinkShape("box", T, tuple(float(v) for v in dims[:3])))
        elif geom == pb.GEOM_CYLINDER:
            out.append(LinkShape("cylinder", T, (float(dims[1]), float(dims[0]))))
        elif geom == pb.GEOM_CAPSULE:
            out.append(LinkShape("capsule", T, (float(dims[1]), float(dims[0]))))
        elif geom == pb.GEOM_SPHERE:
            out.append(LinkShape("sphere", T, (float(dims[0]),)))
        elif geom == pb.GEOM_MESH:
            verts = _mesh_vertices(filename, dims)
            if verts is None and hull_vertices is not None and len(data) == 1:
                verts = invert_transform(T)[:3, :3] @ hull_vertices.T
                verts = verts.T + invert_transform(T)[:3, 3]
            if verts is None:
                out.append(LinkShape("unknown", T))
            else:
                out.append(LinkShape("hull", T, (), verts, BULLET_MESH_MARGIN_M))
        else:
            out.append(LinkShape("unknown", T))
    return tuple(out)
