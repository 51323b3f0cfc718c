"""End-to-end tests on the built-in demo: the stator section and its A-H plan, in Chromium."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from ui_helpers import REPO, UiSession, open_tab, rendered, set_camera, wait_for

from calib.atomic_io import write_bytes_atomic
from webui.plan_doc import PAPER_IDS

pytestmark = pytest.mark.browser

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
