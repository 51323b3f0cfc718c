"""STEP/IGES work objects (planner.cad): the unit from the file, B-rep planar faces, bodies,
bad files, and a plan on a STEP part checked and validated as on its STL export.

The reference parts (``../shared/reference/cad``, see its README) are both modelled in inches:
``box_sides.STEP``, a box of 10 bodies about 184 x 114 x 95 mm, and
``base_interface_AP214.STEP``, a plate about 600 x 640 x 4.8 mm (0.6 m, not 600 m).
"""

from __future__ import annotations

import json
import math
import re
import shutil
from collections.abc import Iterator
from pathlib import Path

import msgspec
import numpy as np
import pytest
import shapely
import trimesh

pytest.importorskip("OCP", reason="STEP parts need cadquery-ocp-novtk (pyproject dependencies)")

from calib.models import Misplacement, ProximitySensor
from calib.plan.file import PlanPoint, Pose, Search, file_sha256, load_plan, save_plan
from calib.procedures import ThreeTwoOne
from planner.cad.occt_read import _quiet
from planner.cell import disk_cache
from planner.cell.scene.workobject import load_work_object
from planner.errors import MeshError
from planner.faces.detection import find_planar_faces
from planner.faces.outline import FaceOutlines

REPO = Path(__file__).resolve().parents[3]
TEMPLATE = REPO / "assets" / "plans" / "plate_holes_best_fit.json"
INCH = 0.0254


@pytest.fixture(scope="module")
def cad_dir() -> Path:
    """``../shared/reference/cad``; skips (fails under CI) where it is absent."""
    from tests.reference_data import REFERENCE

    folder = REFERENCE / "cad"
    if not folder.is_dir():
        import os

        message = f"reference CAD parts not found at {folder}"
        if os.environ.get("CI", "").lower() in ("1", "true", "yes"):
            pytest.fail(f"{message} (required under CI)")
        pytest.skip(message)
    return folder


# ---- units and size ---------------------------------------------------------------------------
def test_unit_comes_from_the_file_and_gives_the_real_size(cad_dir: Path) -> None:
    plate = load_work_object(cad_dir / "base_interface_AP214.STEP")
    assert plate.report.units == "in" and not plate.report.units_detected
    assert "declared in the file" in plate.report.units_note
    # every reason about the part says so too, not "given" (helper-55, D10)
    assert plate.report.size_text.endswith("m (file units 'in', declared in the file)")
    # 23.598 x 25.144 x 0.1875 in, read from the file: 0.6 m, not 600 m
    np.testing.assert_allclose(plate.mesh.extents, [0.59941, 0.63866, 0.0047625], atol=2e-5)
    box = load_work_object(cad_dir / "box_sides.STEP", body="all")
    assert box.report.units == "in"
    np.testing.assert_allclose(box.mesh.extents, [7.25 * INCH, 4.5 * INCH, 3.75 * INCH], atol=1e-9)
    assert box.mesh.is_watertight


def test_plan_units_must_agree_with_the_file(cad_dir: Path) -> None:
    path = cad_dir / "base_interface_AP214.STEP"
    assert load_work_object(path, units="in").report.units == "in"
    with pytest.raises(MeshError, match=r"units is 'mm' but the file declares .* as 'in'"):
        load_work_object(path, units="mm")


@pytest.mark.slow
def test_a_second_load_comes_from_the_cache_and_a_broken_cache_only_slows(
    cad_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from planner.cad.part import load_cad_mesh

    path = cad_dir / "base_interface_AP214.STEP"
    monkeypatch.setenv("WOBJCAL_CACHE_DIR", str(tmp_path / "cache"))
    first, info1 = load_cad_mesh(path, cache=disk_cache)
    mesh, info = load_cad_mesh(path, cache=disk_cache)
    assert not info1.cached and (tmp_path / "cache" / "cad_mesh").is_dir()
    np.testing.assert_array_equal(first.vertices, mesh.vertices)  # the cache gives the same
    assert info.cached and info.file_unit == "in" and len(mesh.faces) == 4688
    blocker = tmp_path / "not_a_folder"
    blocker.write_text("a file where the cache folder should be")
    monkeypatch.setenv("WOBJCAL_CACHE_DIR", str(blocker))
    again, info2 = load_cad_mesh(path, cache=disk_cache)
    assert not info2.cached
    np.testing.assert_array_equal(again.faces, mesh.faces)


def test_the_cache_key_holds_the_opencascade_version(
    cad_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Was: keyed by file, body, units and tolerances only: triangles meshed by another
    OpenCASCADE (an upgrade of cadquery-ocp-novtk) were served from the cache."""
    import planner.cad.part as part

    path = cad_dir / "base_interface_AP214.STEP"
    monkeypatch.setenv("WOBJCAL_CACHE_DIR", str(tmp_path / "cache"))
    assert part.mesher_version().startswith("cadquery-ocp")
    part.load_cad_mesh(path, cache=disk_cache)
    assert part.load_cad_mesh(path, cache=disk_cache)[1].cached
    monkeypatch.setattr(part, "mesher_version", lambda: "cadquery-ocp-novtk==99")
    assert not part.load_cad_mesh(path, cache=disk_cache)[1].cached


# ---- planar faces: B-rep against triangle clustering of the same triangles --------------------
def _stl_twin(mesh: trimesh.Trimesh, folder: Path, name: str) -> Path:
    """The CAD part's triangles as a binary STL, metres (what a CAD tool's STL export gives)."""
    plain = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    path = folder / f"{name}.stl"
    plain.export(path)
    return path


def _outline(faces: object, face_id: int, basis: np.ndarray) -> shapely.Geometry:
    """A planar face's triangles projected on ``basis`` and joined (as FaceOutlines does)."""
    tri = np.asarray(faces.mesh.triangles)[faces.face_id == face_id]  # type: ignore[attr-defined]
    return shapely.union_all(shapely.polygons(tri @ basis)).buffer(1e-7)


def _holes(shape: shapely.Geometry) -> int:
    polys = list(shape.geoms) if hasattr(shape, "geoms") else [shape]
    return sum(len(p.interiors) for p in polys)


@pytest.mark.parametrize(("name", "body"), [("base_interface_AP214", None), ("box_sides", "all")])
def test_brep_planar_faces_match_detection_on_the_stl_export(
    cad_dir: Path, tmp_path: Path, name: str, body: str | None
) -> None:
    cad = load_work_object(cad_dir / f"{name}.STEP", body=body)
    stl = load_work_object(_stl_twin(cad.mesh, tmp_path, name), units="m")
    a, b = find_planar_faces(cad.mesh), find_planar_faces(stl.mesh)
    assert len(a.faces) == len(b.faces) > 0
    # a binary STL holds float32 coordinates: the twin's vertices lie up to ~2e-8 m off; faces
    # of equal area (a plate's two sides) may come in either order, so match them by plane
    match = np.full(len(a.faces), -1)
    for i, fa in enumerate(a.faces):
        for j, fb in enumerate(b.faces):
            if (
                float(fa.normal @ fb.normal) > math.cos(1e-6)
                and abs(fa.offset_m - fb.offset_m) < 1e-7
                and fa.area_m2 == pytest.approx(fb.area_m2, rel=1e-6)
            ):
                match[i] = j
        assert fa.rms_m < 1e-8  # exact planes
    assert sorted(match) == list(range(len(b.faces)))  # one to one
    oa = FaceOutlines(a, 0.009)
    for i, j in enumerate(match):
        pa = oa.face(i)  # the B-rep face's outline with its holes, in its plane
        pb = _outline(b, int(j), oa.basis(i))  # the detected one, in the same basis
        assert _holes(pa) == _holes(pb)
        assert pa.symmetric_difference(pb).area < 1e-5 * pa.area  # the same outline
    # the same triangles on the same faces
    mapped = np.where(a.face_id >= 0, match[a.face_id], -1)
    np.testing.assert_array_equal(mapped, b.face_id)


def test_curved_brep_faces_are_never_planar(cad_dir: Path) -> None:
    plate = load_work_object(cad_dir / "base_interface_AP214.STEP")
    planes = plate.mesh.face_attributes["brep_plane"]
    faces = find_planar_faces(plate.mesh)
    assert len(np.unique(planes[planes >= 0])) == 8  # of the plate's 30 B-rep faces
    assert np.all(faces.face_id[planes < 0] == -1)  # its cylinders (bores, arcs) are on none
    assert np.all(faces.region_of[planes < 0] == -1)
    assert {tuple(np.round(f.normal, 9)) for f in faces.faces} == {(0, 0, 1), (0, 0, -1)}


# ---- a plan on the STEP box, and the same plan on its STL export -----------------------------
_SEARCH = Search(kind="approach", start_offset_m=0.030, overtravel_m=0.020, speed_m_s=0.01)
#: 3-2-1 on the box (file frame, mm): top (+z), the long side -y, the short side -x (to the
#: robot); each well inside its face (holes and edges kept clear of the 18 mm footprint).
_POINTS = (
    ("P1", "primary", (40.4, 65.3, 207.8), (0.0, 0.0, 1.0)),
    ("P2", "primary", (140.1, 84.6, 207.8), (0.0, 0.0, 1.0)),
    ("P3", "primary", (73.6, 142.4, 207.8), (0.0, 0.0, 1.0)),
    ("S1", "secondary", (40.4, 46.7, 175.6), (0.0, -1.0, 0.0)),
    ("S2", "secondary", (140.1, 46.7, 175.6), (0.0, -1.0, 0.0)),
    ("T1", "tertiary", (-18.4, 124.1, 181.3), (-1.0, 0.0, 0.0)),
)
#: The box's bottom 10 mm over the template's pedestal (top z 0.74 m, centre x 1.4016 m).
_T_WORLD_WOBJ = Pose(position_m=(1.3279, -0.1039, 0.6374))


def _box_plan(folder: Path, mesh: str, units: str, body: str | None, vias: bool) -> Path:
    rep = msgspec.structs.replace
    template = load_plan(TEMPLATE, check_files=False)  # its plate mesh is replaced
    points = [
        PlanPoint(
            id=pid,
            role=role,
            position_m=(xyz[0] * 1e-3, xyz[1] * 1e-3, xyz[2] * 1e-3),
            normal=n,
            search=_SEARCH,
        )
        for pid, role, xyz, n in _POINTS
    ]
    wo = rep(
        template.work_object,
        mesh=mesh,
        units=units,
        sha256=file_sha256(folder / mesh),
        T_world_wobj=_T_WORLD_WOBJ,
        body=msgspec.UNSET if body is None else body,
    )
    validation = rep(
        template.validation,
        sensor=ProximitySensor(face_diameter_m=0.018),
        misplacement=Misplacement(max_translation_m=0.005, max_angle_rad=math.radians(1.0)),
    )
    plan = rep(
        template,
        name=f"box_{Path(mesh).suffix.lstrip('.').lower()}_321",
        points=points,
        procedure=ThreeTwoOne(),
        work_object=wo,
        validation=validation,
    )
    if vias:
        from planner.check.vias import plan_with_vias
        from planner.plan_cell import open_cell

        with open_cell(plan, folder) as cell:
            plan = plan_with_vias(plan, cell)[0]
    return save_plan(plan, folder / f"{plan.name}.json")


@pytest.fixture(scope="module")
def box_plans(cad_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict]:
    """The 3-2-1 plan on the STEP box (vias added as ``check --add-vias`` adds them) and the
    same plan (same vias) on the STL export of its triangles."""
    folder = tmp_path_factory.mktemp("box")
    shutil.copy(cad_dir / "box_sides.STEP", folder / "box_sides.STEP")
    step = _box_plan(folder, "box_sides.STEP", "auto", "all", vias=True)
    cad = load_work_object(folder / "box_sides.STEP", body="all")
    _stl_twin(cad.mesh, folder, "box_sides")
    plan = load_plan(step)
    wo = msgspec.structs.replace(
        plan.work_object,
        mesh="box_sides.stl",
        units="m",
        sha256=file_sha256(folder / "box_sides.stl"),
        body=msgspec.UNSET,
    )
    stl = save_plan(
        msgspec.structs.replace(plan, name="box_stl_321", work_object=wo), folder / "stl.json"
    )
    yield {"folder": folder, "step": step, "stl": stl}


@pytest.mark.slow
def test_a_plan_on_the_step_box_checks_as_on_its_stl_export(box_plans: dict) -> None:
    from planner.check.job import check_plan

    folder = box_plans["folder"]
    on_step = check_plan(load_plan(box_plans["step"]), folder)
    on_stl = check_plan(load_plan(box_plans["stl"]), folder)
    assert on_step.feasible, on_step.problems()
    assert on_step.problems() == on_stl.problems() == ()
    for a, b in zip(on_step.points, on_stl.points, strict=True):
        assert (a.point_id, a.status, a.reason) == (b.point_id, b.status, b.reason)
    assert on_step.layout_status == on_stl.layout_status


def test_validate_runs_on_the_step_box(box_plans: dict) -> None:
    from planner.validate.job import validate_plan

    report = validate_plan(
        load_plan(box_plans["step"]), trials=4, seed=3, workers=1, plan_dir=box_plans["folder"]
    )
    assert report.n_trials == report.n_ok == 4, report.failures
    # every simulated calibration found the misplaced box within a millimetre
    assert np.abs(report.delta_procedure[:, :3]).max() < 1e-3


@pytest.mark.slow
def test_cli_check_on_a_step_plan_reports_the_files_unit(
    box_plans: dict, capsys: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    """Was: the unit the STEP file declares was only logged at info level, never shown."""
    from planner.cli.main import main

    assert main(["check", str(box_plans["step"])]) == 0
    assert "STEP in 'in' (declared in the file)" in caplog.text  # said on stderr
    capsys.readouterr()
    assert main(["check", str(box_plans["step"]), "--json"]) == 0
    part = json.loads(capsys.readouterr().out)["work_object"]
    assert part["units"] == "in" and "declared in the file" in part["note"]
    assert "0.184 x 0.114 x 0.0953 m" in part["note"]


# ---- bodies ----------------------------------------------------------------------------------
@pytest.mark.slow
def test_a_file_of_several_bodies_needs_a_choice_naming_them(cad_dir: Path) -> None:
    path = cad_dir / "box_sides.STEP"
    with pytest.raises(MeshError, match=r"holds 10 bodies \(0 'box_base', 1 'side_long', 2 "):
        load_work_object(path)
    gusset = load_work_object(path, body="gusset#3")
    by_index = load_work_object(path, body=7)
    np.testing.assert_array_equal(gusset.mesh.vertices, by_index.mesh.vertices)
    assert max(gusset.mesh.extents) < 0.03  # one small gusset of the box, 28 mm
    with pytest.raises(MeshError, match=r"no body named 'lid' \(it holds 10: 0 'box_base'"):
        load_work_object(path, body="lid")
    with pytest.raises(MeshError, match=r"has no body 10 \(it holds 10"):
        load_work_object(path, body=10)


def _write_step(shape: object, path: Path, unit: str = "MM") -> Path:
    from OCP.Interface import Interface_Static
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    with _quiet():
        Interface_Static.SetCVal_s("write.step.unit", unit)
        writer = STEPControl_Writer()
        writer.Transfer(shape, STEPControl_AsIs)
        writer.Write(str(path))
    return path


def _box(dx: float, dy: float, dz: float, x0: float = 0.0) -> object:
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.gp import gp_Pnt

    return BRepPrimAPI_MakeBox(gp_Pnt(x0, 0.0, 0.0), dx, dy, dz).Shape()


def test_a_multi_body_step_made_here(tmp_path: Path) -> None:
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound

    compound = TopoDS_Compound()
    builder = BRep_Builder()
    builder.MakeCompound(compound)
    builder.Add(compound, _box(100.0, 50.0, 20.0))
    builder.Add(compound, _box(30.0, 30.0, 30.0, x0=200.0))
    path = _write_step(compound, tmp_path / "two_blocks.step")
    # one product of two solids: named by the product (here the writer's), .1 and .2
    with pytest.raises(MeshError, match=r"holds 2 bodies \(0 '[^']+\.1', 1 '[^']+\.2'\)"):
        load_work_object(path)
    second = load_work_object(path, body=1)
    np.testing.assert_allclose(second.mesh.extents, [0.03, 0.03, 0.03], atol=1e-12)
    both = load_work_object(path, body="all")
    np.testing.assert_allclose(both.mesh.extents, [0.23, 0.05, 0.03], atol=1e-12)


def test_iges_reads_with_its_unit(tmp_path: Path) -> None:
    from OCP.IGESControl import IGESControl_Writer

    path = tmp_path / "block.igs"
    with _quiet():
        writer = IGESControl_Writer("IN", 1)  # 1: solids (B-rep), not loose faces
        writer.AddShape(_box(4.0, 2.0, 1.0))  # millimetres in, written in inches
        writer.ComputeModel()
        writer.Write(str(path))
    block = load_work_object(path)
    assert block.report.units == "in"
    np.testing.assert_allclose(block.mesh.extents, [0.004, 0.002, 0.001], atol=1e-9)
    assert len(block.mesh.faces) == 12
    assert np.all(block.mesh.face_attributes["brep_plane"] >= 0)


# ---- bad files -------------------------------------------------------------------------------
def test_a_truncated_step_is_named(cad_dir: Path, tmp_path: Path) -> None:
    text = (cad_dir / "base_interface_AP214.STEP").read_bytes()
    cut = tmp_path / "cut.step"
    cut.write_bytes(text[: len(text) // 2])
    with pytest.raises(MeshError, match=r"cut.step: truncated STEP file: .*END-ISO-10303-21"):
        load_work_object(cut)


def test_a_file_that_is_not_step_is_named(tmp_path: Path) -> None:
    bad = tmp_path / "part.stp"
    bad.write_text("solid part\nendsolid\n")
    with pytest.raises(MeshError, match=r"part.stp: not a STEP file"):
        load_work_object(bad)


def test_an_empty_step_and_a_step_named_stl_are_named(cad_dir: Path, tmp_path: Path) -> None:
    """Was: ``not a STEP file (... this one with b'')`` for an empty file, and ``corrupt binary
    STL: its header says 2,020,565,543 triangles`` for a STEP file renamed ``.stl``."""
    empty = tmp_path / "empty.step"
    empty.write_bytes(b"")
    with pytest.raises(MeshError, match=r"empty.step: empty file \(0 bytes\): not a STEP file$"):
        load_work_object(empty)
    renamed = tmp_path / "box.stl"
    shutil.copy(cad_dir / "box_sides.STEP", renamed)
    with pytest.raises(MeshError, match=r"box.stl: a STEP file .* named '.stl': rename it .step"):
        load_work_object(renamed)


def test_a_corrupt_step_is_named(cad_dir: Path, tmp_path: Path) -> None:
    text = (cad_dir / "base_interface_AP214.STEP").read_text()
    mid = len(text) // 2
    bad = tmp_path / "corrupt.step"
    bad.write_text(
        text[:mid] + "\n#9999999 = CARTESIAN_POINT ( 'NONE, ( 1.0, 2.0 ) ) ;" + text[mid:]
    )
    # an unclosed quote swallows the next entity: without the load check the plate loaded
    # with a hole in it (an open mesh and a warning)
    with pytest.raises(MeshError, match=r"corrupt.step: corrupt STEP file: \d+ entities could not"):
        load_work_object(bad)
    bad.write_text(text.replace("DATA;", "DATA"))
    with pytest.raises(MeshError, match=r"corrupt.step: OpenCASCADE cannot parse this STEP file"):
        load_work_object(bad)


def test_a_step_without_a_solid_is_refused(tmp_path: Path) -> None:
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.gp import gp_Pln

    face = BRepBuilderAPI_MakeFace(gp_Pln(), 0.0, 100.0, 0.0, 50.0).Face()
    path = _write_step(face, tmp_path / "sheet.step")
    with pytest.raises(MeshError, match=r"sheet.step: holds no solid body \(1 face in surfaces"):
        load_work_object(path)


def test_a_step_without_a_length_unit_needs_one_from_the_plan(
    cad_dir: Path, tmp_path: Path
) -> None:
    text = (cad_dir / "base_interface_AP214.STEP").read_text()
    bare, n = re.subn(
        r"GLOBAL_UNIT_ASSIGNED_CONTEXT \( \( #\d+, ", "GLOBAL_UNIT_ASSIGNED_CONTEXT ( ( ", text
    )
    assert n == 3
    path = tmp_path / "no_unit.step"
    path.write_text(bare)
    with pytest.raises(MeshError, match=r"no_unit.step: the STEP file declares no length unit"):
        load_work_object(path)
    stated = load_work_object(path, units="in")  # the user says: inches
    np.testing.assert_allclose(stated.mesh.extents, [0.59941, 0.63866, 0.0047625], atol=2e-5)


def test_a_body_on_a_mesh_file_is_an_error(tmp_path: Path) -> None:
    path = tmp_path / "cube.stl"
    trimesh.creation.box((0.1, 0.1, 0.1)).export(path)
    with pytest.raises(MeshError, match=r"body 'all': .*cube.stl is a mesh file"):
        load_work_object(path, body="all")


@pytest.mark.slow
def test_cli_says_a_bad_step_in_one_line(
    box_plans: dict, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from planner.cli.main import main

    plan = load_plan(box_plans["step"])
    shutil.copy(box_plans["folder"] / "box_sides.STEP", tmp_path / "box_sides.STEP")
    wo = msgspec.structs.replace(plan.work_object, body=msgspec.UNSET)
    path = save_plan(msgspec.structs.replace(plan, work_object=wo), tmp_path / "plan.json")
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert "wobjcal check: error: " in err and "holds 10 bodies" in err
    assert "Traceback" not in err


# ---- the web UI's part upload ----------------------------------------------------------------
@pytest.mark.slow
def test_a_step_upload_in_the_ui_takes_the_files_unit(
    cad_dir: Path, tmp_path_factory: pytest.TempPathFactory
) -> None:
    from webui.files_panel import UploadError
    from webui.server import run
    from webui.testing import box_plan, free_port

    folder = tmp_path_factory.mktemp("ui")
    app = run(box_plan(folder), port=free_port(), block=False, autosave_path=folder / "a.json")
    try:
        files = app.files_panel
        files.upload_dir = folder / "kept"
        files.units.value = "mm"  # the user's pick does not apply to a CAD file
        data = (cad_dir / "base_interface_AP214.STEP").read_bytes()
        files.stage_mesh("base_interface_AP214.STEP", data)
        assert "in in (declared in the file): 599.4 x 638.7 x 4.8 mm" in files.pending_md.content
        files.accept_mesh()
        assert app.state.doc.source.work_object.units == "auto"
        np.testing.assert_allclose(app.view.wobj_mesh.extents[:2], [0.5994, 0.6387], atol=1e-4)
        with pytest.raises(UploadError, match=r"box_sides.STEP: holds 10 bodies \(0 'box_base'"):
            files.stage_mesh("box_sides.STEP", (cad_dir / "box_sides.STEP").read_bytes())
    finally:
        app.stop()


def test_a_cad_file_beyond_the_memory_bound_is_refused_before_reading(tmp_path: Path) -> None:
    """Was: a STEP up to the mesh files' 256 MiB was read whole by OpenCASCADE (~12 times
    its size in memory: past the 2 GB budget of issue 27)."""
    from calib.limits import MAX_CAD_FILE_BYTES

    big = tmp_path / "big.step"
    with big.open("wb") as f:
        f.write(b"ISO-10303-21;\nHEADER;\n")
        f.truncate(MAX_CAD_FILE_BYTES + 1)  # sparse: no disk used
    with pytest.raises(MeshError, match=r"big.step: 64.0 MiB, at most 64 MiB for a CAD file"):
        load_work_object(big)
