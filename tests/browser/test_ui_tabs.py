"""Two browser tabs on one server (issue 14, item 9): each tab has its own selection, its
own highlight and its own robot pose; the plan is shared, so an edit in one tab shows in the
other at once, and deleting the point the other tab has selected clears that tab's selection
cleanly (no stale handle, nothing logged as an error)."""

from __future__ import annotations

import logging
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from ui_helpers import choose, click_world, open_page, open_tab, set_camera, start_ui, wait_for

from calib.frames import transform_points
from webui.app import WobjcalApp
from webui.tab_selection import HIGHLIGHT


class Tab:
    """One page (its own browser context) and its connection on the server."""

    def __init__(self, page: Any, client: Any) -> None:
        self.page, self.client = page, client

    def selected_in_page(self) -> str:
        return str(self.page.get_by_label("Selected", exact=True).input_value())

    def notifications(self) -> str:
        return " ".join(self.page.locator(".mantine-Notification-root").all_inner_texts())

    def click_world(self, p_world: Any) -> None:
        click_world(self.page, self.client, p_world)

    def row(self, point_id: str) -> str:
        rows = self.page.locator("tr").filter(has_text=point_id)
        return str(rows.first.inner_text()) if rows.count() else ""


@pytest.fixture(scope="module")
def tabs(
    browser: Any, box_plan_path: Path, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[tuple[WobjcalApp, Tab, Tab]]:
    app = start_ui(box_plan_path, tmp_path_factory.mktemp("tabs"))
    first = open_page(browser, app)  # browser.new_page: a new browser context per page
    c1 = first.client()
    second = open_page(browser, app)
    c2 = wait_for(
        lambda: next(
            (
                c
                for i, c in app.server.get_clients().items()
                if i != c1.client_id and i in app.ready_clients
            ),
            None,
        ),
        what="the second tab's connection",
    )
    one, two = Tab(first.page, c1), Tab(second.page, c2)
    for tab in (one, two):
        open_tab(tab.page, "Points")
    app.points_panel.follow.value = True  # each tab's robot stands at its selected point
    try:
        yield app, one, two
    finally:
        first.page.close()
        second.page.close()
        app.stop()


def _highlight_at(app: WobjcalApp, tab: Tab, point_id: str) -> bool:
    node = tab.client.scene.get_handle_by_name(HIGHLIGHT)
    if node is None or point_id not in app.state.doc.ids:
        return False
    p = app.state.doc.get(point_id).probe.position_m
    want = transform_points(app.view.T_world_wobj, p)
    return bool(np.allclose(node.position, want, atol=1e-9))


def test_each_tab_selects_its_own_point(tabs: tuple[WobjcalApp, Tab, Tab]) -> None:
    app, one, two = tabs
    choose(one.page, "Selected", "P1")
    choose(two.page, "Selected", "S1")
    wait_for(lambda: app.selection_of(one.client) == "P1", what="tab 1's selection")
    wait_for(lambda: app.selection_of(two.client) == "S1", what="tab 2's selection")
    # each page shows its own, not the other's
    wait_for(lambda: one.selected_in_page() == "P1", what="P1 in page 1")
    wait_for(lambda: two.selected_in_page() == "S1", what="S1 in page 2")
    # each tab's highlight is in its own scene, on its own point
    wait_for(lambda: _highlight_at(app, one, "P1"), what="page 1's highlight on P1")
    wait_for(lambda: _highlight_at(app, two, "S1"), what="page 2's highlight on S1")
    assert app.server.scene.get_handle_by_name(HIGHLIGHT) is None, "no shared highlight"
    # each tab's robot at its own point's probe pose
    robot = app.robot
    assert robot is not None
    for tab, pid in ((one, "P1"), (two, "S1")):
        check = wait_for(lambda pid=pid: app.check_of(pid), what=f"{pid}'s check")
        if check.q is not None:
            np.testing.assert_allclose(robot.q_of(tab.client.client_id), check.q)
    # each tab's settings widgets show its own point
    for tab, pid in ((one, "P1"), (two, "S1")):
        sel = app.selection.tab(tab.client.client_id)
        assert sel is not None and sel.role.value == app.state.doc.get(pid).role


def test_an_edit_in_one_tab_shows_in_the_other(tabs: tuple[WobjcalApp, Tab, Tab]) -> None:
    app, one, two = tabs
    choose(one.page, "Selected", "P2")
    wait_for(lambda: app.selection_of(one.client) == "P2", what="P2 in tab 1")
    choose(one.page, "Role", "(none)")
    one.page.get_by_role("button", name="Apply settings").click()
    try:
        wait_for(lambda: app.state.doc.get("P2").role == "", what="P2's role on the server")
        wait_for(lambda: "(none)" in two.row("P2"), what="P2's new role in page 2's table")
    finally:
        app.state.undo()
    wait_for(lambda: "(none)" not in two.row("P2"), what="the undo in page 2's table")


def test_deleting_the_point_the_other_tab_selected_clears_it(
    tabs: tuple[WobjcalApp, Tab, Tab], caplog: pytest.LogCaptureFixture
) -> None:
    app, one, two = tabs
    choose(two.page, "Selected", "S2")
    wait_for(lambda: _highlight_at(app, two, "S2"), what="page 2's highlight on S2")
    choose(one.page, "Selected", "S2")
    wait_for(lambda: app.selection_of(one.client) == "S2", what="S2 in tab 1")
    caplog.set_level(logging.WARNING)
    one.page.get_by_role("button", name="Delete point").click()
    try:
        wait_for(lambda: "S2" not in app.state.doc.ids, what="S2 deleted")
        wait_for(lambda: app.selection_of(two.client) is None, what="tab 2's selection cleared")
        wait_for(lambda: two.selected_in_page() == "(none)", what="(none) in page 2")
        wait_for(lambda: two.row("S2") == "", what="S2's row gone from page 2")
        wait_for(
            lambda: two.client.scene.get_handle_by_name(HIGHLIGHT) is None,
            what="page 2's highlight removed",
        )
        assert app.selection_of(one.client) is None
        errors = [r for r in caplog.records if r.levelno >= logging.ERROR]
        assert not errors, [r.getMessage() for r in errors]
    finally:
        app.state.undo()
    wait_for(lambda: two.row("S2") != "", what="S2 back in page 2 after the undo")


def test_a_click_through_the_tabs_robot_places_nothing(tabs: tuple[WobjcalApp, Tab, Tab]) -> None:
    """Tab 1's robot stands at a top-face point's probe pose; both tabs look down that point's
    sensor axis and click the point: tab 1 meets its tool first and is told so, nothing is
    placed or selected; tab 2, whose robot stands elsewhere, selects the point's marker."""
    app, one, two = tabs
    T = app.view.T_world_wobj
    doc = app.state.doc
    pid = next(
        p.id
        for p in doc.points
        if np.allclose(p.probe.normal, (0.0, 0.0, 1.0))
        and (c := app.check_of(p.id)) is not None
        and c.q is not None
    )
    choose(one.page, "Selected", pid)
    choose(two.page, "Selected", "(none)")
    check = app.check_of(pid)
    assert check is not None and check.q is not None
    wait_for(
        lambda: np.allclose(app.robot.q_of(one.client.client_id), check.q), what="tab 1's pose"
    )
    assert not np.allclose(app.robot.q_of(two.client.client_id), check.q)
    target = transform_points(T, doc.get(pid).probe.position_m)
    n = T[:3, :3] @ np.array([0.0, 0.0, 1.0])
    side = T[:3, :3] @ np.array([0.03, 0.0, 0.0])  # a little off the axis: a defined view
    for tab in (one, two):
        set_camera(tab.client, target + 1.2 * n + side, target)
    before = app.state.doc
    one.click_world(target)
    wait_for(lambda: "not the part" in one.notifications(), what="tab 1 told why")
    assert "nothing placed: clicked the" in one.notifications()
    assert app.state.doc is before and app.selection_of(one.client) == pid
    two.click_world(target)
    wait_for(lambda: app.selection_of(two.client) == pid, what="tab 2 selects the marker")
    assert app.state.doc is before and "not the part" not in two.notifications()
