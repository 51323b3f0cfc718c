"""Issue 14 in Chromium, on the demo: cell setup (item 1) and jog and teach (item 2), driven
through the page's own fields and buttons; every test checks the server's state."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from ui_helpers import UiSession, act_until, open_tab, save_screenshot, set_camera, wait_for

from calib.frames import transform_points
from webui.cell_edits import WORK_OBJECT, pose_of
from webui.plan_doc import PAPER_IDS


def _input_of(page: Any, handle: Any) -> Any:
    """The (first) number input of a viser vector or slider widget."""
    first = page.locator(f'[id="{handle._impl.uuid}"]')
    if first.evaluate("e => e.tagName") == "INPUT":
        return first
    return first.locator("xpath=following-sibling::*//input").first


def test_typing_a_position_and_applying_moves_the_part(demo: UiSession) -> None:
    app, page = demo.app, demo.page
    open_tab(page, "Cell")
    panel = app.cell_panel
    assert panel.target.value == WORK_OBJECT
    T0 = pose_of(app.state.doc.source, WORK_OBJECT)
    x_mm = round(T0[0, 3] * 1000.0 + 50.0, 3)
    field = _input_of(page, panel.position)
    field.fill(f"{x_mm}")
    field.press("Tab")
    wait_for(lambda: abs(panel.position.value[0] - x_mm) < 1e-6, what="x on the server")
    page.get_by_role("button", name="Apply pose").click()
    wait_for(
        lambda: abs(app.view.T_world_wobj[0, 3] - T0[0, 3] - 0.05) < 1e-9, what="the part moved"
    )
    wait_for(lambda: len(app.checks()) == 8, what="every point checked in the new cell")
    # the cell is rebuilt before the plan changes: undo only once the change is in the plan
    wait_for(
        lambda: abs(pose_of(app.state.doc.source, WORK_OBJECT)[0, 3] - T0[0, 3] - 0.05) < 1e-9,
        what="the move in the plan",
    )
    open_tab(page, "Points")
    page.get_by_role("button", name="Undo", exact=True).click()
    wait_for(lambda: np.allclose(app.view.T_world_wobj, T0, atol=1e-12), what="undo")


def test_snap_button_rests_the_part_on_the_table(demo: UiSession) -> None:
    app, page = demo.app, demo.page
    open_tab(page, "Cell")
    T0 = pose_of(app.state.doc.source, WORK_OBJECT)
    mesh, T_table = app.view.fixtures["table"]
    top = transform_points(T_table, mesh.vertices)[:, 2].max()

    def resting() -> bool:
        low = transform_points(app.view.T_world_wobj, app.view.wobj_mesh.vertices)[:, 2].min()
        return abs(low - top) < 1e-9

    snap = page.get_by_role("button", name="Snap part onto fixture")
    act_until(snap.click, resting, what="the part on the table")  # snapping again: no change
    # the cell is rebuilt before the plan changes: undo only once the change is in the plan
    wait_for(lambda: not np.allclose(pose_of(app.state.doc.source, WORK_OBJECT), T0), what="plan")
    app.state.undo()
    wait_for(lambda: np.allclose(app.view.T_world_wobj, T0, atol=1e-12), what="undo")


def test_jog_slider_and_teach_in_the_page(demo: UiSession, tmp_path: Path) -> None:
    app, page = demo.app, demo.page
    panel = app.teach_panel
    app.select("D")
    check = wait_for(lambda: app.check_of("D"), what="D's check")
    open_tab(page, "Teach")
    to_point = page.get_by_role("button", name="Jog to selected point")
    act_until(to_point.click, lambda: np.allclose(panel.q, check.q), what="the robot at D's pose")
    j1 = _input_of(page, panel.sliders[0])
    want = round(float(np.degrees(check.q[0])) + 2.0, 1)  # the slider step: 0.1 deg

    def jog_j1() -> None:
        j1.fill(f"{want}")
        j1.press("Tab")

    act_until(jog_j1, lambda: abs(np.degrees(panel.q[0]) - want) < 1e-3, what="J1 jogged")
    np.testing.assert_allclose(app.robot.q, panel.q)
    wait_for(
        lambda: panel.last_status is not None and "**" in panel.status_md.content, what="status"
    )
    act_until(to_point.click, lambda: np.allclose(panel.q, check.q), what="back at D")
    T = panel.T_world_tcp()
    T[:3, 3] -= 0.05 * T[:3, 2]  # 50 mm back along the sensor axis, through the IK
    assert panel.move_tcp(T) is not None
    n_before = len(app.state.doc.points)
    page.get_by_role("button", name="Teach pose").click()
    wait_for(lambda: len(app.state.doc.points) == n_before + 1, what="the taught point")
    taught = app.state.doc.points[-1]
    d = app.state.doc.get("D").probe
    np.testing.assert_allclose(taught.probe.position_m, d.position_m, atol=5e-4)  # mesh face
    assert taught.probe.search.start_offset_m == pytest.approx(0.05, abs=5e-4)
    p = transform_points(app.view.T_world_wobj, d.position_m)
    set_camera(demo.client(), np.add(p, [-1.6, -1.9, 1.0]), np.add(p, [-0.4, 0.0, 0.1]))
    save_screenshot(page, "taught_pose.png", tmp_path)
    app.state.undo()


def test_teach_as_via_point_in_the_page(demo: UiSession) -> None:
    import json

    from calib.plan import plan_from_json

    app, page = demo.app, demo.page
    panel = app.teach_panel
    qa = wait_for(lambda: app.check_of("A"), what="A's check").q
    lifted = qa + np.array([0.0, -0.2, 0.0, 0.0, 0.0, 0.0])  # retracted above the part
    panel.jog(lifted)
    app.select("B")
    open_tab(page, "Teach")
    page.get_by_role("button", name="Teach as via point").click()
    wait_for(lambda: len(app.state.doc.get("B").vias) == 1, what="the via on the server")
    np.testing.assert_allclose(app.state.doc.get("B").vias[0].q_rad, lifted, atol=1e-12)
    # the autosaved plan is a valid plan with the via (joint values as taught)
    assert app.state.wait_saved(timeout=120.0), app.state.last_autosave_error
    saved = plan_from_json(app.state._autosave_path.read_text())
    np.testing.assert_allclose(saved.point("B").via_points[0].q_rad, lifted, atol=1e-12)
    assert json.loads(app.state._autosave_path.read_text())["points"][0].get("vias") is None
    wait_for(lambda: app.server.scene.get_handle_by_name("/vias/B/v1"), what="the via marker")
    open_tab(page, "Points")
    page.get_by_role("button", name="Undo", exact=True).click()
    wait_for(lambda: app.state.doc.get("B").vias == (), what="undo removes the via")


def _the_zip_carries_the_uploaded_part(demo: UiSession, part: Path, tmp_path: Path) -> None:
    """ "Download plan with its files": the plan, named after the session plan, refers to the
    part inside the zip (not the server's upload cache), with the uploaded bytes."""
    import zipfile

    from calib.plan.base import resolve_ref
    from calib.plan.file import load_plan

    page = demo.page
    open_tab(page, "Files")
    with page.expect_download() as dl:
        page.get_by_role("button", name="Download plan with its files (.zip)").click()
    saved = tmp_path / dl.value.suggested_filename
    dl.value.save_as(saved)
    stem = saved.stem
    assert saved.suffix == ".zip" and stem in demo.app.state.doc.name.replace(" ", "_")
    out = tmp_path / "unpacked"
    with zipfile.ZipFile(saved) as z:
        z.extractall(out)
    plan = load_plan(out / stem / f"{stem}.json")
    mesh = plan.work_object.mesh
    assert not Path(mesh).is_absolute() and ".cache" not in mesh
    found = Path(resolve_ref(mesh, out / stem))
    assert found.resolve().is_relative_to((out / stem).resolve())
    assert found.read_bytes() == part.read_bytes()


def test_uploading_a_part_shows_its_size_then_reframes_and_lists_points_off_it(
    demo: UiSession, reference_dir: Path, tmp_path: Path
) -> None:
    from webui import clients

    app, page = demo.app, demo.page
    files = app.files_panel
    before = app.state.doc
    open_tab(page, "Files")
    files.units.value = "mm"
    with page.expect_file_chooser() as fc:
        page.get_by_role("button", name="Upload work-object mesh").click()
    fc.value.set_files(str(reference_dir / "parts" / "plate_holes.STL"))
    wait_for(lambda: "203.2 x 304.8 x 12.7 mm" in page.inner_text("body"), what="the size")
    assert app.state.doc is before, "not used before it is accepted"
    page.get_by_role("button", name="Use this part").click()
    wait_for(lambda: app.state.doc.source.work_object.units == "mm", what="the new part")
    want = clients.framed_camera(app.view, clients.ISO_DIRECTION, demo.client().camera.fov)[1]
    wait_for(lambda: np.allclose(demo.client().camera.look_at, want, atol=1e-3), what="reframed")
    wait_for(lambda: "off the new part" in page.inner_text("body"), what="the list")
    assert set(files.off) == set(PAPER_IDS)
    page.get_by_role("button", name="Project them onto the part").click()
    wait_for(lambda: not files.off, what="the points projected")
    for p in app.state.doc.points:
        assert app.picker.project(p.probe.position_m).distance_m < 1e-9
    _the_zip_carries_the_uploaded_part(demo, reference_dir / "parts" / "plate_holes.STL", tmp_path)
    app.state.undo()
    app.state.undo()
    wait_for(lambda: app.state.doc.source is before.source, what="the demo back")


def test_the_robot_and_camera_move_only_when_asked(demo: UiSession, tmp_path: Path) -> None:
    """Issue 22 item 5: selecting a point leaves the robot where it stands; "Robot to selected
    point" moves it there; moving the part (Snap) keeps the camera where the user put it; the
    Robot dropdown draws it as a ghost or hides it, and a ghost does not stop a click."""
    from ui_helpers import choose

    app, page = demo.app, demo.page
    client = demo.client()
    robot = app.robot
    assert robot is not None and robot.display == "shown"
    open_tab(page, "Points")
    q0 = robot.q_of(client.client_id)
    check = wait_for(lambda: app.check_of("C"), what="C's check")
    assert check.q is not None and not np.allclose(check.q, q0)
    choose(page, "Selected", "C")
    wait_for(lambda: app.selection_of(client) == "C", what="C selected (server)")
    assert np.allclose(robot.q_of(client.client_id), q0), "selecting does not move the robot"
    page.get_by_role("button", name="Robot to selected point").click()
    wait_for(lambda: np.allclose(robot.q_of(client.client_id), check.q), what="robot at C")
    # the camera stays where the user put it when the part moves
    set_camera(client, (3.0, -2.0, 2.5), (1.2, 0.0, 0.6))
    cam = np.array(client.camera.position)
    open_tab(page, "Cell")
    T0 = pose_of(app.state.doc.source, WORK_OBJECT)
    page.get_by_role("button", name="Snap part onto fixture").click()
    wait_for(lambda: not np.allclose(pose_of(app.state.doc.source, WORK_OBJECT), T0), what="snap")
    wait_for(lambda: len(app.checks()) == 8, what="the points checked in the moved cell")
    assert np.allclose(client.camera.position, cam, atol=1e-6), "the camera did not jump"
    app.state.undo()
    wait_for(lambda: np.allclose(app.view.T_world_wobj, T0, atol=1e-12), what="undo")
    # ghost: drawn translucent, clicks go through it
    q1 = app.robot.q_of(client.client_id)
    choose(page, "Robot", "ghost")
    wait_for(lambda: app.robot is not None and app.robot.display == "ghost", what="ghost")
    save_screenshot(page, "robot_ghost.png", tmp_path)
    choose(page, "Robot", "hidden")
    wait_for(lambda: app.robot is not None and app.robot.display == "hidden", what="hidden")
    choose(page, "Robot", "shown")
    wait_for(lambda: app.robot is not None and app.robot.display == "shown", what="shown")
    assert np.allclose(app.robot.q_of(client.client_id), q1), "each tab keeps its pose"


def test_typing_a_points_position_moves_it_in_one_undo_step(demo: UiSession) -> None:
    """Issue 22 item 6: the selected point's X/Y/Z (mm, wobj) and normal are fields; a typed
    Y applied with "Apply settings" moves the point along its face (projected onto the part),
    one undo step; typing alone changes nothing; with nothing selected the fields are not
    shown."""
    from ui_helpers import choose

    app, page = demo.app, demo.page
    client = demo.client()
    open_tab(page, "Points")
    choose(page, "Selected", "(none)")
    wait_for(lambda: app.selection_of(client) is None, what="nothing selected")
    tab = app.selection.tab(client.client_id)
    assert tab is not None
    field = page.locator(f'[id="{tab.position_mm._impl.uuid}"]')
    wait_for(lambda: not field.is_visible(), what="the fields hidden")
    choose(page, "Selected", "B")
    wait_for(field.is_visible, what="the fields shown")
    p0 = np.array(app.state.doc.get("B").probe.position_m)
    n0 = np.array(app.state.doc.get("B").probe.normal)
    wait_for(lambda: np.allclose(tab.position_mm.value, p0 * 1000, atol=1e-3), what="B's X/Y/Z")
    before = app.state.doc
    y_field = field.locator("xpath=ancestor::*[count(.//input)>=3][1]//input").nth(1)
    y_field.fill(f"{p0[1] * 1000 - 10.0:.3f}")  # along B's face (its normal is x)
    y_field.press("Tab")
    wait_for(lambda: abs(tab.position_mm.value[1] - (p0[1] * 1000 - 10.0)) < 1e-6, what="typed")
    assert app.state.doc is before, "typing alone changes nothing"
    page.get_by_role("button", name="Apply settings").click()

    def moved() -> Any:
        p = app.state.doc.get("B").probe
        return p if abs(p.position_m[1] - p0[1] + 0.010) < 1e-4 else None

    probe = wait_for(moved, what="B moved 10 mm along y")
    # on the part (the nearest spot of the mesh: within 0.1 mm of the typed one here)
    assert np.allclose(np.asarray(probe.position_m)[::2], p0[::2], atol=1e-4)
    assert np.allclose(probe.normal, n0, atol=2e-3)  # the facet's normal, as a click gives
    assert app.picker.project(probe.position_m).distance_m < 1e-9
    open_tab(page, "Points")
    page.get_by_role("button", name="Undo", exact=True).click()
    wait_for(lambda: app.state.doc is before, what="the plan before the entry: one undo step")


def test_moving_the_part_keeps_the_jogged_robot_where_it_stands(demo: UiSession) -> None:
    """helper-56 (D1): after a jog, moving the part rebuilt the robot: the fields went back to
    0, the arm stayed drawn at the jogged pose and the tool at the home pose's flange. The same
    robot, base and tool are kept now, each tab's robot where it stands."""
    app, page = demo.app, demo.page
    panel, robot = app.teach_panel, app.robot
    assert robot is not None
    open_tab(page, "Teach")
    j2 = _input_of(page, panel.sliders[1])
    want = 20.0

    def jog() -> None:
        j2.fill(f"{want}")
        j2.press("Tab")

    act_until(jog, lambda: abs(np.degrees(panel.q[1]) - want) < 1e-3, what="J2 jogged")
    q_jogged = panel.q.copy()
    open_tab(page, "Cell")
    T0 = pose_of(app.state.doc.source, WORK_OBJECT)
    page.get_by_role("button", name="Snap part onto fixture").click()
    wait_for(lambda: not np.allclose(pose_of(app.state.doc.source, WORK_OBJECT), T0), what="snap")
    wait_for(lambda: len(app.checks()) == 8, what="the points checked in the moved cell")
    assert app.robot is robot, "the same robot drawing, not rebuilt"
    np.testing.assert_allclose(robot.q_of(demo.client().client_id), q_jogged)
    open_tab(page, "Teach")
    j2 = _input_of(page, app.teach_panel.sliders[1])  # the sliders are built anew
    wait_for(lambda: float(j2.input_value()) == want, what="the page's J2 field at the jog")
    app.state.undo()
    wait_for(lambda: np.allclose(app.view.T_world_wobj, T0, atol=1e-12), what="undo")
