"""Issue 22, items 6 and 7, in Chromium: editing like a CAD tool and the small things that
cost trust. Fine jogging (a typed joint value, 0.1 deg steps, the limits said), the 3-point
frame drawn as a triad while it is picked, the status table (an icon per row, a short first
cause, every cause for the selected point) and Ctrl+Z / Ctrl+Shift+Z. Every test checks the
server's state and what the page shows."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

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
from webui import plan_doc
from webui.frame_panel import MODE, TRIAD_NODE
from webui.joint_jog import PLUS
from webui.testing import T_WORLD_WOBJ_BOX


def _field(page: Any, handle: Any) -> Any:
    """The input of a viser number widget."""
    return page.locator(f'[id="{handle._impl.uuid}"]')


def _row(page: Any, point_id: str) -> Any:
    """The table row of ``point_id`` on the page."""
    return page.locator("tr", has=page.locator(f"td:text-is('{point_id}')"))


def test_fine_jog_steps_and_typed_values_in_the_page(demo: UiSession, tmp_path: Path) -> None:
    """A 0.1 deg step of J1 moves J1 by 0.1 deg (the slider's 24 px moved it 42 deg); a typed
    J3 goes there; a value beyond the limits is refused on the page, the robot stays."""
    app, page = demo.app, demo.page
    panel = app.teach_panel
    fine = panel.fine
    check = wait_for(lambda: app.check_of("D"), what="D's check")
    app.select("D")
    open_tab(page, "Teach")
    to_point = page.get_by_role("button", name="Jog to selected point")
    act_until(to_point.click, lambda: np.allclose(panel.q, check.q), what="the robot at D's pose")
    choose(page, "Step (deg)", "0.1")
    wait_for(lambda: fine.step.value == "0.1", what="the step on the server")
    q0 = panel.q.copy()
    plus = page.get_by_role("button", name=PLUS, exact=True)
    act_until(plus.click, lambda: not np.allclose(panel.q, q0), what="J1 stepped")
    assert np.degrees(panel.q[0] - q0[0]) == pytest.approx(0.1, abs=1e-9)
    np.testing.assert_allclose(panel.q[1:], q0[1:])
    np.testing.assert_allclose(app.robot.q, panel.q)
    want = f"{np.degrees(panel.q[0]):.2f}"
    wait_for(lambda: _field(page, fine.fields[0]).input_value() == want, what="J1 on the page")
    j3 = _field(page, fine.fields[2])
    target = round(float(np.degrees(panel.q[2])) - 1.5, 2)

    def type_j3() -> None:
        j3.fill(f"{target}")
        j3.press("Tab")

    act_until(type_j3, lambda: abs(np.degrees(panel.q[2]) - target) < 1e-6, what="J3 typed")
    wait_for(lambda: "**" in panel.status_md.content, what="the jog's status")
    before = panel.q.copy()
    over = float(fine.hi[2]) + 20.0
    fine.fields[2].value = over  # as the page sends it while typing, before the field clamps
    wait_for(lambda: "outside its limits" in page.inner_text("body"), what="the refusal")
    np.testing.assert_array_equal(panel.q, before)
    wait_for(lambda: abs(float(j3.input_value()) - target) < 1e-6, what="J3 shows the joint")
    close_notifications(page)  # before the screenshot hides them (then they cannot be closed)
    save_screenshot(page, "jog_fine.png", tmp_path)


def test_the_status_table_has_icons_short_causes_and_details(
    demo: UiSession, tmp_path: Path
) -> None:
    """One row per point with ✓/⚠/✗ and the first cause without the part's size note; the
    selected point's every cause below. A point under the part (its sensor in the table) with
    no role left (a ninth point of the A-H plan) is flagged **role** and stays ✗ and red."""
    from webui.scene import STATUS_RGB
    from webui.status_table import causes, short_cause

    app, page = demo.app, demo.page
    wait_for(lambda: len(app.checks()) == 8, what="the A-H checks")
    view = app.view
    low = view.wobj_mesh.bounds.mean(axis=0) * [1, 1, 0] + [0, 0, view.wobj_mesh.bounds[0, 2]]
    under = app.picker.project(low - [0.0, 0.0, 0.01])  # the face on the table
    app.state.update(
        lambda d: plan_doc.place_point(d, "I", under.position_wobj, under.normal_wobj), "place I"
    )
    try:
        bad = wait_for(lambda: app.check_of("I"), what="I's check")
        assert bad.status == "infeasible" and "I" in app.flags.by_point, bad.reason
        marker = app.server.scene.get_handle_by_name("/wobj/points/I/marker")
        wait_for(lambda: tuple(marker.color) == STATUS_RGB["infeasible"], what="I in red")
        open_tab(page, "Points")
        checks = app.checks()
        icon = {"feasible": "✓", "marginal": "⚠", "infeasible": "✗"}
        for pid, c in checks.items():
            row = _row(page, pid)
            wait_for(lambda row=row: row.count() == 1, what=f"{pid}'s one row")
            wait_for(lambda row=row, c=c: icon[c.status] in row.inner_text(), what="the icon")
            text = row.inner_text()
            assert c.status in text and "file units" not in text, text
        assert "role" in _row(page, "I").inner_text()
        assert short_cause(causes(bad)[0])[:30] in _row(page, "I").inner_text()
        choose(page, "Selected", "I")
        wait_for(lambda: "wobj frame" in page.inner_text("body"), what="the details on the page")
        for cause in (c.text for c in causes(bad)):
            wait_for(lambda cause=cause: cause in page.inner_text("body"), what=f"'{cause}'")
        wait_for(lambda: "role: point I has no role" in page.inner_text("body"), what="role")
        save_screenshot(page, "status_table.png", tmp_path)
    finally:
        app.state.undo()
    wait_for(lambda: _row(page, "I").count() == 0, what="I's row gone")


def test_the_3_point_frame_is_drawn_as_a_triad_while_picked(ui: UiSession, tmp_path: Path) -> None:
    """After the origin and +x, the frame they define is drawn at the origin (x to the +x
    point, z out of the face clicked); it goes on Cancel, and when the frame is applied."""
    app, page = ui.app, ui.page
    wait_for(lambda: app.view is not None, what="the cell")
    centre = transform_points(T_WORLD_WOBJ_BOX, [0.0, 0.0, 0.0])
    set_camera(ui.client(), centre + np.array([0.55, -0.6, 0.75]), centre)
    open_tab(page, "Cell")
    start = page.get_by_role("button", name="Define frame by 3 points")
    act_until(start.click, lambda: app.click_mode == MODE, what="the 3-point mode")
    panel = app.frame_panel
    o, px = np.array([-0.24, 0.02, 0.0]), np.array([0.15, 0.05, 0.0])  # clear of the WOCS
    _click(ui, o, lambda: len(panel.picked) == 1)
    assert app.server.scene.get_handle_by_name(TRIAD_NODE) is None, "not defined yet"
    _click(ui, px, lambda: len(panel.picked) == 2)
    triad = wait_for(lambda: app.server.scene.get_handle_by_name(TRIAD_NODE), what="the triad")
    T = panel.triad
    assert T is not None
    x = (panel.picked[1] - panel.picked[0]) / np.linalg.norm(panel.picked[1] - panel.picked[0])
    np.testing.assert_allclose(T[:3, 0], x, atol=1e-9)
    np.testing.assert_allclose(T[:3, 2], [0.0, 0.0, 1.0], atol=1e-9)  # out of the top face
    # viser lists a frame's handle before it sets its pose (another thread): wait for the pose
    want = transform_points(T_WORLD_WOBJ_BOX, T[:3, 3])
    wait_for(lambda: np.allclose(triad.position, want, rtol=1e-7, atol=0.0), what="its pose")
    wait_for(lambda: "green (+y) side" in page.inner_text("body"), what="the hint")
    page.get_by_text("green (+y) side").scroll_into_view_if_needed()
    save_screenshot(page, "frame_triad.png", tmp_path)
    page.get_by_role("button", name="Cancel 3-point frame").click()
    wait_for(lambda: app.server.scene.get_handle_by_name(TRIAD_NODE) is None, what="gone")
    assert app.click_mode == "place"
    # picked again to the end: the frame is applied and the triad goes
    act_until(start.click, lambda: app.click_mode == MODE, what="the 3-point mode again")
    _click(ui, o, lambda: len(panel.picked) == 1)
    _click(ui, px, lambda: len(panel.picked) == 2)
    wait_for(lambda: app.server.scene.get_handle_by_name(TRIAD_NODE), what="the triad again")
    _click(ui, np.array([-0.10, 0.15, 0.0]), lambda: app.click_mode == "place")
    assert app.server.scene.get_handle_by_name(TRIAD_NODE) is None
    wait_for(lambda: all(app.check_of(p) for p in app.state.doc.ids), what="the checks")
    app.state.undo()
    wait_for(lambda: np.allclose(app.view.T_world_wobj, T_WORLD_WOBJ_BOX), what="old frame")


def _click(ui: UiSession, p_wobj: Any, done: Any) -> None:
    """Click ``p_wobj`` on the box until the panel has taken it (a click can be lost)."""
    x, y = canvas_point(ui, transform_points(T_WORLD_WOBJ_BOX, p_wobj))
    for _ in range(4):
        ui.page.mouse.click(x, y)
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline:
            if done():
                return
            time.sleep(0.05)
    pytest.fail(f"the click at {p_wobj} was never taken")


def test_ctrl_z_and_ctrl_shift_z_undo_and_redo(ui: UiSession) -> None:
    """The keys undo and redo as the buttons do (viser's command palette hotkeys); typed
    into a field, Ctrl+Z is the field's own."""
    app, page = ui.app, ui.page
    wait_for(lambda: app.view is not None, what="the cell")
    open_tab(page, "Points")
    before = app.state.doc
    app.state.update(
        lambda d: plan_doc.place_point(d, "K", (0.05, 0.02, 0.0), (0.0, 0.0, 1.0)), "place K"
    )
    row = _row(page, "K")
    wait_for(lambda: row.count() == 1, what="K's row")
    page.evaluate("document.activeElement && document.activeElement.blur()")  # no field focused
    page.keyboard.press("Control+z")
    wait_for(lambda: app.state.doc is before, what="the undo on the server")
    wait_for(lambda: row.count() == 0, what="K's row gone")
    page.keyboard.press("Control+Shift+Z")
    wait_for(lambda: "K" in app.state.doc.ids, what="the redo on the server")
    wait_for(lambda: row.count() == 1, what="K's row back")
    # in a field the keys are the field's own: the plan keeps K
    open_tab(page, "Validate")
    trials = page.get_by_label("Trials", exact=True)
    trials.fill("30")
    trials.press("Control+z")
    trials.fill("40")
    trials.press("Tab")  # sent after any command the key sent, on the same websocket
    wait_for(lambda: app.validate_panel.trials.value == 40, what="the typed trials")
    time.sleep(1.0)  # a command would have run by now (the thread pool is idle)
    assert "K" in app.state.doc.ids, "Ctrl+Z in a field undid the plan"
    open_tab(page, "Points")
    page.evaluate("document.activeElement && document.activeElement.blur()")
    page.keyboard.press("Control+z")
    wait_for(lambda: row.count() == 0, what="K's row gone again")
