"""The 3-point work-object frame in the browser: three clicks on the part define the frame;
the server's plan is re-expressed in it with nothing moved in the world (one undo step)."""

from __future__ import annotations

import json
import time
from typing import Any

import numpy as np
import pytest
from ui_helpers import UiSession, canvas_point, open_tab, set_camera, wait_for

from calib.frames import transform_points
from calib.plan.file import Plan
from webui.frame_panel import MODE
from webui.testing import T_WORLD_WOBJ_BOX


def _world_points(ui: UiSession) -> dict[str, np.ndarray]:
    doc = ui.app.state.doc
    assert isinstance(doc.source, Plan)
    T = doc.source.work_object.T_world_wobj.matrix()
    return {p.id: transform_points(T, p.probe.position_m) for p in doc.points}


def _click(ui: UiSession, p_wobj: Any, done: Any) -> None:
    """Click ``p_wobj`` until the panel has taken it (a click can be lost on a loaded machine;
    a repeated click on a slow but taken one is refused as coinciding, and changes nothing)."""
    x, y = canvas_point(ui, transform_points(T_WORLD_WOBJ_BOX, p_wobj))
    for _ in range(4):
        ui.page.mouse.click(x, y)
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline:
            if done():
                return
            time.sleep(0.05)
    pytest.fail(f"the click at {p_wobj} was never taken")


def test_three_clicks_define_the_frame_and_nothing_moves(ui: UiSession) -> None:
    page = ui.page
    wait_for(lambda: ui.app.view is not None, what="the cell")
    centre = transform_points(T_WORLD_WOBJ_BOX, [0.0, 0.0, 0.0])  # top face centre
    set_camera(ui.client(), centre + np.array([0.05, -0.05, 1.3]), centre)
    before = _world_points(ui)
    source_before = ui.app.state.doc.source
    open_tab(page, "Cell")
    page.get_by_role("button", name="Define frame by 3 points").click()
    wait_for(lambda: ui.app.click_mode == MODE, what="the 3-point mode")
    wait_for(lambda: "click the origin" in page.inner_text("body"), what="the prompt")
    _click(ui, [-0.10, -0.05, 0.0], lambda: len(ui.app.frame_panel.picked) == 1)
    _click(ui, [0.10, 0.10, 0.0], lambda: len(ui.app.frame_panel.picked) == 2)
    # a third point on the line origin -> +x is refused, the panel waits for it again
    _click(ui, [0.0, 0.025, 0.0], lambda: "collinear" in ui.notifications())
    assert len(ui.app.frame_panel.picked) == 2 and ui.app.click_mode == MODE
    o, px = (p.copy() for p in ui.app.frame_panel.picked)
    _click(ui, [-0.15, 0.10, 0.0], lambda: ui.app.click_mode == "place")
    plan = ui.app.state.doc.source
    assert isinstance(plan, Plan)
    T_mesh = plan.work_object.mesh_matrix()  # = inv(T_old_new)
    T_old_new = np.linalg.inv(T_mesh)
    np.testing.assert_allclose(T_old_new[:3, 3], o, atol=1e-9)
    np.testing.assert_allclose(T_old_new[:3, 0], (px - o) / np.linalg.norm(px - o), atol=1e-9)
    np.testing.assert_allclose(T_old_new[:3, 2], [0, 0, 1], atol=0.02)  # the top face's normal
    np.testing.assert_allclose(
        plan.work_object.T_world_wobj.matrix(), T_WORLD_WOBJ_BOX @ T_old_new, atol=1e-9
    )
    after = _world_points(ui)
    for pid, p in before.items():
        np.testing.assert_allclose(after[pid], p, atol=1e-9)  # nothing moved in the world
    assert ui.app.state.wait_saved(timeout=120.0), ui.app.state.last_autosave_error
    saved = json.loads(ui.app.state.autosave_path.read_text())  # type: ignore[union-attr]
    assert "T_wobj_mesh" in saved["work_object"]
    wait_for(lambda: all(ui.app.check_of(pid) for pid in before), what="the checks")
    ui.app.state.undo()  # one step back: the old frame
    assert ui.app.state.doc.source == source_before
    wait_for(lambda: ui.app.view is not None and np.allclose(
        ui.app.view.T_world_wobj, T_WORLD_WOBJ_BOX), what="the old cell")  # fmt: skip
    assert "Frame z points into" not in ui.notifications(), "z out of the top face: no warning"


def test_a_frame_with_z_into_the_part_is_warned(ui: UiSession) -> None:
    """Issue 22 item 7: the third point on the -y side turns z into the part; the frame is
    made (the user's choice), and the page says that z points into the work object."""
    page = ui.page
    wait_for(lambda: ui.app.view is not None, what="the cell")
    centre = transform_points(T_WORLD_WOBJ_BOX, [0.0, 0.0, 0.0])
    set_camera(ui.client(), centre + np.array([0.04, -0.06, 1.3]), centre)  # not the last one
    source_before = ui.app.state.doc.source
    open_tab(page, "Cell")
    page.get_by_role("button", name="Define frame by 3 points").click()
    wait_for(lambda: ui.app.click_mode == MODE, what="the 3-point mode")
    _click(ui, [-0.10, -0.05, 0.0], lambda: len(ui.app.frame_panel.picked) == 1)
    _click(ui, [0.10, 0.10, 0.0], lambda: len(ui.app.frame_panel.picked) == 2)
    _click(ui, [0.10, -0.12, 0.0], lambda: ui.app.click_mode == "place")
    plan = ui.app.state.doc.source
    assert isinstance(plan, Plan)
    z = np.linalg.inv(plan.work_object.mesh_matrix())[:3, 2]
    np.testing.assert_allclose(z, [0, 0, -1], atol=0.02)  # into the box
    text = wait_for(
        lambda: "Frame z points into the work object" in ui.notifications() and ui.notifications(),
        what="the warning on the page",
    )
    assert "turn z over" in text
    ui.app.state.undo()
    assert ui.app.state.doc.source == source_before
