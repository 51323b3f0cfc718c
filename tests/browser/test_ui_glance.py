"""Issue 14 in Chromium, on the demo: reading at a glance (first view, view buttons, legend,
short labels), panels in tabs, honest status (role flags, clicks that do nothing say why, the
busy line), roles and procedures, and the gizmo. Every test checks the server's state."""

from __future__ import annotations

import threading
from pathlib import Path

import numpy as np
import pytest
from ui_helpers import (
    UiSession,
    act_until,
    canvas_point,
    choose,
    close_notifications,
    open_tab,
    save_screenshot,
    set_camera,
    wait_for,
)

from calib.frames import transform_points
from webui import clients
from webui.plan_doc import NO_ROLE, PAPER_IDS
from webui.scene import STATUS_RGB


def _camera_direction(ui: UiSession) -> np.ndarray:
    cam = ui.client().camera
    d = np.asarray(cam.look_at, float) - np.asarray(cam.position, float)
    return d / np.linalg.norm(d)


def _in_view(ui: UiSession, points_world: np.ndarray) -> np.ndarray:
    """``(N, 2)`` the points' page coordinates as fractions of the canvas (0-1)."""
    box = ui.page.locator("canvas").first.bounding_box()
    xy = np.array([canvas_point(ui, p) for p in points_world])
    return (xy - [box["x"], box["y"]]) / [box["width"], box["height"]]


def test_first_view_frames_the_part_with_the_robot_in_view(demo: UiSession, tmp_path: Path) -> None:
    view = demo.app.view
    assert view is not None
    part, robot = clients.cell_points(view)
    want = clients.framed_camera(view, clients.ISO_DIRECTION, demo.client().camera.fov)[1]
    wait_for(
        lambda: np.allclose(demo.client().camera.look_at, want, atol=1e-3),
        what="the browser to report the framed camera",
    )
    uv = _in_view(demo, np.vstack([part, robot]))
    assert np.all((uv > 0.0) & (uv < 1.0)), f"part or robot outside the view: {uv}"
    centre = _in_view(demo, part.mean(axis=0)[None])[0]
    assert abs(centre[0] - 0.5) < 0.25 and abs(centre[1] - 0.5) < 0.25, centre
    wait_for(lambda: len(demo.app.checks()) == 8, what="the A-H checks")
    save_screenshot(demo.page, "first_view.png", tmp_path)


def test_view_buttons_move_the_camera_of_the_tab(demo: UiSession) -> None:
    for name, direction in (("Top", clients.VIEWS["Top"]), ("Front", clients.VIEWS["Front"])):
        demo.page.get_by_role("button", name=name, exact=True).click()
        d = np.asarray(direction) / np.linalg.norm(direction)
        wait_for(
            lambda d=d: float(_camera_direction(demo) @ d) > 0.999,
            what=f"the {name} view",
        )
    demo.page.get_by_role("button", name="Fit", exact=True).click()
    wait_for(lambda: float(_camera_direction(demo) @ d) > 0.999, what="fit keeps the direction")


def test_legend_and_short_labels(demo: UiSession) -> None:
    demo.page.get_by_text("Legend", exact=True).click()
    wait_for(lambda: "being checked" in demo.page.inner_text("body"), what="the legend")
    for pid in PAPER_IDS:
        label = demo.app.server.scene.get_handle_by_name(f"/wobj/points/{pid}/label")
        assert label is not None and label.text == pid, "a label is the point's id only"
        assert label.depth_test, "labels hide behind the part"


def test_panels_are_tabs(demo: UiSession) -> None:
    for tab, button in (
        ("Validate", "Validate plan"),
        ("Files", "Download plan JSON"),
        ("Points", "Undo"),  # its "Apply settings" shows only with a point selected
    ):
        open_tab(demo.page, tab)
        demo.page.get_by_role("button", name=button).wait_for(state="visible")
    assert demo.app.tabs.names[:5] == ("Points", "Cell", "Teach", "Validate", "Files")


def test_point_moved_onto_a_face_its_role_cannot_use_is_flagged_at_once(demo: UiSession) -> None:
    app = demo.app
    b = app.state.doc.get("B").probe
    top = [b.position_m[0] - 0.04, b.position_m[1], 0.3]  # above the top face: projected onto it
    app.move_point_to("B", top)
    try:
        assert app.state.doc.get("B").probe.normal == pytest.approx((0.0, 0.0, 1.0))
        assert "B" in app.flags.by_point and "must have normal" in app.flags.by_point["B"]
        marker = app.server.scene.get_handle_by_name("/wobj/points/B/marker")
        assert tuple(marker.color) == STATUS_RGB["role"]
        open_tab(demo.page, "Points")
        wait_for(lambda: "must have normal" in demo.page.inner_text("body"), what="B's row says")
        assert "**role**" in app.points_panel.status_md.content
    finally:
        app.state.undo()
    assert "B" not in app.flags.by_point
    wait_for(lambda: "must have normal" not in demo.page.inner_text("body"), what="flag gone")


def test_a_click_on_empty_space_says_why(demo: UiSession) -> None:
    before = demo.app.state.doc
    box = demo.page.locator("canvas").first.bounding_box()
    demo.page.get_by_role("button", name="Top", exact=True).click()  # look down: sky is floor
    demo.page.get_by_role("button", name="Front", exact=True).click()
    wait_for(lambda: _camera_direction(demo)[1] > 0.9, what="the front view")
    close_notifications(demo.page)
    act_until(  # the sky above the cell: clicking it again places nothing either
        lambda: demo.page.mouse.click(box["x"] + 15, box["y"] + 15),
        lambda: "nothing placed" in demo.notifications(),
        what="the notification",
    )
    assert demo.app.state.doc is before


def test_a_click_on_a_marker_selects_the_point(demo: UiSession) -> None:
    view = demo.app.view
    before = demo.app.state.doc
    probe = demo.app.state.doc.get("G").probe
    g = transform_points(view.T_world_wobj, probe.position_m)
    n = view.T_world_wobj[:3, :3] @ np.asarray(probe.normal)
    set_camera(demo.client(), g + 0.8 * n + [0.0, -0.3, 0.3], g)  # G in the middle, facing it
    demo.app.select(None)
    x, y = canvas_point(demo, g)
    demo.page.mouse.click(x, y)
    wait_for(lambda: demo.app.selected == "G", what="G selected by its marker")
    assert demo.app.state.doc is before, "selecting places nothing"


def test_busy_line_shows_while_the_cell_checks(demo: UiSession) -> None:
    gate = threading.Event()
    demo.app.worker.submit(lambda _s: gate.wait(120))  # the cell is busy with something else
    a = demo.app.state.doc.get("A").probe.position_m
    mover = threading.Thread(
        target=demo.app.move_point_to, args=("A", np.add(a, [0, 0.003, 0])), daemon=True
    )
    mover.start()
    try:
        wait_for(lambda: "Busy:" in demo.page.inner_text("body"), what="the busy line")
        assert "checking A" in demo.app.busy.text
    finally:
        gate.set()
        mover.join(120)
    wait_for(lambda: "Busy:" not in demo.page.inner_text("body"), what="the busy line to go")
    demo.app.state.undo()


def test_procedure_choice_and_roles_in_the_page(demo: UiSession) -> None:
    app = demo.app
    open_tab(demo.page, "Points")
    choose(demo.page, "Procedure", "best_fit")
    wait_for(lambda: app.state.doc.method == "best_fit", what="the procedure on the server")
    assert {p.role for p in app.state.doc.points} == {"fit"}
    wait_for(lambda: "least-squares fit" in demo.page.inner_text("body"), what="its summary")
    demo.page.get_by_role("button", name="Undo", exact=True).click()
    wait_for(lambda: app.state.doc.method == "hultman2013", what="undo of the procedure")
    wait_for(lambda: app.points_panel.procedure.value == "hultman2013", what="the dropdown")
    # every A-H role is taken: a new point gets none, and the refusal names it
    a = app.state.doc.get("A").probe  # on the side face, 10 mm from A
    target = transform_points(app.view.T_world_wobj, np.add(a.position_m, [0, 0.01, 0]))
    n = app.view.T_world_wobj[:3, :3] @ np.asarray(a.normal)
    app.place_at_ray(target + 0.3 * n, -n, point_id="I")
    try:
        assert app.state.doc.get("I").role == NO_ROLE
        wait_for(lambda: "| I | (none) |" in app.points_panel.status_md.content, what="I's row")
        open_tab(demo.page, "Files")
        demo.page.get_by_role("button", name="Download plan JSON").click()
        wait_for(lambda: "point I has no role" in demo.notifications(), what="the refusal")
        assert "Not downloaded" in demo.notifications()
    finally:
        app.state.undo()


def test_gizmo_is_sized_for_the_part_and_drawn_over_it(demo: UiSession) -> None:
    app = demo.app
    app.select("A")
    open_tab(demo.page, "Points")
    demo.page.get_by_text("Drag selected point", exact=True).click()
    wait_for(lambda: app.points_panel.drag.value, what="the drag box on the server")
    gizmo = wait_for(lambda: app.server.scene.get_handle_by_name("/wobj/gizmo"), what="the gizmo")
    scale, offset = app.points_panel.gizmo_geometry()
    assert gizmo.scale == pytest.approx(scale) and not gizmo.depth_test
    a = app.state.doc.get("A").probe
    np.testing.assert_allclose(gizmo.position, np.add(a.position_m, offset * np.array(a.normal)))
    demo.page.get_by_text("Drag selected point", exact=True).click()
    wait_for(lambda: app.server.scene.get_handle_by_name("/wobj/gizmo") is None, what="removed")
