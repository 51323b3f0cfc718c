"""The stator mesh (:mod:`planner.parts.stator_mesh`): a later build of the same geometry is the
same mesh, as a new object."""

from __future__ import annotations

import dataclasses

import numpy as np
import trimesh

from planner.faces.detection import mesh_digest
from planner.parts.stator import StatorGeometry
from planner.parts.stator_mesh import build_stator_mesh, side_face_grid, triangulate_section


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


def test_the_kept_mesh_is_the_processed_triangulation() -> None:
    """A kept build (``process=False`` from the kept arrays) is the mesh trimesh makes of the
    triangulation with its processing (merged vertices), to the bit."""
    g = StatorGeometry.prototype()
    grid = side_face_grid(g)
    vertices, faces = triangulate_section(grid, g.depth_m)
    front = vertices[:, 0] == 0.0
    vertices[front, 0] = g.side_face_offset_m(vertices[front, 1], vertices[front, 2])
    fresh = trimesh.Trimesh(vertices=vertices, faces=faces, process=True, validate=False)
    kept = build_stator_mesh(g)
    assert np.array_equal(kept.vertices, fresh.vertices)
    assert np.array_equal(kept.faces, fresh.faces)


def test_a_geometry_given_a_list_of_bolt_slots_is_a_key() -> None:
    g = StatorGeometry.prototype()
    listed = dataclasses.replace(g, bolt_slots=list(g.bolt_slots))  # type: ignore[arg-type]
    assert listed.bolt_slots == g.bolt_slots and hash(listed) == hash(g)
    assert mesh_digest(build_stator_mesh(listed)) == mesh_digest(build_stator_mesh(g))
