"""Issue 22, item 1, pure parts: fixtures added (box, cylinder, mesh) and deleted, the plan's
cylinder fixture (validation, round trip, older plans' bytes kept), the mesh tool description
(load and its errors), the tool and the sensor edits."""

from __future__ import annotations

import dataclasses
import json
import re
from pathlib import Path

import msgspec
import numpy as np
import pytest
import trimesh

from calib.errors import InputError, PlanError
from calib.frames import make_transform, matrix_from_tait_bryan_zyx
from calib.models import ProximitySensor, TouchProbe
from calib.plan.cell import FixtureSpec, Pose
from calib.plan.file import load_plan, plan_digest, plan_from_json, plan_to_json
from planner.cell.scene.tool import load_tool, mesh_tool_description
from planner.errors import MeshError, UnknownFrameError, URDFError
from webui import cell_setup_edits as edits
from webui.plan_adapter import plan_point, ui_plan_from_plan
from webui.testing import box_plan

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def plan_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return box_plan(tmp_path_factory.mktemp("setup"))


# ---- fixtures ------------------------------------------------------------------------------
def test_add_box_cylinder_and_delete(plan_path: Path) -> None:
    plan = load_plan(plan_path)
    box = edits.box_fixture(plan, "block", (100, 200, 50), (1600, 0, 850))
    assert box.box_size_m == pytest.approx((0.1, 0.2, 0.05))
    assert box.T_world_fixture.position_m == pytest.approx((1.6, 0.0, 0.85))
    plan2 = edits.with_fixture(plan, box)
    name = edits.free_fixture_name(plan2, "block")
    assert name == "block_2"
    cyl = edits.cylinder_fixture(plan2, "cylinder", 50, 200, (1600, 0, 950))
    assert cyl.cylinder == pytest.approx((0.05, 0.2)) and cyl.shape == "cylinder"
    plan3 = edits.with_fixture(plan2, cyl)
    assert edits.fixture_names(plan3) == ("block", "cylinder")
    with pytest.raises(InputError, match="'block' is in the cell already"):
        edits.box_fixture(plan3, "block", (1, 1, 1), (0, 0, 0))
    with pytest.raises(InputError, match="1 to 64 letters"):
        edits.box_fixture(plan3, "", (1, 1, 1), (0, 0, 0))
    plan4 = edits.without_fixture(plan3, "block")
    assert edits.fixture_names(plan4) == ("cylinder",)
    with pytest.raises(InputError, match=r"no fixture 'nope' to delete \(fixtures: cylinder\)"):
        edits.without_fixture(plan4, "nope")
    assert plan.cell.fixtures == []  # the edits are pure


def test_bad_sizes_give_one_clear_message(plan_path: Path) -> None:
    plan = load_plan(plan_path)
    with pytest.raises(InputError, match=r"^cylinder radius: must be > 0 mm, got -5"):
        edits.cylinder_fixture(plan, "c", -5, 100, (0, 0, 0))
    with pytest.raises(InputError, match=r"^cylinder length: must be > 0 mm, got nan"):
        edits.cylinder_fixture(plan, "c", 5, float("nan"), (0, 0, 0))
    with pytest.raises(InputError, match=r"^box size: must be 3 lengths > 0 mm"):
        edits.box_fixture(plan, "b", (10, 0, 10), (0, 0, 0))
    with pytest.raises(InputError, match="1e\\+06 m is not a plausible coordinate"):
        edits.box_fixture(plan, "b", (10, 10, 10), (1e9, 0, 0))
    with pytest.raises(InputError, match="mesh units: must be one of"):
        edits.mesh_fixture(plan, "m", "x.stl", "furlong", "0" * 64, (0, 0, 0))


def test_cylinder_spec_validation() -> None:
    with pytest.raises(PlanError, match=r"^cylinder_m: must be \(radius, length\) > 0"):
        FixtureSpec(name="c", cylinder_m=(-0.1, 0.2))
    with pytest.raises(PlanError, match="exactly one of mesh, box_size_m and cylinder_m"):
        FixtureSpec(name="c", cylinder_m=(0.1, 0.2), box_size_m=(1.0, 1.0, 1.0))
    with pytest.raises(PlanError, match="exactly one of mesh, box_size_m and cylinder_m"):
        FixtureSpec(name="c")
    with pytest.raises(PlanError, match="sha256: must be null for a cylinder"):
        FixtureSpec(name="c", cylinder_m=(0.1, 0.2), sha256="0" * 64)


def test_cylinder_in_a_plan_file_names_the_json_path(plan_path: Path) -> None:
    raw = json.loads(plan_path.read_text())
    raw["cell"]["fixtures"] = [{"name": "post", "mesh": None, "cylinder_m": [0.05, -1.0]}]
    with pytest.raises(PlanError, match=r"cell\.fixtures\[0\].*cylinder_m: must be"):
        plan_from_json(json.dumps(raw))
    raw["cell"]["fixtures"] = [{"name": "post", "cylinder_m": [0.05]}]
    with pytest.raises(PlanError, match=r"cell\.fixtures\[0\]\.cylinder_m: must have length 2"):
        plan_from_json(json.dumps(raw))


def test_plan_round_trip_with_a_cylinder(plan_path: Path, tmp_path: Path) -> None:
    plan = load_plan(plan_path)
    cyl = edits.cylinder_fixture(plan, "post", 50, 200, (1600, 0, 950))
    plan2 = edits.with_fixture(plan, cyl)
    text = plan_to_json(plan2)
    assert '"cylinder_m": [\n' in text
    back = plan_from_json(text)
    assert back == plan2 and plan_to_json(back) == text
    assert back.cell.fixtures[0].cylinder == pytest.approx((0.05, 0.2))


def test_older_plans_keep_their_bytes_and_digest(plan_path: Path) -> None:
    """A plan without cylinders writes no ``cylinder_m``: its bytes and digest hold."""
    for path in [REPO / "tests" / "data" / "golden" / "stator_ah.plan.json", plan_path]:
        text = path.read_text()
        plan = plan_from_json(text)
        assert "cylinder_m" not in plan_to_json(plan)
        assert plan_to_json(plan) == text
    golden = REPO / "tests" / "data" / "golden" / "stator_ah.plan.json"
    plan = plan_from_json(golden.read_text())
    box = FixtureSpec(name="table", box_size_m=(1.0, 1.0, 1.0))
    assert "cylinder_m" not in json.dumps(msgspec.to_builtins(box))
    assert plan_digest(plan) == plan_digest(plan_from_json(plan_to_json(plan)))


def test_the_cell_builds_a_cylinder_fixture(plan_path: Path) -> None:
    from planner.plan_cell import open_cell

    plan = load_plan(plan_path)
    cyl = edits.cylinder_fixture(plan, "post", 50, 200, (1600, 0, 950))
    with open_cell(edits.with_fixture(plan, cyl), plan_path.parent) as cell:
        f = cell.fixtures["post"]
        assert f.shape == "cylinder" and f.size_m == pytest.approx((0.05, 0.2))
        np.testing.assert_allclose(f.T_world_fixture[:3, 3], [1.6, 0.0, 0.95])


# ---- the mesh tool description -------------------------------------------------------------
def _tool_mesh(folder: Path) -> Path:
    mesh = trimesh.creation.cylinder(radius=30.0, height=150.0)
    mesh.apply_translation((0.0, 0.0, 75.0))
    path = folder / "probe.stl"
    mesh.export(path)
    return path


def test_mesh_tool_description_loads(tmp_path: Path) -> None:
    mesh = _tool_mesh(tmp_path)
    R = matrix_from_tait_bryan_zyx(0.0, np.radians(10.0), 0.0)
    T = make_transform(R, [0.0, 0.01, 0.158])
    text = mesh_tool_description(
        mesh.name, {"sensor": T}, units="mm", sensor_tcp="sensor", name="probe",
        sensor_links=("probe",),
    )  # fmt: skip
    desc = tmp_path / "probe.tool.json"
    desc.write_text(text)
    tool = load_tool(desc)
    assert tool.name == "probe" and tool.urdf_path is None and tool.sensor_tcp == "sensor"
    assert tool.tcp_names == ["flange", "sensor"] and tool.sensor_links == ("probe",)
    np.testing.assert_allclose(tool.T_flange_tcp("sensor"), T, atol=1e-12)
    np.testing.assert_allclose(tool.mesh.bounds, [[-0.03, -0.03, 0.0], [0.03, 0.03, 0.15]])


@pytest.mark.parametrize(
    ("change", "error", "match"),
    [
        ({"colour": "red"}, URDFError, "unknown key 'colour'"),
        ({"sensing_distance_m": 0.008}, URDFError, "the sensor's numbers are the plan's"),
        ({"urdf": "x.urdf"}, URDFError, "either urdf .* or mesh .*, not both"),
        ({"mesh": "../probe.stl"}, URDFError, "mesh must be a file name relative"),
        ({"mesh": "none.stl"}, MeshError, "none.stl"),
        ({"tcp_frames": {}}, URDFError, "tcp_frames must map TCP names to poses"),
        (
            {"tcp_frames": {"sensor": {"position_m": [0, 0]}}},
            URDFError,
            r"tcp_frames\.sensor: .*position_m: must have length 3",
        ),
        (
            {"tcp_frames": {"sensor": {"quat_wxyz": [2, 0, 0, 0]}}},
            URDFError,
            r"tcp_frames\.sensor: quat_wxyz: must be a unit vector",
        ),
        ({"sensor_tcp": "tip"}, UnknownFrameError, r"sensor_tcp 'tip' is not one of tcp_frames"),
        ({"sensor_links": ["body"]}, URDFError, "sensor_links of a mesh tool may only name"),
        ({"units": "furlong"}, MeshError, "furlong"),
        ({"schema": "wobjcal.tool/9"}, URDFError, "schema 'wobjcal.tool/9' is not"),
    ],
)
def test_mesh_tool_description_errors(
    tmp_path: Path, change: dict[str, object], error: type[Exception], match: str
) -> None:
    mesh = _tool_mesh(tmp_path)
    desc = json.loads(
        mesh_tool_description(mesh.name, {"sensor": np.eye(4)}, "mm", "sensor", "probe")
    )
    desc.update(change)
    path = tmp_path / "bad.tool.json"
    path.write_text(json.dumps(desc))
    with pytest.raises(error, match=match) as info:
        load_tool(path)
    assert "\n" not in str(info.value)  # one line, one message


def test_the_builtin_tool_description_still_loads() -> None:
    tool = load_tool("builtin:cable_feeder")
    assert tool.sensor_tcp == "sensor" and "sensor_body" in tool.sensor_links


# ---- the tool and the sensor edits ---------------------------------------------------------
def test_tool_edit_and_tcp_choice(plan_path: Path, tmp_path: Path) -> None:
    plan = load_plan(plan_path)
    mesh = _tool_mesh(tmp_path)
    desc = tmp_path / "probe.tool.json"
    desc.write_text(mesh_tool_description(mesh.name, {"tip": np.eye(4)}, "mm", None, "probe"))
    tool = load_tool(desc)
    assert edits.tcp_choice(tool, "sensor") == "tip"  # the old TCP is not on this tool
    assert edits.tcp_choice(tool, "flange") == "flange"
    assert edits.tcp_choice(load_tool("builtin:cable_feeder"), "tube_1") == "tube_1"
    plan2 = edits.with_tool(plan, str(desc), "tip")
    assert (plan2.cell.tool.name, plan2.cell.tool.tcp) == (str(desc), "tip")
    assert plan2.cell.tool.mount == plan.cell.tool.mount


def test_sensor_edit_in_mm_and_the_search_speed(plan_path: Path) -> None:
    ui = ui_plan_from_plan(load_plan(plan_path))
    fields = edits.sensor_fields(ui)
    assert fields == edits.SensorFields("proximity", 18.0, 8.0, 0.04, 10.0)
    ui2 = edits.with_sensor(ui, edits.SensorFields("proximity", 12.0, 5.0, 0.02, None))
    sensor = ui2.source.validation.sensor
    assert isinstance(sensor, ProximitySensor)
    assert sensor.face_diameter_m == pytest.approx(0.012)
    assert sensor.sensing_distance_m == pytest.approx(0.005)
    assert sensor.repeatability_sigma_m == pytest.approx(2e-5)
    assert sensor.n_rays == ProximitySensor().n_rays  # the rest kept
    assert ui2.points == ui.points  # speed None: each point keeps its own
    ui3 = edits.with_sensor(ui2, edits.SensorFields("touch", 4.0, 0.0, 0.001, 25.0))
    probe = ui3.source.validation.sensor
    assert isinstance(probe, TouchProbe) and probe.tip_diameter_m == pytest.approx(0.004)
    assert probe.trigger_repeatability_sigma_m == pytest.approx(1e-6)
    assert [p.speed_m_s for p in ui3.points] == pytest.approx([0.025] * len(ui3.points))
    assert plan_point(ui3.points[0]).search.speed_m_s == pytest.approx(0.025)
    assert edits.sensor_fields(ui3).kind == "touch"
    with pytest.raises(InputError, match=r"^detection range \(mm\): must be > 0, got 0"):
        edits.with_sensor(ui, edits.SensorFields("proximity", 18.0, 0.0, 0.04, None))
    with pytest.raises(InputError, match=r"^search speed \(mm/s\): must be > 0, got -1"):
        edits.with_sensor(ui, edits.SensorFields("proximity", 18.0, 8.0, 0.04, -1.0))
    unknown = r"^unknown sensor kind \(validation\.sensor\.kind\) 'laser'; known: proximity, touch$"
    with pytest.raises(InputError, match=unknown):
        edits.with_sensor(ui, edits.SensorFields("laser", 18.0, 8.0, 0.04, None))


def test_mesh_fixture_spec(plan_path: Path) -> None:
    plan = load_plan(plan_path)
    spec = edits.mesh_fixture(plan, "clamp", "/tmp/clamp.stl", "mm", "a" * 64, (10, 20, 30))
    assert spec.shape == "mesh" and spec.units == "mm" and spec.sha256 == "a" * 64
    assert spec.T_world_fixture == Pose(position_m=(0.01, 0.02, 0.03))


def test_an_older_description_with_sensor_keys_still_loads(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """Before ``wobjcal.tool/1`` the docs asked for ``sensing_distance_m`` and
    ``sensor_diameter_m`` in a tool JSON and the loader ignored extra keys: such a file (no
    ``schema``) still loads, the keys ignored and said so in the log."""
    builtin = Path(load_tool("builtin:cable_feeder").urdf_path or "")
    desc = {
        "name": "old_feeder",
        "urdf": str(builtin),
        "tcps": ["sensor"],
        "sensor_tcp": "sensor",
        "sensor_links": ["sensor_body"],
        "sensing_distance_m": 0.008,
        "sensor_diameter_m": 0.018,
        "description": "written for wobjcal 0.1",
    }
    path = tmp_path / "old.tool.json"
    path.write_text(json.dumps(desc))
    with caplog.at_level("WARNING", logger="planner.cell.scene.tool"):
        tool = load_tool(path)
    assert tool.name == "old_feeder" and tool.sensor_tcp == "sensor"
    assert "sensing_distance_m" in caplog.text and "ignored" in caplog.text


@pytest.mark.parametrize(
    ("field", "value", "says"),
    [
        ("speed_mm_s", 1e9, "search speed (mm/s): at most 250 mm/s"),
        ("range_mm", 1000.0, "detection range (mm): at most 50 mm"),
        ("diameter_mm", 1e6, "diameter (mm): at most 100 mm"),
        ("noise_mm", 1000.0, "noise 1 sigma (mm): at most 5 mm"),
    ],
)
def test_implausible_sensor_numbers_are_refused_naming_the_field(
    plan_path: Path, field: str, value: float, says: str
) -> None:
    ui = ui_plan_from_plan(load_plan(plan_path))
    fields = dataclasses.replace(edits.sensor_fields(ui), **{field: value})
    with pytest.raises(InputError, match=re.escape(says)):
        edits.with_sensor(ui, fields)


def test_a_detection_range_the_tool_does_not_have_is_named() -> None:
    """The built-in cable feeder's sensor TCP lies 8 mm in front of its sensor's face (a ray
    back from the TCP into the tool): a 5 mm sensor is 3 mm off, and said so."""
    from planner.cell.scene.tool_face import gap_mismatch, sensor_face_gap_m

    tool = load_tool("builtin:cable_feeder")
    assert sensor_face_gap_m(tool) == pytest.approx(0.008, abs=1e-9)
    assert gap_mismatch(tool, 0.008) == ""
    why = gap_mismatch(tool, 0.005)
    assert "8.0 mm in front of its sensor face" in why and "3.0 mm off" in why
