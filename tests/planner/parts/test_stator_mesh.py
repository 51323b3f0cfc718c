"""The stator mesh (:mod:`planner.parts.stator_mesh`): a later build of the same geometry is the
same mesh, as a new object."""

from __future__ import annotations

from planner.faces.detection import mesh_digest
from planner.parts.stator import StatorGeometry
from planner.parts.stator_mesh import build_stator_mesh


def test_a_second_build_is_a_new_mesh_with_the_same_triangles() -> None:
    """The triangulation is kept per geometry (validate builds the part twice): a later build
    is the same mesh, and a new object the caller may move without changing the next one."""
    g = StatorGeometry.prototype()
    a, b = build_stator_mesh(g), build_stator_mesh(g)
    assert a is not b and mesh_digest(a) == mesh_digest(b)
    assert a.is_watertight and b.is_watertight
    b.apply_translation([1.0, 0.0, 0.0])
    assert mesh_digest(build_stator_mesh(g)) == mesh_digest(a)
    flat = build_stator_mesh(g, deformed=False)
    assert mesh_digest(flat) != mesh_digest(a)  # the bulge is part of the key
