"""Fixtures of the cell: tables, clamps and other static obstacles, named and placed.

A fixture is a box, a cylinder or a mesh, at ``T_world_fixture``. Box and cylinder frames sit
at the shape's centre (cylinder axis = local z). Mesh fixtures are concave static bodies, like
the work object. Use :func:`table` for the common case of a table top given by its top height.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_positive
from calib.errors import ShapeError
from calib.frames import check_transform, make_transform
from calib.limits import MAX_MESH_TRIANGLES
from planner.cell.scene.bodies import BodyLinks, mesh_collision_shape, static_body
from planner.cell.scene.pybullet_client import pb
from planner.cell.scene.workobject import load_work_object

FloatArray = NDArray[np.float64]
FixtureShape = Literal["box", "cylinder", "mesh"]


@dataclass(frozen=True)
class Fixture:
    """A named static obstacle.

    Attributes:
        name: unique name within the cell, used in collision reasons (e.g. ``"table"``).
        shape: ``"box"``, ``"cylinder"`` or ``"mesh"``.
        T_world_fixture: ``(4, 4)`` pose of the fixture frame, world frame, m.
        size_m: box: ``(3,)`` full edge lengths; cylinder: ``(radius, height)``; mesh: ``()``.
        mesh: mesh in the fixture frame, m (mesh fixtures only).
    """

    name: str
    shape: FixtureShape
    T_world_fixture: FloatArray
    size_m: tuple[float, ...] = ()
    mesh: trimesh.Trimesh | None = field(default=None, repr=False)

    @classmethod
    def box(cls, name: str, size_m: ArrayLike, T_world_fixture: ArrayLike | None = None) -> Fixture:
        """A box of full edge lengths ``size_m`` (3,) m, centred at ``T_world_fixture``."""
        s = np.asarray(size_m, dtype=float).reshape(-1)
        if s.shape != (3,):
            raise ShapeError(f"fixture {name!r}: size_m must be (3,), got {s.shape}")
        sizes = tuple(check_positive(v, f"fixture {name!r} size_m") for v in s)
        return cls(name, "box", _pose(name, T_world_fixture), sizes)

    @classmethod
    def cylinder(
        cls, name: str, radius_m: float, height_m: float, T_world_fixture: ArrayLike | None = None
    ) -> Fixture:
        """A cylinder (axis = local z) centred at ``T_world_fixture``."""
        r = check_positive(radius_m, f"fixture {name!r} radius_m")
        h = check_positive(height_m, f"fixture {name!r} height_m")
        return cls(name, "cylinder", _pose(name, T_world_fixture), (r, h))

    @classmethod
    def from_mesh(
        cls,
        name: str,
        mesh: str | Path | trimesh.Trimesh,
        T_world_fixture: ArrayLike | None = None,
        units: str = "auto",
        max_triangles: int = MAX_MESH_TRIANGLES,
    ) -> Fixture:
        """A mesh fixture (any format trimesh reads; units as for work objects) of at most
        ``max_triangles`` triangles.

        Raises:
            MeshError: missing, unreadable, empty or too large mesh (the message names the file).
        """
        wobj = load_work_object(mesh, units=units, name=name, max_triangles=max_triangles)
        return cls(name, "mesh", _pose(name, T_world_fixture), (), wobj.mesh)

    def create_body(self, client: int) -> BodyLinks:
        """Add the fixture to PyBullet ``client`` as a static body."""
        if self.shape == "box":
            half = [v / 2 for v in self.size_m]
            shape = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=half, physicsClientId=client)
        elif self.shape == "cylinder":
            shape = pb.createCollisionShape(
                pb.GEOM_CYLINDER,
                radius=self.size_m[0],
                height=self.size_m[1],
                physicsClientId=client,
            )
        else:
            if self.mesh is None:
                raise ShapeError(f"fixture {self.name!r} is a mesh fixture without a mesh")
            shape = mesh_collision_shape(client, self.mesh, True, f"fixture {self.name!r}")
        return static_body(client, shape, self.T_world_fixture, self.name)


def fixture_from_spec(name: str, **spec: Any) -> Fixture:
    """A fixture from keywords: ``size_m=`` (box), ``radius_m=`` and ``height_m=`` (cylinder)
    or ``mesh=`` (+ ``units=``), each with an optional ``T_world_fixture=``.

    Raises:
        ShapeError: none of those forms, or bad sizes or pose; MeshError: bad mesh.
    """
    T = spec.get("T_world_fixture")
    if "mesh" in spec:
        limit = int(spec.get("max_triangles", MAX_MESH_TRIANGLES))
        return Fixture.from_mesh(name, spec["mesh"], T, spec.get("units", "auto"), limit)
    if "radius_m" in spec and "height_m" in spec:
        return Fixture.cylinder(name, spec["radius_m"], spec["height_m"], T)
    if "size_m" in spec:
        return Fixture.box(name, spec["size_m"], T)
    raise ShapeError(
        f"fixture {name!r} needs size_m= (box), radius_m= and height_m= (cylinder) or mesh=, "
        f"got {sorted(spec)}"
    )


def table(
    name: str = "table",
    top_z_m: float = 0.0,
    size_m: ArrayLike = (1.0, 1.0, 0.05),
    center_xy_m: ArrayLike = (0.0, 0.0),
) -> Fixture:
    """A table top: a box of ``size_m`` whose upper face lies at height ``top_z_m`` (world z)."""
    s = np.asarray(size_m, dtype=float)
    xy = np.asarray(center_xy_m, dtype=float)
    if xy.shape != (2,):
        raise ShapeError(f"fixture {name!r}: center_xy_m must be (2,), got {xy.shape}")
    T = make_transform(p=[xy[0], xy[1], top_z_m - float(s.reshape(-1)[-1]) / 2])
    return Fixture.box(name, s, T)


def _pose(name: str, T: ArrayLike | None) -> FloatArray:
    if T is None:
        return np.eye(4)
    return check_transform(T, f"fixture {name!r} T_world_fixture")
