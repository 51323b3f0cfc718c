"""Messages that name the cause (issue 27, items 4 and 5).

Each case printed something that did not name its cause (a bare PyBullet failure, four raw
PyBullet lines and 'malformed XML?', a plausibility error on a coordinate for a unit the format
does not have, every point failing for a reason of its own when the robot stands inside the
part, nothing at all) or said nothing where a user needed to know (a plan without a cell; a
layout whose gross errors ``calibrate`` cannot see). ``docs/bad_inputs.md`` has a row for each.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import trimesh

from calib.errors import InputError
from calib.estimators.gross_errors import detectability
from calib.frames import make_transform, transform_points
from calib.plan.file import load_plan, plan_from_json
from calib.plan.measurements import Measurements, MeasurementsError, measurements_from_json
from calib.probing import ProbePoint
from planner.calibrate.job import calibrate_plan
from planner.check.job import base_in_part, plan_detectability
from planner.check.results import PlanCheck
from planner.errors import URDFError
from planner.plan_cell import default_cell_note, nominal_T_base_wobj
from planner.robot.urdf import load_urdf

ROOT = Path(__file__).resolve().parent.parent
PLATE_321 = ROOT / "assets" / "plans" / "plate_holes_321.json"
PLATE_BEST_FIT = ROOT / "assets" / "plans" / "plate_holes_best_fit.json"
STATOR = ROOT / "assets" / "plans" / "stator_section_ah.json"


# ---- URDF mesh references outside the URDF's folder or package --------------------------------
def _robot(mesh_uri: str) -> str:
    return (
        '<robot name="r"><link name="base"/><link name="arm"><visual><geometry>'
        f'<mesh filename="{mesh_uri}"/></geometry></visual></link>'
        '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        "</robot>"
    )


@pytest.mark.parametrize(
    "uri",
    [
        "/etc/passwd",
        "file:///etc/passwd",
        "package://robot/../../../../../../../../etc/passwd",
        "package://etc/passwd",
        "../../../../../../../../../etc/passwd",
    ],
)
def test_a_mesh_outside_the_urdfs_folder_is_refused_naming_file_link_and_path(
    tmp_path: Path, uri: str
) -> None:
    """Was: four raw PyBullet lines ('invalid mesh filename extension', 'failed to parse
    link') and 'Cannot load URDF file. (malformed XML?)'."""
    urdf = tmp_path / "robot" / "robot.urdf"
    urdf.parent.mkdir()
    urdf.write_text(_robot(uri))
    for check_meshes in (True, False):  # the kinematics read it without meshes: refused too
        with pytest.raises(URDFError) as info:
            load_urdf(urdf, check_meshes=check_meshes)
        text = str(info.value)
        assert str(urdf) in text and "<link name='arm'>" in text and repr(uri) in text
        assert "its own folder or package" in text and "\n" not in text


def test_a_symbolic_link_out_of_the_folder_is_refused(tmp_path: Path) -> None:
    secret = tmp_path / "secret.stl"
    trimesh.creation.box([0.1, 0.1, 0.1]).export(secret)
    folder = tmp_path / "robot"
    folder.mkdir()
    (folder / "arm.stl").symlink_to(secret)
    (folder / "robot.urdf").write_text(_robot("arm.stl"))
    with pytest.raises(URDFError, match=r"'arm.stl' resolves to .*secret\.stl, outside"):
        load_urdf(folder / "robot.urdf")


def test_meshes_inside_the_package_still_load(tmp_path: Path) -> None:
    """A ROS package (``package.xml``) may hold its meshes beside its ``urdf`` folder, and a
    sibling package's mesh is found by ``package://``."""
    pkg = tmp_path / "ws" / "my_robot"
    (pkg / "urdf" / "sub").mkdir(parents=True)
    (pkg / "meshes").mkdir()
    (pkg / "package.xml").write_text("<package/>")
    trimesh.creation.box([0.1, 0.1, 0.1]).export(pkg / "meshes" / "arm.stl")
    other = tmp_path / "ws" / "other_pkg" / "meshes"
    other.mkdir(parents=True)
    trimesh.creation.box([0.1, 0.1, 0.1]).export(other / "arm.stl")
    for uri in ("../../meshes/arm.stl", "package://other_pkg/meshes/arm.stl"):
        urdf = pkg / "urdf" / "sub" / "robot.urdf"
        urdf.write_text(_robot(uri))
        assert load_urdf(urdf).link("arm").visuals[0].geometry.mesh_path is not None


# ---- a URDF with more links than PyBullet can pose ---------------------------------------------
def _chain(path: Path, n_links: int) -> Path:
    links = "\n".join(f'<link name="l{i}"/>' for i in range(n_links))
    joints = "\n".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
        '<origin xyz="0 0 0.001"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        for i in range(1, n_links)
    )
    path.write_text(f'<robot name="chain">\n{links}\n{joints}\n</robot>\n')
    return path


@pytest.fixture
def client() -> Iterator[int]:
    from planner.cell.scene.pybullet_client import connect_direct, pb

    c = connect_direct()
    yield c
    pb.disconnect(physicsClientId=c)


def test_more_links_than_pybullet_poses_is_named(tmp_path: Path, client: int) -> None:
    """Was (5,000 links): 'internal error: error: GetBasePositionAndOrientation failed.'"""
    from planner.cell.scene.bodies import PYBULLET_MAX_LINKS, load_urdf_body, world_link_pose

    ok = load_urdf_body(client, _chain(tmp_path / "ok.urdf", PYBULLET_MAX_LINKS), np.eye(4), "x")
    assert world_link_pose(client, ok, -1).shape == (4, 4)
    long = _chain(tmp_path / "long.urdf", PYBULLET_MAX_LINKS + 1)
    with pytest.raises(URDFError) as info:
        load_urdf_body(client, long, np.eye(4), "robot")
    text = str(info.value)
    assert text.startswith(f"robot URDF {long}: 129 links;") and "at most 128 links" in text


# ---- measurement units the format does not have -----------------------------------------------
def test_units_cm_name_the_field_not_a_coordinate() -> None:
    """Was: 'points.P1[0]: 1330 m is not a plausible coordinate (limit +-1000 m)'."""
    doc = {
        "schema": "wobjcal.measurements/1",
        "units": "cm",
        "plan_digest": "0123456789abcdef",
        "points": {"P1": [1330.0, 7.6, 767.7]},
    }
    with pytest.raises(MeasurementsError) as info:
        measurements_from_json(json.dumps(doc), "m.json")
    assert str(info.value) == (
        "m.json: units: 'cm' is not a unit of this format (m or mm); convert to mm (multiply by 10)"
    )
    for bad in ("furlong", 1000):
        with pytest.raises(MeasurementsError, match=r"m\.json: units: .* \(m or mm\); convert"):
            measurements_from_json(json.dumps({**doc, "units": bad}), "m.json")
    kept = measurements_from_json(json.dumps({**doc, "units": "mm"}), "m.json")
    assert kept.plan_digest == "0123456789abcdef" and kept.scale == 1e-3


# ---- the robot's base inside the part ----------------------------------------------------------
@pytest.fixture(scope="module")
def small_cell() -> Iterator[Any]:
    from planner.cell.cell import Cell

    with Cell(acl_samples=50, use_acl_cache=False) as c:
        yield c


def test_a_base_inside_the_part_is_named_once_as_the_cause(small_cell: Any) -> None:
    """Was: every point failed for a reason of its own ('joint 3 at limit', 'base_link hits
    feeder_body'), the base never named."""
    plate = trimesh.creation.box([0.2, 0.3, 0.0127])
    plate.apply_translation([0.1, 0.15, 0.00635])  # wobj frame at a corner, as the plate's
    small_cell.set_work_object(plate, "m", make_transform(p=[-0.1, -0.15, -0.006]), name="plate")
    text = base_in_part(small_cell)
    assert text.startswith("the robot's base lies inside the work object plate (its origin is")
    assert "(100.0, 150.0, 6.0) mm in the work-object frame" in text
    assert "base_link overlaps the part by" in text and "cell.robot.T_world_base" in text
    check = PlanCheck((), "opw", error=text)
    assert check.problems() == (f"error: {text}",) and not check.feasible
    small_cell.set_work_object(plate, "m", make_transform(p=[1.3, 0.0, 0.6]), name="plate")
    assert base_in_part(small_cell) == ""


# ---- a plan without a cell section -------------------------------------------------------------
def test_a_plan_without_cell_says_so(tmp_path: Path) -> None:
    """Was: the built-in robot and no fixtures, silently."""
    raw = json.loads(PLATE_321.read_text())
    assert default_cell_note(plan_from_json(json.dumps(raw))) == ""
    del raw["cell"]
    note = default_cell_note(plan_from_json(json.dumps(raw)))
    assert note.startswith("plan has no cell section: using the built-in robot irb4400 ")
    assert "built-in tool cable_feeder" in note and "no fixtures" in note
    raw["cell"] = {}  # given, if empty: not the file's silence
    assert default_cell_note(plan_from_json(json.dumps(raw))) == ""


def test_the_cli_notes_a_missing_cell(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from planner.cli.main import main

    raw = json.loads(PLATE_321.read_text())
    del raw["cell"]
    raw["work_object"], raw["points"] = {}, []  # the built-in part: no file to read
    plan = tmp_path / "no_cell.json"
    plan.write_text(json.dumps(raw))
    monkeypatch.chdir(tmp_path)
    main(["export", str(plan), "--format", "json", "-o", str(tmp_path / "out.json")])
    err = capsys.readouterr().err
    assert "wobjcal export: note: plan has no cell section: using the built-in robot" in err


# ---- redundancy: can a gross error be seen? ----------------------------------------------------
def _probes(path: Path) -> list[ProbePoint]:
    return [p.to_probe_point() for p in load_plan(path, check_files=False).points]


def test_a_plain_three_two_one_has_no_redundancy_and_says_how_many_to_add() -> None:
    d = detectability(_probes(PLATE_321))
    assert d.redundancy == 0 and d.unseen == ("P1", "P2", "P3", "S1", "S2", "T1")
    assert d.add == 3 and d.faces == ("P1's face", "S1's face", "T1's face")
    msg = d.message("plate.json")
    assert msg.startswith("6 constraints for 6 degrees of freedom: no redundancy")
    assert "add 3 point(s)" in msg and "`wobjcal suggest plate.json --add 3 -o OUT`" in msg


def test_a_redundant_layout_can_still_hide_a_point() -> None:
    """The shipped A-H plan has 4 redundant constraints, but none on C's face or on the edges
    F and H find: a gross error there moves the frame and leaves no residual."""
    d = detectability(_probes(STATOR))
    assert d.redundancy == 4 and d.unseen == ("C", "F", "H") and d.edge_only == ("F", "H")
    assert d.add == 2 and "F (its edge)" in d.message()
    assert detectability(_probes(PLATE_BEST_FIT)).ok


def test_the_points_to_add_make_every_gross_error_seen() -> None:
    """Adding the counted points on the faces the count names (among each face's points, or
    10 mm beside a face's only point) leaves no point unseen: the count is enough."""
    probes = [p.to_probe_point() for p in load_plan(PLATE_321, check_files=False).points]
    by_id = {p.id: p for p in probes}
    extra = []
    for k, face in enumerate(detectability(probes).faces):
        p = by_id[face.split("'")[0]]
        mates = [q.position_m for q in probes if np.allclose(q.normal, p.normal)]
        if len(mates) > 1:
            pos = np.mean(mates, axis=0)
        else:
            t = np.cross(p.normal, [0.0, 0.0, 1.0])
            pos = np.asarray(p.position_m) + 0.01 * t / np.linalg.norm(t)
        extra.append(ProbePoint(f"X{k}", (pos[0], pos[1], pos[2]), p.normal, p.search))
    assert len(extra) == 3 and detectability([*probes, *extra]).ok


def test_check_json_and_the_calibrate_note_say_it(tmp_path: Path) -> None:
    """Was: check said nothing; calibrate noted 'no redundancy' but not what to do."""
    plan = load_plan(PLATE_321, check_files=False)
    d = plan_detectability(plan)
    assert d is not None
    data = PlanCheck((), "opw", detectability=d).to_json()["redundancy"]
    assert data["redundant"] == 0 and data["add"] == 3 and "no redundancy" in data["note"]
    T = nominal_T_base_wobj(plan)
    pts = {
        p.id: transform_points(
            T, np.asarray(p.position_m) + (0.005 * np.asarray(p.normal) if p.id == "P1" else 0.0)
        )
        for p in plan.points
    }
    out = calibrate_plan(plan, Measurements.from_points_m(pts, units="mm"))
    (note,) = out.notes
    assert "no redundancy" in note and "add 3 point(s) to make it detectable" in note


@pytest.mark.reference
def test_the_ui_layout_panel_says_it() -> None:
    from webui.layout_panel import redundancy_markdown
    from webui.plan_adapter import ui_plan_from_plan

    text = redundancy_markdown(ui_plan_from_plan(load_plan(PLATE_321, check_files=False)))
    assert text.startswith("**Redundancy:** 6 constraints for 6 degrees of freedom")
    assert "*Add best point* 3 time(s)" in text
    assert redundancy_markdown(ui_plan_from_plan(load_plan(PLATE_BEST_FIT))) == ""


def test_suggest_add_grows_a_three_two_one_plan_into_a_best_fit() -> None:
    """Was: `suggest --add N` refused a 3-2-1 plan ('added points need the best fit'), so the
    command the redundancy line names could not run."""
    from calib.procedures import PROCEDURES
    from planner.suggest import as_procedure

    plan = load_plan(PLATE_321, check_files=False)
    grown = as_procedure(plan, PROCEDURES["best_fit"])
    assert grown.method == "best_fit" and {p.role for p in grown.points} == {"fit"}
    assert [p.position_m for p in grown.points] == [p.position_m for p in plan.points]


def test_a_plan_with_an_x_offset_run_is_not_grown_into_a_best_fit() -> None:
    """Was: the A-H plan's redundancy line named `suggest --add 2`, which wrote a best fit of ten
    points without the paper's x-offset run: a plan that places no slot. Now the line says why
    no point can be added, and `--add` refuses the plan naming it."""
    from planner.suggest import suggest_plan

    plan = load_plan(STATOR)
    d = plan_detectability(plan)
    assert d is not None and d.unseen == ("C", "F", "H") and d.add == 2
    note = d.message()
    assert "x-offset run" in note and "--add" not in note, note
    with pytest.raises(InputError, match="--add: the plan's hultman2013 procedure takes exactly"):
        suggest_plan(plan, STATOR.parent, add=2)
    plate = load_plan(PLATE_321, check_files=False)
    assert plate.fixed_points() == ""
    assert "--add 3" in (plan_detectability(plate) or d).message()
