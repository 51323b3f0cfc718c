"""Issue 22 item 3 in Chromium: after a plan is loaded through the page, the scene (the
server's, and the tab's own: robot, tool) holds exactly the objects, at the same poses, as a
fresh start of the UI on that plan: no fixtures, vias or moves left from the plan before, and
the vias of the new one drawn at once."""

from __future__ import annotations

import shutil
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from ui_helpers import UiSession, open_page, open_tab, start_ui, wait_for

from webui.server import WobjcalApp

REPO = Path(__file__).resolve().parents[2]
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"


def _scene(app: WobjcalApp, client: Any) -> dict[str, tuple[Any, ...]]:
    """``{node name: (position, orientation, visible)}`` of the server's scene and of the
    tab's own (rounded to 1 um and 1e-6: the same pose drawn twice)."""
    out: dict[str, tuple[Any, ...]] = {}
    for where, api in (("server", app.server.scene), ("tab", client.scene)):
        for name, handle in dict(api._handle_from_node_name).items():
            pos = tuple(np.round(np.asarray(handle.position, dtype=float), 6) + 0.0)
            quat = np.asarray(handle.wxyz, dtype=float)
            quat = quat if quat[0] >= 0 else -quat  # q and -q: the same rotation
            out[f"{where}:{name}"] = (pos, tuple(np.round(quat, 6) + 0.0), bool(handle.visible))
    return out


def _settled(ui: UiSession, n_points: int) -> dict[str, tuple[Any, ...]]:
    """The scene once every point is checked and drawn (the same over 1.5 s: nothing left to
    draw)."""
    app = ui.app
    wait_for(lambda: len(app.checks()) == n_points, timeout=300, what="every point checked")

    def steady() -> dict[str, tuple[Any, ...]] | None:
        first = _scene(app, ui.client())
        time.sleep(1.5)
        return first if _scene(app, ui.client()) == first else None

    return wait_for(steady, what="a steady scene")


@pytest.fixture
def session(browser: Any, box_plan_path: Path, tmp_path: Path) -> Iterator[UiSession]:
    shutil.copy(STATOR, box_plan_path.parent / STATOR.name)
    app = start_ui(box_plan_path, tmp_path / "a")
    ui = open_page(browser, app)
    try:
        yield ui
    finally:
        ui.page.close()
        app.stop()


def _fresh(browser: Any, plan: Path, tmp_path: Path, n: int) -> dict[str, tuple[Any, ...]]:
    app = start_ui(plan, tmp_path)
    ui = open_page(browser, app)
    try:
        return _settled(ui, n)
    finally:
        ui.page.close()
        app.stop()


def _upload(ui: UiSession, plan: Path) -> None:
    open_tab(ui.page, "Files")
    with ui.page.expect_file_chooser() as fc:
        ui.page.get_by_role("button", name="Upload plan (.json)").click()
    fc.value.set_files(str(plan))


def test_a_loaded_plan_gives_the_scene_of_a_fresh_load(
    session: UiSession, browser: Any, box_plan_path: Path, tmp_path: Path
) -> None:
    ui = session
    box = _settled(ui, 6)
    assert not any(k.startswith("server:/fixtures/") for k in box)
    stator = box_plan_path.parent / STATOR.name
    # box -> stator: the stator's table and its vias (C, D) drawn, as on a fresh start
    _upload(ui, stator)
    wait_for(lambda: ui.app.state.doc.method == "hultman2013", what="the stator plan loaded")
    switched = _settled(ui, 8)
    fresh = _fresh(browser, stator, tmp_path / "b", 8)
    assert "server:/fixtures/table" in fresh and any(k.startswith("server:/vias/") for k in fresh)
    assert switched == fresh, {k for k in switched.keys() ^ fresh.keys()}
    # stator -> box: the table and the vias gone
    _upload(ui, box_plan_path)
    wait_for(lambda: ui.app.state.doc.method == "three_two_one", what="the box plan loaded")
    back = _settled(ui, 6)
    assert back == box, {k for k in back.keys() ^ box.keys()}
