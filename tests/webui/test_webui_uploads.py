"""Uploading a part and a robot, server side (issue 14, item 5): the size in the chosen units
before accepting, points off the new surface listed, projected or dropped; a URDF zipped with
its meshes; errors name the user's file."""

from __future__ import annotations

import io
import re
import zipfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from calib.errors import InputError
from webui.app import WobjcalApp
from webui.part_upload import OFF_SURFACE_M
from webui.server import run
from webui.testing import box_plan, free_port


@pytest.fixture(scope="module")
def app(tmp_path_factory: pytest.TempPathFactory) -> Iterator[WobjcalApp]:
    folder = tmp_path_factory.mktemp("uploads")
    a = run(box_plan(folder), port=free_port(), block=False, autosave_path=folder / "auto.json")
    a.files_panel.upload_dir = folder / "kept"
    yield a
    a.stop()


def test_a_part_waits_for_its_units_with_its_size_shown(
    app: WobjcalApp, reference_dir: Path
) -> None:
    files = app.files_panel
    before = app.state.doc
    data = (reference_dir / "parts" / "plate_holes.STL").read_bytes()
    files.units.value = "mm"
    files.stage_mesh("plate_holes.STL", data)
    assert app.state.doc is before, "nothing changes before the part is accepted"
    assert "plate_holes.STL in mm: 203.2 x 304.8 x 12.7 mm" in files.pending_md.content
    files.units.value = "m"  # the size follows the units at once
    assert "203200.0 x 304800.0 x 12700.0 mm" in files.pending_md.content
    files.units.value = "auto"
    assert "auto picks mm" in files.pending_md.content
    files.units.value = "mm"
    files.accept_mesh()
    assert app.state.doc.source.work_object.units == "mm"
    np.testing.assert_allclose(app.view.wobj_mesh.extents, [0.2032, 0.3048, 0.0127], atol=1e-6)
    assert files.pending is None and not files.accept.visible
    # the box plan's points are not on the plate: listed with their distances
    assert set(files.off) == set(app.state.doc.ids)
    assert all(d > OFF_SURFACE_M for d in files.off.values())
    assert "Points off the new part's surface:" in files.off_md.content
    files.fix_off_surface("project")
    picker = app.picker
    for p in app.state.doc.points:
        assert picker.project(p.probe.position_m).distance_m < 1e-9
    assert files.off == {} and not files.project_off.visible
    app.state.undo()  # the projection
    files._list_off_surface()
    files.fix_off_surface("drop")
    assert app.state.doc.points == ()
    app.state.undo()
    app.state.undo()  # the new part
    np.testing.assert_allclose(app.view.wobj_mesh.extents, [0.6, 0.4, 0.3], atol=1e-9)


def test_the_points_off_the_part_are_of_the_plan_shown(
    app: WobjcalApp, reference_dir: Path
) -> None:
    """helper-56 (D4): after a new part listed A-H off its surface, loading another plan kept
    the list (and "Project them" said no points were off): the list follows the plan."""
    files = app.files_panel
    data = (reference_dir / "parts" / "plate_holes.STL").read_bytes()
    files.units.value = "mm"
    files.stage_mesh("plate_holes.STL", data)
    files.accept_mesh()
    assert files.off and "Points off the new part's surface:" in files.off_md.content
    other = box_plan(app.plan_dir, name="other_plan")  # its mesh beside the app's plan
    files.upload_plan(other.name, other.read_bytes())
    assert files.off == {} and files.off_md.content == "" and not files.project_off.visible
    app.state.undo()  # the plan: the plate again, its points off it listed again
    assert set(files.off) == set(app.state.doc.ids) and files.project_off.visible
    app.state.undo()  # the new part: the box, the points on it
    assert files.off == {} and files.off_md.content == ""
    app.state.redo()  # the plate again (review, helper-57: the list was the box's here)
    assert set(files.off) == set(app.state.doc.ids)
    app.state.undo()
    assert files.off == {}
    np.testing.assert_allclose(app.view.wobj_mesh.extents, [0.6, 0.4, 0.3], atol=1e-9)


def test_a_bad_part_is_refused_naming_the_users_file(app: WobjcalApp) -> None:
    before = app.state.doc
    with pytest.raises(InputError, match=r"broken_part\.stl") as info:
        app.files_panel.stage_mesh("broken_part.stl", b"solid x\nendsolid x\n")
    assert str(app.files_panel.upload_dir) not in str(info.value), "no internal cache path"
    assert app.state.doc is before and app.files_panel.pending is None


def _ur5_zip(reference_dir: Path, drop: str | None = None) -> bytes:
    """The reference UR5 as a ROS package zip: ``package://ur_description/...`` references."""
    root = reference_dir / "robots" / "ur5"
    text = (root / "ur5.urdf").read_text()
    text = re.sub(r'filename="(meshes/[^"]+)"', r'filename="package://ur_description/\1"', text)
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        z.writestr("ur_description/urdf/ur5.urdf", text)
        for stl in sorted((root / "meshes" / "collision").glob("*.stl")):
            if stl.name != drop:
                z.write(stl, f"ur_description/meshes/collision/{stl.name}")
    return buf.getvalue()


@pytest.mark.slow
def test_a_robot_zip_brings_its_meshes(app: WobjcalApp, reference_dir: Path) -> None:
    files = app.files_panel
    files.upload_urdf("ur5_package.zip", _ur5_zip(reference_dir))
    try:
        assert app.view.chain is not None and app.view.chain.n_joints == 6
        urdf = Path(app.state.doc.source.cell.robot.urdf)
        assert urdf.is_file() and files.upload_dir in urdf.parents
        assert 'filename="package://' not in urdf.read_text()
        assert app.robot is not None, "the robot is drawn from the zip's meshes"
    finally:
        app.state.undo()
    before = app.state.doc
    with pytest.raises(InputError, match=r"ur5_missing\.zip: .*refers to .*wrist3\.stl"):
        files.upload_urdf("ur5_missing.zip", _ur5_zip(reference_dir, drop="wrist3.stl"))
    assert app.state.doc is before
    evil = io.BytesIO()
    with zipfile.ZipFile(evil, "w") as z:
        z.writestr("../escape.urdf", "<robot name='x'/>")
    with pytest.raises(InputError, match="unsafe path"):
        files.upload_urdf("evil.zip", evil.getvalue())
    with pytest.raises(InputError, match="not a zip"):
        files.upload_urdf("fake.zip", b"not a zip at all")


def _with_frame(app: WobjcalApp, T_wobj_mesh: np.ndarray) -> None:
    """Give the session plan's part a 3-point frame (``work_object.T_wobj_mesh``)."""
    import msgspec

    from calib.plan.cell import Pose

    source = app.state.doc.source
    wo = msgspec.structs.replace(source.work_object, T_wobj_mesh=Pose.from_matrix(T_wobj_mesh))
    app.replace_source(msgspec.structs.replace(source, work_object=wo), "3-point frame")


@pytest.mark.slow
def test_a_new_part_starts_with_its_own_frame_unless_the_frame_is_kept(
    app: WobjcalApp, reference_dir: Path
) -> None:
    """Issue 14: a new part kept the earlier part's 3-point frame (``T_wobj_mesh``) and came
    in shifted and turned by it; now it starts with the identity and the notice says so."""
    from calib.frames import make_transform, matrix_from_rotvec

    files = app.files_panel
    data = (reference_dir / "parts" / "plate_holes.STL").read_bytes()
    T_old = make_transform(matrix_from_rotvec([0.0, 0.0, 0.7]), [0.05, -0.02, 0.01])
    _with_frame(app, T_old)
    undo_depth = 1
    try:
        np.testing.assert_allclose(app.state.doc.source.work_object.mesh_matrix(), T_old)
        files.units.value = "mm"
        files.keep_frame.value = False
        files.stage_mesh("plate_holes.STL", data)
        said = files.accept_mesh()
        undo_depth += 1
        assert app.state.doc.source.work_object.mesh_pose is None, "identity: the file's frame"
        assert "file's own" in said and "not kept" in said, said
        # the part lies in the wobj frame as in its file (mm -> m), not moved by T_old
        lo = app.view.wobj_mesh.bounds[0]
        plate_lo = np.array([0.0, 0.0, 0.0])  # the plate's file has its corner at the origin
        np.testing.assert_allclose(lo, plate_lo, atol=1e-6)
        app.state.undo()
        undo_depth -= 1
        np.testing.assert_allclose(app.state.doc.source.work_object.mesh_matrix(), T_old)
        files.keep_frame.value = True  # the user chooses to keep it
        files.stage_mesh("plate_holes.STL", data)
        said = files.accept_mesh()
        undo_depth += 1
        np.testing.assert_allclose(app.state.doc.source.work_object.mesh_matrix(), T_old)
        assert "is kept" in said, said
    finally:
        files.keep_frame.value = False
        for _ in range(undo_depth):
            app.state.undo()


def test_uploads_no_plan_uses_are_removed(app: WobjcalApp, reference_dir: Path) -> None:
    """Issue 27: every upload stayed in ~/.cache/wobjcal/uploads for ever, the refused and the
    cancelled ones too; a 10,000-point plan uploaded drove the server past 9 GB."""
    import hashlib
    import json

    import trimesh

    files = app.files_panel
    box = trimesh.creation.box(extents=(0.5, 0.35, 0.25))  # a part no earlier test used
    box.apply_translation((0.0, 0.0, -0.125))
    data = box.export(file_type="stl")
    files.units.value = "m"
    files.stage_mesh("block.stl", data)
    staged = files.pending.path.parent  # type: ignore[union-attr]
    assert staged.is_dir()
    files.cancel_mesh()
    assert not staged.exists(), "a cancelled upload is removed"
    broken, missing = b"solid y\nendsolid y\n", _ur5_zip(reference_dir, drop="wrist2.stl")
    with pytest.raises(InputError):
        files.stage_mesh("broken_part.stl", broken)
    with pytest.raises(InputError, match="refers to"):
        files.upload_urdf("ur5_missing.zip", missing)
    for refused in (broken, missing):
        folder = files.upload_dir / hashlib.sha256(refused).hexdigest()[:16]
        assert not folder.exists(), "a refused upload is removed"
    files.stage_mesh("block.stl", data)
    files.accept_mesh()  # used by the plan: kept, also once the pending part is gone
    used = Path(app.state.doc.source.work_object.mesh)
    files.close()
    assert used.is_file(), "the session's plan (and its autosave) uses it"
    app.state.undo()
    files.close()  # the end of a session whose plan no longer uses it
    assert not used.exists()
    doc = json.loads((Path(app.plan_dir) / "box_plan.json").read_text())
    doc["points"] = [dict(doc["points"][i % 6], id=f"Q{i}") for i in range(10_000)]
    before = app.state.doc
    with pytest.raises(InputError, match=r"10,000 points, at most 500"):
        files.upload_plan("big.json", json.dumps(doc).encode())
    assert app.state.doc is before
