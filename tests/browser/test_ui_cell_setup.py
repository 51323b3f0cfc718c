"""Issue 22, item 1 in Chromium: the Cell tab sets up the whole cell. Fixtures (box, cylinder)
are added and deleted, the sensor's numbers and the search speed applied, a mesh tool uploaded
with its TCP and a built-in tool's TCP chosen, all through the page's own fields and buttons;
each change shows on the page (the lists, the fields, the re-checked status rows), is saved in
the autosaved plan, and is one undo step."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import trimesh
from ui_helpers import (
    TIMEOUT_S,
    UiSession,
    act_until,
    choose,
    close_notifications,
    open_tab,
    save_screenshot,
    set_camera,
    wait_for,
)


def _inputs(page: Any, handle: Any) -> Any:
    """The inputs of a viser widget (a number or text: one; a vector: one per component),
    found from its label as a user finds them."""
    label = page.locator(f'label[for="{handle._impl.uuid}"]')
    return label.locator("xpath=ancestor::div[contains(@class, 'mantine-Flex-root')][1]//input")


def _type(page: Any, handle: Any, values: tuple[float | str, ...]) -> None:
    """Type ``values`` into the inputs of ``handle`` as a user does, and wait until the server
    has them."""
    fields = _inputs(page, handle)

    def typed() -> None:
        for i, v in enumerate(values):
            field = fields.nth(i)
            field.fill(f"{v}")
            field.press("Tab")

    def arrived() -> bool:
        got = handle.value if len(values) > 1 else (handle.value,)
        return all(str(g) == str(v) or g == v for g, v in zip(got, values, strict=True))

    act_until(typed, arrived, what=f"{handle.label} typed")


def _body(ui: UiSession) -> str:
    return str(ui.page.inner_text("body"))


def _saved(ui: UiSession) -> dict[str, Any]:
    """The autosaved plan, once the file holds the document the server shows."""
    assert ui.app.state.wait_saved(timeout=TIMEOUT_S), ui.app.state.last_autosave_error
    return dict(json.loads(ui.app.state.autosave_path.read_text()))


def _all_checked(ui: UiSession) -> bool:
    return len(ui.app.checks()) == len(ui.app.state.doc.points)


def _undo(ui: UiSession, gone: Any, what: str) -> None:
    open_tab(ui.page, "Points")
    ui.page.get_by_role("button", name="Undo", exact=True).click()
    wait_for(gone, what=what)


def test_a_cylinder_is_added_then_deleted_and_bad_sizes_are_refused(ui: UiSession) -> None:
    app, page = ui.app, ui.page
    open_tab(page, "Cell")
    fixtures = app.cell_panel.fixtures
    close_notifications(page)
    choose(page, "Shape", "cylinder")
    wait_for(lambda: fixtures.cylinder.visible, what="the cylinder's fields")
    _type(page, fixtures.name, ("",))
    _type(page, fixtures.position, (1600.0, 0.0, 1300.0))
    _type(page, fixtures.cylinder, (-5.0, 200.0))
    before = app.state.doc
    page.get_by_role("button", name="Add fixture").click()
    wait_for(
        lambda: "cylinder radius: must be > 0 mm, got -5" in ui.notifications(),
        what="the refusal on the page",
    )
    assert app.state.doc is before, "nothing changed"
    close_notifications(page)
    _type(page, fixtures.cylinder, (50.0, 200.0))
    page.get_by_role("button", name="Add fixture").click()
    wait_for(lambda: app.state.doc.source.cell.fixtures, what="the cylinder in the plan")
    spec = app.state.doc.source.cell.fixtures[0]
    assert spec.name == "cylinder" and spec.cylinder == pytest.approx((0.05, 0.2))
    assert _saved(ui)["cell"]["fixtures"][0]["cylinder_m"] == pytest.approx([0.05, 0.2])
    mesh, T = app.view.fixtures["cylinder"]
    np.testing.assert_allclose(mesh.extents, [0.1, 0.1, 0.2], atol=1e-3)
    np.testing.assert_allclose(T[:3, 3], [1.6, 0.0, 1.3])
    fixture_field = page.get_by_label("Fixture", exact=True)
    wait_for(lambda: fixture_field.input_value() == "cylinder", what="cylinder listed")
    wait_for(lambda: _all_checked(ui), what="the points checked with the cylinder")
    page.get_by_role("button", name="Delete fixture").click()
    wait_for(lambda: app.state.doc.source.cell.fixtures == [], what="deleted")
    wait_for(lambda: fixture_field.input_value() == "(no fixture)", what="none listed")
    assert "cylinder" not in app.view.fixtures and _saved(ui)["cell"]["fixtures"] == []
    _undo(ui, lambda: len(app.state.doc.source.cell.fixtures) == 1, "undo of the delete")
    _undo(ui, lambda: app.state.doc.source.cell.fixtures == [], "undo of the add")


def test_a_mesh_fixture_is_uploaded_in_its_units(ui: UiSession, tmp_path: Path) -> None:
    app, page = ui.app, ui.page
    open_tab(page, "Cell")
    fixtures = app.cell_panel.fixtures
    path = tmp_path / "clamp.stl"
    trimesh.creation.box(extents=(80.0, 60.0, 40.0)).export(path)  # mm
    _type(page, fixtures.position, (1500.0, 300.0, 1000.0))
    choose(page, "Fixture mesh units", "mm")
    with page.expect_file_chooser() as fc:
        page.get_by_role("button", name="Upload fixture mesh").click()
    fc.value.set_files(str(path))
    fixture_field = page.get_by_label("Fixture", exact=True)
    wait_for(lambda: fixture_field.input_value() == "clamp", what="the clamp listed")
    spec = app.state.doc.source.cell.fixtures[0]
    assert (spec.units, spec.box_size_m) == ("mm", None) and spec.sha256 is not None
    saved = _saved(ui)["cell"]["fixtures"][0]
    assert saved["mesh"] == spec.mesh and saved["units"] == "mm"
    wait_for(lambda: "clamp" in app.view.fixtures, what="the clamp in the cell")
    np.testing.assert_allclose(app.view.fixtures["clamp"][0].extents, [0.08, 0.06, 0.04])
    _undo(ui, lambda: app.state.doc.source.cell.fixtures == [], "undo of the clamp")


def test_the_sensor_and_search_speed_apply_in_one_step(ui: UiSession) -> None:
    app, page = ui.app, ui.page
    open_tab(page, "Cell")
    sensor = app.cell_panel.sensor
    wait_for(lambda: _all_checked(ui), what="the points checked")
    before = app.state.doc
    _type(page, sensor.diameter, (12.0,))
    _type(page, sensor.range, (5.0,))
    _type(page, sensor.speed, (20.0,))
    assert app.state.doc is before, "typing alone changes nothing"
    page.get_by_role("button", name="Apply sensor").click()
    wait_for(
        lambda: app.state.doc.source.validation.sensor.face_diameter_m == pytest.approx(0.012),
        what="the sensor in the plan",
    )
    s = _saved(ui)
    assert s["validation"]["sensor"]["sensing_distance_m"] == pytest.approx(0.005)
    assert [p["search"]["speed_m_s"] for p in s["points"]] == pytest.approx([0.02] * 6)
    wait_for(lambda: _all_checked(ui), what="every point checked again")
    # the built-in tool's sensor TCP lies 8 mm in front of its face: a 5 mm sensor is named
    disagree = page.get_by_text("Sensor and tool disagree")
    disagree.wait_for(state="visible", timeout=30_000)
    assert "3.0 mm off along its normal" in page.inner_text("body")
    _undo(ui, lambda: app.state.doc is before, "one undo step")
    disagree.wait_for(state="detached", timeout=30_000)
    open_tab(page, "Cell")
    diameter = _inputs(page, sensor.diameter)
    wait_for(lambda: float(diameter.input_value()) == 18.0, what="the page shows 18 mm again")
    assert float(_inputs(page, sensor.speed).input_value()) == 10.0
    # a touch probe: the detection range is not its number
    choose(page, "Sensor kind", "touch")
    wait_for(lambda: float(diameter.input_value()) == 6.0, what="the touch probe's ball")
    wait_for(lambda: sensor.range.disabled, what="no range for a touch probe")
    page.get_by_role("button", name="Apply sensor").click()
    wait_for(lambda: app.state.doc.source.validation.sensor.KIND == "touch", what="touch")
    assert _saved(ui)["validation"]["sensor"]["kind"] == "touch"
    _undo(ui, lambda: app.state.doc is before, "back to the proximity sensor")


def test_a_mesh_tool_is_uploaded_with_its_tcp_and_a_tcp_chosen(
    ui: UiSession, tmp_path: Path
) -> None:
    app, page = ui.app, ui.page
    open_tab(page, "Cell")
    tool = app.cell_panel.tool
    before = app.state.doc
    mesh = trimesh.creation.cylinder(radius=30.0, height=150.0)
    mesh.apply_translation((0.0, 0.0, 75.0))
    path = tmp_path / "probe_tool.stl"
    mesh.export(path)
    _type(page, tool.mesh_tcp, (0.0, 0.0, 158.0))
    choose(page, "Tool mesh units", "mm")
    with page.expect_file_chooser() as fc:
        page.get_by_role("button", name="Upload tool").click()
    fc.value.set_files(str(path))
    tool_field = page.get_by_label("Tool", exact=True)
    wait_for(lambda: tool_field.input_value().startswith("file: probe_tool"), what="the tool")
    wait_for(lambda: "Tool: probe_tool" in _body(ui), what="its summary on the page")
    assert page.get_by_label("TCP", exact=True).input_value() == "sensor"
    ref = app.state.doc.source.cell.tool.name
    assert ref.endswith(".tool.json") and _saved(ui)["cell"]["tool"]["name"] == ref
    desc = json.loads(Path(ref).read_text())
    assert desc["tcp_frames"]["sensor"]["position_m"] == pytest.approx([0.0, 0.0, 0.158])
    assert app.view.tool_mesh is not None and app.view.tool_urdf is None
    wait_for(lambda: _all_checked(ui), what="the points checked with the new tool")
    # back to the built-in tool, probing with a tube's TCP
    choose(page, "Tool", "builtin:cable_feeder")
    choose(page, "TCP", "tube_1")
    page.get_by_role("button", name="Apply tool").click()
    wait_for(lambda: app.state.doc.source.cell.tool.tcp == "tube_1", what="the built-in's tube_1")
    wait_for(lambda: "probing with TCP tube_1" in _body(ui), what="said on the page")
    assert _saved(ui)["cell"]["tool"] == {"name": "builtin:cable_feeder", "tcp": "tube_1"}
    _undo(ui, lambda: app.state.doc.source.cell.tool.name == ref, "undo to the mesh tool")
    _undo(ui, lambda: app.state.doc is before, "undo to the first tool")
    wait_for(lambda: app.view.tool_urdf is not None, what="the cable feeder back in the cell")


def test_a_box_fixture_blocks_a_point_and_undo_takes_it_away(ui: UiSession, tmp_path: Path) -> None:
    """Last in the module: the screenshot hides the page's notifications from then on."""
    app, page = ui.app, ui.page
    wait_for(lambda: _all_checked(ui), what="the points checked")
    assert "hits block" not in (app.check_of("P1").reason or "")
    open_tab(page, "Cell")
    fixtures = app.cell_panel.fixtures
    choose(page, "Shape", "box")
    _type(page, fixtures.name, ("block",))
    _type(page, fixtures.position, (1600.0, 0.0, 850.0))  # over P1, world mm
    _type(page, fixtures.box_size, (100.0, 100.0, 100.0))
    page.get_by_role("button", name="Add fixture").click()
    wait_for(
        lambda: [f.name for f in app.state.doc.source.cell.fixtures] == ["block"],
        what="the fixture in the plan",
    )
    # the page: the new fixture chosen under Fixture and as the Move target
    fixture_field = page.get_by_label("Fixture", exact=True)
    wait_for(lambda: fixture_field.input_value() == "block", what="block listed")
    wait_for(
        lambda: page.get_by_label("Move", exact=True).input_value() == "fixture: block",
        what="block to move",
    )
    # saved in the plan (autosave), as a box of 100 mm at (1600, 0, 850) mm
    saved = _saved(ui)["cell"]["fixtures"]
    assert saved[0]["name"] == "block" and saved[0]["box_size_m"] == pytest.approx([0.1] * 3)
    assert saved[0]["T_world_fixture"]["position_m"] == pytest.approx([1.6, 0.0, 0.85])
    assert "cylinder_m" not in saved[0]
    # re-checked at once: P1's row says the tool hits the block
    wait_for(lambda: "hits block" in app.check_of("P1").reason, what="P1 blocked (server)")
    if app.check_of("P1").q is not None:  # the robot at P1's pose, its tool in the block
        app.select("P1")
        app.robot_to_selected()
    set_camera(ui.client(), (2.7, -1.1, 1.6), (1.5, 0.05, 0.9))
    save_screenshot(page, "cell_setup.png", tmp_path)
    open_tab(page, "Points")
    wait_for(lambda: "hits block" in _body(ui), what="P1's row on the page")
    _undo(ui, lambda: app.state.doc.source.cell.fixtures == [], "undo of the fixture")
    wait_for(lambda: "block" not in app.view.fixtures, what="the old cell back")
    wait_for(lambda: "hits block" not in _body(ui), what="P1's row without the block")
    open_tab(page, "Cell")
    wait_for(lambda: fixture_field.input_value() == "(no fixture)", what="no fixture listed")
    assert _saved(ui)["cell"]["fixtures"] == []
