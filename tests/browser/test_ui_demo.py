"""End-to-end tests on the built-in demo: the stator section and its A-H plan, in Chromium."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
from ui_helpers import (
    REPO,
    UiSession,
    open_tab,
    rendered,
    save_screenshot,
    set_camera,
    wait_for,
)

from calib.atomic_io import write_bytes_atomic
from calib.frames import transform_points
from webui.plan_doc import PAPER_IDS

#: The README's screenshot: rewritten only when WOBJCAL_UPDATE_SCREENSHOTS=1 (tests leave the
#: tracked tree alone otherwise).
SCREENSHOT = REPO / "docs" / "img" / "demo_cell.png"
#: Where every run writes its screenshot (git-ignored).
ARTIFACT = REPO / "artifacts" / "demo_cell.png"
UPDATE_SCREENSHOTS = os.environ.get("WOBJCAL_UPDATE_SCREENSHOTS") == "1"


def test_demo_loads_with_ah_points_and_statuses(demo: UiSession) -> None:
    assert demo.app.state.doc.ids == PAPER_IDS
    checks = wait_for(lambda: len(demo.app.checks()) == 8 and demo.app.checks(), what="checks")
    statuses = {c.status for c in checks.values()}
    wait_for(
        lambda: all(st in demo.page.inner_text("body") for st in statuses),
        what="the statuses on the page",
    )
    for c in checks.values():
        assert c.status in {"feasible", "marginal", "infeasible"}
        assert c.status == "feasible" or c.reason, f"{c.point_id} gives no reason"


def test_validate_button_produces_table_and_histograms(demo: UiSession) -> None:
    demo.app.validate_panel.trials.value = 30
    open_tab(demo.page, "Validate")
    demo.page.get_by_role("button", name="Validate plan").click()
    panel = demo.app.validate_panel
    wait_for(lambda: not panel.running and panel.result_md.content, timeout=300, what="validation")
    md = panel.last_markdown
    assert md, f"validation gave no table: {panel.result_md.content}"
    assert "| WOCS origin x-axis |" in md
    wait_for(lambda: "WOCS origin x-axis" in demo.page.inner_text("body"), what="table on page")
    assert len(demo.app.validate_panel.plots) >= 6
    assert demo.app.validate_panel.last_report.n_trials == 30


def test_validation_report_reads_in_full_with_value_axes_and_goes_stale(
    demo: UiSession, tmp_path: Path
) -> None:
    """Issue 14, item 4: the report's window is wide enough for the whole table (no cell cut
    off), the histograms have value axes in the row's unit, the error map paints the part,
    and a plan change marks the report stale at once."""
    panel = demo.app.validate_panel
    if panel.last_report is None or panel.stale:
        panel.trials.value = 30
        open_tab(demo.page, "Validate")
        demo.page.get_by_role("button", name="Validate plan").click()
        wait_for(lambda: not panel.running and panel.last_report is not None and not panel.stale,
                 timeout=300, what="validation")  # fmt: skip
    assert panel.report_window.visible
    table = demo.page.locator("table", has_text="WOCS origin x-axis").first
    table.wait_for(state="visible")
    overflow = table.evaluate(
        """t => { let e = t.parentElement; while (e && e.clientWidth >= t.scrollWidth - 1
                   && e !== document.body) e = e.parentElement;
                 const r = t.getBoundingClientRect();
                 return {cut: e !== document.body && e !== null, right: r.right,
                         width: window.innerWidth}; }"""
    )
    assert not overflow["cut"] and overflow["right"] <= overflow["width"], overflow
    for plot in panel.plots:
        assert plot.scales == {"x": {"time": False}}, "a value axis, not uPlot's time axis"
        unit = "deg" if "(deg," in plot.title else "mm"
        assert plot.axes[0]["label"] == f"error ({unit})"
    assert any("(deg," in p.title for p in panel.plots) and any(
        "(mm," in p.title for p in panel.plots
    )
    panel.show_error.value = True
    wait_for(lambda: "place each point within" in panel.error_md.content, what="the error map")
    demo.page.set_viewport_size({"width": 1500, "height": 900})
    save_screenshot(demo.page, "validation_tab.png", tmp_path)
    panel.show_error.value = False
    a = demo.app.state.doc.get("A").probe.position_m
    demo.app.move_point_to("A", np.add(a, [0.0, 0.002, 0.0]))
    try:
        assert panel.stale and "move A" in panel.stale
        wait_for(lambda: "Stale" in demo.page.inner_text("body"), what="the stale mark")
    finally:
        demo.app.state.undo()


def test_heat_map_colours_the_part_by_what_fails(demo: UiSession, tmp_path: Path) -> None:
    """Issue 14, item 6: the map runs on the cell worker, colours each sample by what fails,
    ends with smooth colours over a refined surface, and shows its legend."""
    from webui.heatmap import CATEGORY_RGB

    open_tab(demo.page, "Points")
    demo.page.get_by_text("Reachability heat map", exact=True).click()
    heat = demo.app.heatmap
    wait_for(lambda: heat.done.is_set() and heat.summary, timeout=600, what="the heat map")
    assert len(heat.categories) == len(heat.points) and set(heat.categories) <= set(CATEGORY_RGB)
    assert len(set(heat.categories)) >= 3, heat.summary
    mesh = demo.app.server.scene.get_handle_by_name("/wobj/heat_mesh")
    assert mesh is not None
    wait_for(lambda: "robot or tool collides" in demo.page.inner_text("body"), what="legend")
    view = demo.app.view
    centre = transform_points(view.T_world_wobj, view.wobj_mesh.bounds.mean(axis=0))
    set_camera(demo.client(), np.add(centre, [0.5, -1.3, 0.9]), centre)
    demo.app.validate_panel.report_window.visible = False  # the part, not the last report
    save_screenshot(demo.page, "heat_map.png", tmp_path)
    demo.page.get_by_text("Reachability heat map", exact=True).click()
    wait_for(lambda: demo.app.server.scene.get_handle_by_name("/wobj/heat_mesh") is None,
             what="the map hidden")  # fmt: skip


def test_screenshot_of_demo_cell(demo: UiSession, tmp_path: Path) -> None:
    demo.page.set_viewport_size({"width": 1500, "height": 900})
    # hide transient notifications (e.g. SwiftShader's "software WebGL" warning)
    demo.page.add_style_tag(content=".mantine-Notification-root { display: none !important; }")
    client = demo.client()
    client.camera.fov = 0.8
    set_camera(client, (0.3, -2.6, 2.1), (0.95, -0.15, 0.85))
    demo.app.select("F")  # the robot at F's probe pose, at the start of its edge search
    wait_for(lambda: demo.app.robot is not None and demo.app.robot.q is not None, what="robot")
    rendered(demo.page)  # SwiftShader has drawn the new view
    shot = tmp_path / "demo_cell.png"  # this run's own file: two suites at once never mix
    demo.page.screenshot(path=str(shot))  # the page's default timeout: generous
    assert shot.stat().st_size > 20_000, "the screenshot looks empty"
    ARTIFACT.parent.mkdir(parents=True, exist_ok=True)
    write_bytes_atomic(ARTIFACT, shot.read_bytes())
    if UPDATE_SCREENSHOTS:
        shutil.copyfile(shot, SCREENSHOT)
    assert np.isfinite(client.camera.fov)


def test_checks_run_while_validation_runs(demo: UiSession) -> None:
    panel = demo.app.validate_panel
    wait_for(lambda: not panel.running, timeout=300, what="an earlier validation")
    fut = panel.start(400)
    try:
        a = demo.app.state.doc.get("A")
        moved = np.add(a.probe.position_m, [0.0, 0.002, 0.0])  # 2 mm along the side face
        check = demo.app.move_point_to("A", moved)
        assert check is not None and panel.running, "the check waited for the validation"
    finally:
        fut.result(300)
        demo.app.state.undo()


def test_a_program_check_passes_downloads_at_once(demo: UiSession, tmp_path: Path) -> None:
    """The demo's A-H plan passes check for RAPID: "Download RAPID" downloads it straight
    away, its header says CHECKED, and no refusal or "Export anyway" shows."""
    open_tab(demo.page, "Files")
    button = demo.page.get_by_role("button", name="Download RAPID")
    button.wait_for(state="visible")
    with demo.page.expect_download(timeout=300_000) as dl:
        button.click()
    saved = tmp_path / dl.value.suggested_filename
    dl.value.save_as(saved)
    text = saved.read_text()
    assert saved.suffix == ".mod" and "CHECKED: wobjcal check passed" in text
    assert "NOT CHECKED" not in text
    assert not demo.page.get_by_role("button", name="Export anyway").is_visible()
    assert "not downloaded" not in demo.page.inner_text("body")
