"""End-to-end tests of the web UI in a real headless Chromium (Playwright).

Each test starts the UI in-process on a free port and drives it through the browser; what the
browser did is checked on the server side (the session plan and its checks).
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from ui_helpers import UiSession, click_world, open_tab, save_screenshot, set_camera, wait_for

from calib.frames import transform_points
from webui.testing import T_WORLD_WOBJ_BOX


def click_world_point(ui: UiSession, p_world: Any) -> None:
    """Click the canvas where ``p_world`` appears in the page's camera."""
    click_world(ui.page, ui.client(), p_world)


def open_folder(ui: UiSession, button: str) -> None:
    """Show the "Files" tab, where ``button`` is."""
    open_tab(ui.page, "Files")
    ui.page.get_by_role("button", name=button).wait_for(state="visible")


def test_page_loads_with_plan_points_and_status(ui: UiSession) -> None:
    wait_for(lambda: "P1" in ui.page.content(), what="the status table")
    assert set(ui.app.state.doc.ids) == {"P1", "P2", "P3", "S1", "S2", "T1"}
    text = ui.page.inner_text("body")
    for label in ("Points", "Validate", "Files", "Place"):
        assert label in text
    checks = wait_for(lambda: len(ui.app.checks()) == 6 and ui.app.checks(), what="checks")
    assert all(c.status in {"feasible", "marginal", "infeasible"} for c in checks.values())


def click_until_placed(ui: UiSession, point_id: str, target: Any, want: Any) -> Any:
    """Click the canvas at ``target`` (world) until ``point_id`` is placed where ``want``
    (``(position_wobj, normal_wobj)``) says; a click that lands elsewhere (the browser still
    busy under load) is undone and tried again. Returns the placed point."""
    pos, normal = (np.asarray(v, dtype=float) for v in want)

    def placed_right() -> bool:
        if point_id not in ui.app.state.doc.ids:
            return False
        probe = ui.app.state.doc.get(point_id).probe
        return bool(
            np.allclose(probe.position_m, pos, atol=0.005)
            and np.allclose(probe.normal, normal, atol=1e-9)
        )

    deadline = time.monotonic() + 120.0
    while time.monotonic() < deadline:
        click_world_point(ui, target)
        try:
            wait_for(lambda: point_id in ui.app.state.doc.ids, timeout=20.0, what="a point")
        except pytest.fail.Exception:
            continue  # the click missed the part: try again
        if placed_right():
            return ui.app.state.doc.get(point_id)
        ui.app.state.undo()  # landed elsewhere: take it back, click again
    pytest.fail(f"{point_id} was never placed at {pos} with normal {normal}")


def test_click_on_mesh_places_point_on_surface(ui: UiSession) -> None:
    target_wobj = np.array([0.12, -0.07, 0.0])  # on the top face
    target = transform_points(T_WORLD_WOBJ_BOX, target_wobj)
    set_camera(ui.client(), target + np.array([0.9, -0.5, 1.1]), target + np.array([0.05, 0.15, 0]))
    ui.app.points_panel.place.value = "A"
    point = click_until_placed(ui, "A", target, (target_wobj, [0, 0, 1]))
    np.testing.assert_allclose(point.probe.position_m, target_wobj, atol=0.005)
    check = wait_for(lambda: ui.app.check_of("A"), what="A's check")
    assert check.status in {"feasible", "marginal", "infeasible"}
    wait_for(lambda: "| A |" in ui.app.points_panel.status_md.content, what="A in the table")
    wait_for(lambda: check.status in ui.page.inner_text("body"), what="status on the page")


def test_unreachable_spot_is_infeasible_with_reason(ui: UiSession) -> None:
    # the far side face (wobj -y, facing away from the robot) is out of reach
    target_wobj = np.array([0.05, -0.2, -0.12])
    target = transform_points(T_WORLD_WOBJ_BOX, target_wobj)
    set_camera(ui.client(), target + np.array([1.2, 0.5, 0.5]), target + np.array([0, -0.1, 0]))
    ui.app.points_panel.place.value = "Z"
    click_until_placed(ui, "Z", target, (target_wobj, [0, -1, 0]))
    check = wait_for(lambda: ui.app.check_of("Z"), what="Z's check")
    assert check.status == "infeasible" and check.reason
    from webui.status_table import causes, part_note

    # the row's first cause; every cause in the selected point's details, the part's note once
    for cause in (c.text for c in causes(check)):
        wait_for(lambda cause=cause: cause in ui.page.inner_text("body"), what=f"'{cause}'")
    note = part_note(check)
    assert not note or ui.page.inner_text("body").count(note) == 1


def test_validate_refuses_a_plan_that_cannot_work_naming_the_point(ui: UiSession) -> None:
    """The box plan's searches start 30 mm out, closer than the default 20 mm, 3 deg
    misplacement allows (and earlier tests of this module add points the 3-2-1 has no role
    for): the validation does not start, and says which points and why."""
    open_tab(ui.page, "Validate")
    ui.page.get_by_role("button", name="Validate plan").click()
    msg = wait_for(
        lambda: "Validation not started" in ui.notifications() and ui.notifications(),
        what="the notification",
    )
    # the clicks of the module's earlier tests (on this worker: xdist may split the module)
    # found every 3-2-1 role full: A (and Z) placed without one
    named = "have no role" in msg or "point A has no role" in msg
    assert "the search starts 30.0 mm out" in msg or named, msg
    assert ui.app.validate_panel.last_report is None


def drop_points_without_role(ui: UiSession) -> None:
    """Delete the points placed by earlier tests with every 3-2-1 role full (they have none,
    and a plan file refuses them, naming them)."""
    from webui import plan_doc

    for p in ui.app.state.doc.points:
        if p.role == plan_doc.NO_ROLE:
            ui.app.state.update(lambda d, pid=p.id: plan_doc.delete_point(d, pid), "delete")


def test_plan_download_matches_server_plan(ui: UiSession, tmp_path: Path) -> None:
    wait_for(lambda: "P1" in ui.page.content(), what="page ready")
    drop_points_without_role(ui)
    with ui.page.expect_download() as dl:
        open_folder(ui, "Download plan JSON")
        ui.page.get_by_role("button", name="Download plan JSON").click()
    saved = tmp_path / "downloaded.json"
    dl.value.save_as(saved)
    _, server_bytes = ui.app.files_panel.plan_bytes()
    assert saved.read_bytes() == server_bytes
    assert json.loads(saved.read_text())["schema"] == "wobjcal.plan/1"


def test_bad_upload_shows_error_and_changes_nothing(ui: UiSession, tmp_path: Path) -> None:
    wait_for(lambda: "P1" in ui.page.content(), what="page ready")
    before = ui.app.state.doc
    bad = tmp_path / "broken.json"
    bad.write_text('{"schema": "wobjcal.plan/1", "points": [}')
    open_folder(ui, "Upload plan (.json)")
    with ui.page.expect_file_chooser() as fc:
        ui.page.get_by_role("button", name="Upload plan (.json)").click()
    fc.value.set_files(str(bad))
    text = wait_for(
        lambda: "File not used" in ui.notifications() and ui.notifications(),
        what="the error notification",
    )
    assert "broken.json" in text
    assert ui.app.state.doc is before


def test_second_tab_sees_the_same_session(ui: UiSession, browser: Any) -> None:
    from ui_helpers import open_page

    other = open_page(browser, ui.app)
    try:
        wait_for(lambda: "P1" in other.page.inner_text("body"), what="the plan in tab 2")
        origin = transform_points(T_WORLD_WOBJ_BOX, [0.0, 0.1, 1.0])
        ui.app.place_at_ray(origin, T_WORLD_WOBJ_BOX[:3, :3] @ [0, 0, -1.0], point_id="M")
        wait_for(lambda: "M" in other.page.locator("td").all_inner_texts(), what="M in tab 2")
        assert len(ui.app.server.get_clients()) >= 2
    finally:
        other.page.close()


def test_a_program_check_refuses_is_not_downloaded_until_export_anyway(
    ui: UiSession, tmp_path: Path
) -> None:
    """The box plan's searches are too short for the default misplacement and S1, S2 are out
    of reach: check refuses the RAPID program, so "Download RAPID" downloads nothing and the
    page lists why; "Export anyway" downloads it with the reasons in its header."""
    wait_for(lambda: "P1" in ui.page.content(), what="page ready")
    drop_points_without_role(ui)
    downloads: list[Any] = []

    def seen(download: Any) -> None:
        downloads.append(download)

    ui.page.on("download", seen)
    open_folder(ui, "Download RAPID")
    ui.page.get_by_role("button", name="Download RAPID").click()
    shown = wait_for(
        lambda: "RAPID not downloaded" in ui.page.inner_text("body") and ui.page.inner_text("body"),
        what="the refusal in the Files tab",
    )
    assert "S1: out of reach" in shown and "P1: search:" in shown
    assert "Not exported" in ui.notifications()
    anyway = ui.page.get_by_role("button", name="Export anyway")
    assert anyway.is_visible()
    time.sleep(1.0)  # a download would have started by now
    assert downloads == []
    save_screenshot(ui.page, "export_refused.png", tmp_path)  # hides notifications: last test
    with ui.page.expect_download() as dl:
        anyway.click()
    saved = tmp_path / dl.value.suggested_filename
    dl.value.save_as(saved)
    text = saved.read_text()
    assert saved.suffix == ".mod" and "MODULE" in text
    head = " ".join(" ".join(line.lstrip("! ") for line in text.splitlines()[:40]).split())
    assert 'NOT CHECKED: exported with --force (or with "Export anyway" in the UI)' in head
    assert "(P1: search:" in head and "S1: out of reach" in head
    wait_for(lambda: not anyway.is_visible(), what="the button hidden after the download")
    assert "RAPID not downloaded" not in ui.page.inner_text("body")
    ui.page.remove_listener("download", seen)
