"""Issue 13 in Chromium, on the demo (A-H plan): the Layout tab shows the predicted quality,
follows a moved point, and its buttons suggest a layout (progress, one undo step) and add the
best next point. Every step checks the server's state (the panel's ``last`` quality, the
plan's points) as well as the page."""

from __future__ import annotations

import threading
from pathlib import Path

import pytest
from ui_helpers import UiSession, choose, open_tab, save_screenshot, wait_for

from planner.sim.quality import LayoutQuality

LEVEL = 95.5


def _poi_line(q: LayoutQuality) -> str:
    """The page's line of the first point of interest (as the panel writes it)."""
    p = q.poi[0]
    return f"{p.label}: {p.at(LEVEL) * 1e3:.3f} mm at {LEVEL:g} %"


def _shown(ui: UiSession, q: LayoutQuality) -> bool:
    return _poi_line(q) in ui.page.inner_text("body")


def _settled(ui: UiSession) -> LayoutQuality:
    """The panel's quality of the current points, once computed (server state)."""
    return ui.app.layout_panel.refresh().result(120)


def test_layout_tab_shows_the_quality_and_follows_a_moved_point(demo: UiSession) -> None:
    app, page = demo.app, demo.page
    panel = app.layout_panel
    open_tab(page, "Layout")
    q0 = wait_for(lambda: panel.last, what="the A-H layout's quality on the server")
    assert q0.rating == "ok" and len(q0.poi) == 2
    wait_for(lambda: "Layout: ok" in page.inner_text("body"), what="the rating in the page")
    wait_for(lambda: _shown(demo, q0), what=f"'{_poi_line(q0)}' in the page")
    assert "weakest:" in page.inner_text("body") and "noise gain" in page.inner_text("body")
    before = q0.worst_poi_m(LEVEL)
    # E moved to 5 mm below D (D and E aim F's and H's edge tracks): weaker, live (the RAPID
    # program runs F and H from their measured face points: A and B no longer reach the frame)
    d = app.state.doc.get("D").probe.position_m
    app.move_point_to("E", [d[0], d[1], d[2] - 0.005])
    try:
        q1 = wait_for(
            lambda: (
                panel.last
                if panel.last is not None and panel.last.worst_poi_m(LEVEL) > 1.5 * before
                else None
            ),
            what="the server's quality after E moved",
        )
        wait_for(lambda: _shown(demo, q1), what=f"'{_poi_line(q1)}' in the page")
        assert not _shown(demo, q0)
    finally:
        app.state.undo()
    q2 = wait_for(
        lambda: (
            panel.last
            if panel.last is not None
            and panel.last.worst_poi_m(LEVEL) == pytest.approx(before, rel=1e-9)
            else None
        ),
        what="the quality back after undo",
    )
    wait_for(lambda: _shown(demo, q2), what="the A-H quality in the page again")


def test_suggest_keeps_the_plans_procedure_unless_another_is_picked(demo: UiSession) -> None:
    """On the A-H plan, "Suggest layout" with the default "keep the plan's" procedure says
    what to pick and changes nothing (it used to switch to a best fit silently)."""
    app, page = demo.app, demo.page
    open_tab(page, "Layout")
    ah = app.state.doc
    assert app.layout_panel.procedure.value == "keep the plan's"
    page.get_by_role("button", name="Suggest layout", exact=True).click()
    text = wait_for(
        lambda: "Not suggested" in demo.notifications() and demo.notifications(),
        what="the refusal",
    )
    assert (
        "the plan's procedure is hultman2013" in text
        and "pick 3-2-1, best fit or iterative best fit under Suggested procedure" in text
    )
    assert app.state.doc is ah
    assert not page.get_by_role("button", name="Accept suggestion").is_visible()


def test_suggest_shows_progress_and_replaces_the_points_in_one_undo_step(
    demo: UiSession, tmp_path: Path
) -> None:
    app, page = demo.app, demo.page
    panel = app.layout_panel
    open_tab(page, "Layout")
    ah_ids = app.state.doc.ids
    assert ah_ids == ("A", "B", "C", "D", "E", "F", "G", "H")
    n_max = int(panel.max_points.value)
    choose(page, "Suggested procedure", "best fit")
    wait_for(lambda: panel.procedure.value == "best fit", what="best fit picked (server)")
    # hold the cell's worker so the suggestion waits in the queue: the progress bar and the
    # disabled buttons are then on screen for as long as the test needs to see them
    gate = threading.Event()
    app.worker.submit(lambda _s: gate.wait(120))
    suggest = page.get_by_role("button", name="Suggest layout", exact=True)
    try:
        suggest.click()
        wait_for(lambda: panel.progress.visible, what="the progress bar on the server")
        # the bar's root: at 0 % its fill (role "progressbar") has no width, so Playwright
        # counts the fill as hidden however long it waits
        page.locator(".mantine-Progress-root").first.wait_for(state="visible")
        wait_for(suggest.is_disabled, what="the Suggest button disabled while it runs")
        assert app.state.doc.ids == ah_ids, "nothing replaced before the suggestion is done"
    finally:
        gate.set()
    # shown beside the current layout, applied only on accept
    accept = page.get_by_role("button", name="Accept suggestion", exact=True)
    accept.wait_for(state="visible")
    wait_for(lambda: "Layout suggested" in demo.notifications(), what="the notification")
    body = page.inner_text("body")
    assert "Suggestion (not applied)" in body and "hultman2013" in body and "best_fit" in body
    for row in ("predicted error", "landing risk", "cycle time"):
        assert row in body, row
    assert app.state.doc.ids == ah_ids, "nothing replaced before accept"
    accept.scroll_into_view_if_needed()
    save_screenshot(page, "suggest_compare.png", tmp_path)
    accept.click()
    wait_for(lambda: app.state.doc.ids != ah_ids, what="the suggested points on the server")
    accept.wait_for(state="hidden")
    doc = app.state.doc
    assert doc.method == "best_fit" and all(p.role == "fit" for p in doc.points)
    assert 6 <= len(doc.points) <= n_max
    wait_for(lambda: not panel.progress.visible, what="the progress bar to go (server)")
    assert panel.progress.value > 0.0, "the suggestion reported its progress"
    page.locator(".mantine-Progress-root").first.wait_for(state="detached")  # viser drops it
    wait_for(suggest.is_enabled, what="the Suggest button back")
    q = _settled(demo)
    assert q is not None and q.rating == "ok"
    wait_for(lambda: _shown(demo, q), what="the suggested layout's quality in the page")
    suggested = doc.ids

    # "Add best point": the suggested points kept, one more, on accept
    page.get_by_role("button", name="Add best point", exact=True).click()
    accept.wait_for(state="visible")
    assert app.state.doc.ids == suggested
    accept.click()
    wait_for(lambda: len(app.state.doc.points) == len(suggested) + 1, what="one point added")
    added = app.state.doc.ids
    assert added[: len(suggested)] == suggested
    for old in suggested:  # the kept points did not move
        assert app.state.doc.get(old).probe == doc.get(old).probe
    wait_for(lambda: not panel.progress.visible, what="the progress bar to go")

    # one undo step each: the add, then the whole suggestion
    app.state.undo()
    assert app.state.doc.ids == suggested
    app.state.undo()
    assert app.state.doc.ids == ah_ids and app.state.doc.method == "hultman2013"
    q_ah = _settled(demo)
    assert q_ah is not None and q_ah.rating == "ok"
    wait_for(lambda: _shown(demo, q_ah), what="the A-H quality in the page after undo")
