"""The machined plate's 3-2-1 and best-fit plans (touch probe, mm mesh) validate in the UI,
and the simulated error shows on the part."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from ui_helpers import REPO, UiSession, act_until, open_page, open_tab, start_ui, wait_for

from webui.validation import error_colours

PLANS = REPO / "assets" / "plans"


@pytest.fixture(scope="module", params=["plate_holes_321.json", "plate_holes_best_fit.json"])
def plate(
    request: Any, browser: Any, reference_dir: Path, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[UiSession]:
    app = start_ui(PLANS / request.param, tmp_path_factory.mktemp("plate"))
    session = open_page(browser, app)
    try:
        yield session
    finally:
        session.page.close()
        app.stop()


def test_plate_plan_validates_and_paints_the_error(plate: UiSession) -> None:
    panel = plate.app.validate_panel
    panel.trials.value = 40
    open_tab(plate.page, "Validate")
    # a click that lands while the panel is redrawn is lost on a loaded machine: click again
    # until the validation has started (a click while it runs is refused, not queued)
    act_until(
        lambda: plate.page.get_by_role("button", name="Validate plan").click(),
        lambda: panel.running or panel.last_report is not None,
        what="the validation to start",
    )
    wait_for(
        lambda: panel.last_report is not None and not panel.running,
        timeout=120,
        what="the validation",
    )
    report = panel.last_report
    assert report.n_trials == 40 and report.n_ok == 40 and report.sensor == "touch"
    wait_for(lambda: "predicted" in plate.page.inner_text("body"), what="the table on the page")
    assert "| WOCS origin x-axis |" in panel.last_markdown
    # the error map: tick the box, the work object's vertices are coloured green to red
    assert not panel.show_error.disabled
    panel.show_error.value = True
    wait_for(lambda: "place each point within" in panel.error_md.content, what="the map legend")
    painted = error_colours(report, plate.app.view.wobj_mesh)
    assert painted is not None
    rgb, lo, hi = painted
    assert rgb.shape == (len(plate.app.view.wobj_mesh.vertices), 3) and 0 < lo < hi
    assert len(np.unique(rgb, axis=0)) > 3  # a gradient over the part, not one colour
    panel.show_error.value = False
    wait_for(lambda: panel.error_md.content == "", what="the map cleared")
