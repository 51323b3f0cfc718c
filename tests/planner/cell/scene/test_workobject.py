"""Tests of planner.cell.scene.workobject: formats, units, repair, errors and the concave PyBullet
body."""

from __future__ import annotations

import logging

import numpy as np
import pybullet as pb
import pytest
import trimesh

from calib.frames import make_transform
from planner import builtins
from planner.cell.scene.workobject import load_work_object
from planner.errors import MeshError, UnknownBuiltinError


def test_plate_in_mm_is_detected_with_a_warning(reference_dir, caplog) -> None:
    path = reference_dir / "parts" / "plate_holes.STL"
    with caplog.at_level(logging.WARNING, logger="planner.cell.scene.workobject"):
        wobj = load_work_object(path)
    r = wobj.report
    assert (r.units, r.units_detected, r.scale) == ("mm", True, 1e-3)
    # 8 x 12 x 0.5 inch
    np.testing.assert_allclose(sorted(wobj.mesh.extents), [0.0127, 0.2032, 0.3048], atol=1e-6)
    assert r.watertight and r.boundary_edges == 0
    assert r.merged_vertices > 0  # binary STL stores every triangle's corners separately
    assert "read as 'mm'" in caplog.text and "plate_holes.STL" in caplog.text
    assert wobj.name == "plate_holes"
    # the plate has 5 through-holes: genus 5, so Euler characteristic 2 - 2 * 5
    assert wobj.mesh.euler_number == 2 - 2 * 5


def test_explicit_units(reference_dir) -> None:
    path = reference_dir / "parts" / "plate_holes.STL"
    inch = load_work_object(path, units="inch")  # wrong on purpose: 25.4x the mm size
    assert inch.mesh.extents.max() == pytest.approx(304.8 * 0.0254, rel=1e-6)
    assert not inch.report.units_detected
    with pytest.raises(MeshError, match=r"furlong"):
        load_work_object(path, units="furlong")


def test_metre_mesh_is_kept_in_metres() -> None:
    box = trimesh.creation.box([0.3, 0.2, 1.5])
    wobj = load_work_object(box)
    assert wobj.report.units == "m" and wobj.report.units_detected
    assert wobj.report.warnings == (wobj.report.units_note,)  # says what it assumed
    assert "units 'auto' read as 'm'" in wobj.report.units_note
    assert "the part is 0.3 x 0.2 x 1.5 m" in wobj.report.units_note


# ---- units (issue 10, item 4) ----------------------------------------------------------------
def test_auto_reads_the_plate_as_mm_and_says_so(reference_dir) -> None:
    w = load_work_object(reference_dir / "parts" / "plate_holes.STL", units="auto", reach_m=1.89)
    assert w.report.units == "mm"
    assert "read as 'mm'" in w.report.units_note and "reach 1.89 m" in w.report.units_note
    assert "0.203 x 0.305 x 0.0127 m" in w.report.units_note
    assert w.report.size_text == "0.203 x 0.305 x 0.0127 m (file units 'mm', detected)"


def test_auto_reads_a_part_drawn_in_inches(tmp_path) -> None:
    """Item 4: a 5 x 2.5 x 1.4 in part was read as a 5 m block that swallows the robot."""
    box = trimesh.creation.box([5.0, 2.5, 1.4])
    box.export(tmp_path / "bracket.stl")
    w = load_work_object(tmp_path / "bracket.stl", units="auto", reach_m=1.89)
    assert w.report.units == "in"
    np.testing.assert_allclose(sorted(w.mesh.extents), sorted([0.127, 0.0635, 0.03556]))
    assert "the file names no unit" in w.report.units_note
    # the file's own hint wins when it gives a plausible part: 50 numbers are mm without it
    big = trimesh.creation.box([50.0, 25.0, 14.0])
    big.export(tmp_path / "frame.stl")
    assert load_work_object(tmp_path / "frame.stl", reach_m=1.89).report.units == "mm"
    big.export(tmp_path / "frame_inch.stl")
    w = load_work_object(tmp_path / "frame_inch.stl", units="auto", reach_m=1.89)
    assert w.report.units == "in" and "the file names 'in'" in w.report.units_note
    # a hint that gives no plausible part is overruled, and said
    box.export(tmp_path / "bracket_mm.stl")
    w = load_work_object(tmp_path / "bracket_mm.stl", units="auto", reach_m=1.89)
    assert w.report.units == "in" and "names 'mm', but that gives 0.005 m" in w.report.units_note


def test_explicit_units_that_make_no_sense_are_said(reference_dir) -> None:
    w = load_work_object(reference_dir / "parts" / "plate_holes.STL", units="m", reach_m=1.89)
    assert w.report.units == "m"
    (warning,) = w.report.warnings
    assert "read in 'm' the part is 304.8 m across" in warning
    assert "'mm' would make it 0.305 m" in warning


def test_raw_scan_loads_with_a_report(reference_dir) -> None:
    wobj = load_work_object(reference_dir / "parts" / "noether_raw_mesh.ply")
    r = wobj.report
    assert not r.watertight
    assert r.boundary_edges > 3000
    assert r.removed_degenerate_faces == 2
    assert any("open mesh" in w for w in r.warnings)
    assert r.n_faces == len(wobj.mesh.faces) > 50_000


def test_winding_of_a_closed_mesh_is_fixed() -> None:
    box = trimesh.creation.box([0.2, 0.2, 0.2])
    box.invert()  # all normals inward
    assert box.volume < 0
    wobj = load_work_object(box, units="m")
    assert wobj.report.fixed_winding
    assert wobj.mesh.volume == pytest.approx(0.008)


@pytest.mark.parametrize("ext", ["obj", "ply", "glb", "stl"])
def test_formats_trimesh_reads(tmp_path, ext) -> None:
    box = trimesh.creation.box([0.1, 0.2, 0.3])
    path = tmp_path / f"part.{ext}"
    box.export(path)
    wobj = load_work_object(path, units="m")
    np.testing.assert_allclose(sorted(wobj.mesh.extents), [0.1, 0.2, 0.3], atol=1e-9)
    assert wobj.mesh.volume == pytest.approx(0.006)


def test_bad_meshes_name_the_file(tmp_path) -> None:
    with pytest.raises(MeshError, match=r"missing\.stl"):
        load_work_object(tmp_path / "missing.stl")
    garbage = tmp_path / "garbage.stl"
    garbage.write_bytes(b"\x00\x01 this is not a mesh" * 3)
    with pytest.raises(MeshError, match=r"garbage\.stl"):
        load_work_object(garbage)
    empty = tmp_path / "empty.obj"
    empty.write_text("# no faces\n")
    with pytest.raises(MeshError, match=r"empty\.obj"):
        load_work_object(empty)
    nan = trimesh.creation.box([1, 1, 1])
    nan.vertices[3, 1] = np.nan
    with pytest.raises(MeshError, match=r"NaN"):
        load_work_object(nan)
    with pytest.raises(MeshError, match=r"empty"):
        load_work_object(trimesh.Trimesh())


@pytest.mark.parametrize("cut", ["after a facet", "in a facet"])
def test_an_ascii_stl_cut_short_is_named_so(tmp_path, cut: str) -> None:
    """helper-55 (D11): an ASCII STL cut in a copy was 'no triangle could be read from its
    58,692 bytes' although it held hundreds of facets."""
    box = trimesh.creation.box([0.1, 0.2, 0.3])
    text = trimesh.exchange.stl.export_stl_ascii(box)
    end = [i for i in range(len(text)) if text.startswith("endfacet", i)][4] + len("endfacet\n")
    path = tmp_path / "cut.stl"
    path.write_text(text[:end] if cut == "after a facet" else text[: end + 30])
    with pytest.raises(MeshError, match=r"cut\.stl: an ASCII STL cut short: 5 whole facets"):
        load_work_object(path, units="m")
    whole = tmp_path / "whole.stl"
    whole.write_text(text)
    assert len(load_work_object(whole, units="m").mesh.faces) == 12


def cube_mesh() -> trimesh.Trimesh:
    """A 0.1 m cube: a built-in part factory for the registry test."""
    return trimesh.creation.box([0.1, 0.1, 0.1])


def test_builtin_part_registry(monkeypatch: pytest.MonkeyPatch) -> None:
    """A part is one factory plus one table entry; unknown names list the valid ones."""
    monkeypatch.setitem(
        builtins.BUILTIN_PARTS, "test_cube", builtins.BuiltinPart(f"{__name__}:cube_mesh")
    )
    assert "builtin:test_cube" in builtins.builtin_part_names()
    wobj = load_work_object("builtin:test_cube")
    assert wobj.name == "test_cube"
    assert wobj.mesh.volume == pytest.approx(1e-3)
    with pytest.raises(UnknownBuiltinError, match=r"builtin:stator_section.*builtin:test_cube"):
        load_work_object("builtin:no_such_part")


def test_concave_body_does_not_fill_holes() -> None:
    """A sphere inside a ring's hole is clear of the exact mesh; the convex hull swallows it."""
    ring = trimesh.creation.annulus(r_min=0.05, r_max=0.2, height=0.1)
    wobj = load_work_object(ring, units="m")
    client = pb.connect(pb.DIRECT)
    try:
        body = wobj.create_body(client, make_transform(p=[1.0, 0.0, 0.0]))
        sphere = pb.createMultiBody(
            0,
            pb.createCollisionShape(pb.GEOM_SPHERE, radius=0.02, physicsClientId=client),
            basePosition=[1.0, 0.0, 0.0],
            physicsClientId=client,
        )
        pts = pb.getClosestPoints(sphere, body.body_id, 0.1, physicsClientId=client)
        clear = min(p[8] for p in pts)
        hull = pb.createMultiBody(
            0,
            pb.createCollisionShape(
                pb.GEOM_MESH, vertices=ring.vertices.tolist(), physicsClientId=client
            ),
            basePosition=[1.0, 0.0, 0.0],
            physicsClientId=client,
        )
        blocked = min(p[8] for p in pb.getClosestPoints(sphere, hull, 0.1, physicsClientId=client))
    finally:
        pb.disconnect(client)
    # 0.05 hole radius - 0.02 sphere radius, less the chord error of the polygonal hole
    assert clear == pytest.approx(0.03, abs=1e-3)
    assert blocked < -0.05


def test_large_mesh_goes_through_a_file(monkeypatch) -> None:
    """Above the inline vertex limit the body is built from a temporary OBJ, same geometry."""
    import planner.cell.scene.bodies

    box = trimesh.creation.box([0.5, 0.5, 0.5]).subdivide().subdivide()
    monkeypatch.setattr(planner.cell.scene.bodies, "MAX_INLINE_VERTICES", 10)
    wobj = load_work_object(box, units="m")
    client = pb.connect(pb.DIRECT)
    try:
        body = wobj.create_body(client, np.eye(4))
        sphere = pb.createMultiBody(
            0,
            pb.createCollisionShape(pb.GEOM_SPHERE, radius=0.01, physicsClientId=client),
            basePosition=[0.0, 0.0, 0.30],
            physicsClientId=client,
        )
        d = min(
            p[8] for p in pb.getClosestPoints(sphere, body.body_id, 0.1, physicsClientId=client)
        )
    finally:
        pb.disconnect(client)
    assert d == pytest.approx(0.04, abs=1e-6)


# ---- bad mesh files (issue 10, items 7 and 8) -------------------------------------------------
def test_bad_mesh_files_say_what_is_wrong(tmp_path) -> None:
    import os

    rand = tmp_path / "random.stl"
    rand.write_bytes(os.urandom(2000))
    with pytest.raises(
        MeshError, match=r"corrupt binary STL: its header says .* the file has 2,000"
    ):
        load_work_object(rand)
    ascii_ = tmp_path / "garbage.stl"
    ascii_.write_text("solid x\nfacet garbage\n")
    with pytest.raises(MeshError, match=r"no triangle could be read from its 22 bytes"):
        load_work_object(ascii_)
    with pytest.raises(MeshError, match=r"is a directory, not a mesh file"):
        load_work_object(tmp_path)
    with pytest.raises(MeshError, match=r"/dev/zero: not a regular file"):
        load_work_object("/dev/zero")


def test_a_five_million_triangle_mesh_is_refused_before_parsing(tmp_path) -> None:
    """Item 7: 5 million triangles took 145 s and 7.2 GB to say 'no planar face'. A binary STL's
    header gives the count: refused at once, with the number (a sparse file, nothing parsed)."""
    import time

    n = 5_000_000
    path = tmp_path / "scan.stl"
    with path.open("wb") as handle:
        handle.write(b"\0" * 80 + n.to_bytes(4, "little"))
        handle.truncate(84 + 50 * n)
    t0 = time.perf_counter()
    with pytest.raises(MeshError, match=r"scan\.stl: 5,000,000 triangles; wobjcal takes at most"):
        load_work_object(path)
    assert time.perf_counter() - t0 < 5.0
