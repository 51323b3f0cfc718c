"""Fixtures of the end-to-end UI tests: one headless Chromium, a UI server per test on a free port.

Chromium is the Debian package at ``/usr/bin/chromium`` driven by Playwright (``playwright
install`` cannot download browsers here); WebGL runs on SwiftShader.
"""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from ui_helpers import CHROMIUM, CHROMIUM_ARGS, UiSession, open_page, start_ui

from webui.testing import box_plan

HERE = Path(__file__).resolve().parent


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Every test in this folder is a browser test (the marker is set by the directory:
    ``-m "not browser"`` leaves them out without a marker in each file)."""
    for item in items:
        if HERE in Path(str(item.path)).resolve().parents:
            item.add_marker(pytest.mark.browser)


@pytest.fixture(scope="session")
def browser() -> Iterator[Any]:
    """One headless Chromium for the whole session."""
    if shutil.which(CHROMIUM) is None:
        pytest.skip(f"{CHROMIUM} not installed")
    sync_api = pytest.importorskip("playwright.sync_api")
    with sync_api.sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        yield b
        b.close()


@pytest.fixture(scope="module", autouse=True)
def server_memory_only(request: pytest.FixtureRequest) -> Iterator[None]:
    """The validate panel's memory budget counts what this module's UI adds to the process.

    The UI server runs inside the pytest worker, which has held every earlier test's arrays,
    cells and caches (3 GB late in a full run): the panel read that as the server's and refused
    a 40-trial validation as over its 2 GB budget, and the test waited 120 s for a run that never
    started. The budget itself is tested in ``tests/webui/test_webui_validate_budget.py``.
    """
    from webui import validate_panel

    real = validate_panel._rss_bytes
    baseline = real()
    mp = pytest.MonkeyPatch()
    mp.setattr(validate_panel, "_rss_bytes", lambda: max(real() - baseline, 0))
    try:
        yield
    finally:
        mp.undo()


@pytest.fixture(scope="session")
def box_plan_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 3-2-1 plan on a box work object (mesh file next to the plan)."""
    return box_plan(tmp_path_factory.mktemp("plan"))


@pytest.fixture(scope="module")
def ui(
    browser: Any, box_plan_path: Path, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[UiSession]:
    """The UI on the box plan, with one page open (shared by a module's tests)."""
    app = start_ui(box_plan_path, tmp_path_factory.mktemp("ui"))
    session = open_page(browser, app)
    try:
        yield session
    finally:
        session.page.close()
        app.stop()


@pytest.fixture(scope="module")
def demo(browser: Any, tmp_path_factory: pytest.TempPathFactory) -> Iterator[UiSession]:
    """The UI on the built-in demo (stator section, A-H plan), with one page open."""
    app = start_ui(None, tmp_path_factory.mktemp("demo"))
    session = open_page(browser, app)
    try:
        yield session
    finally:
        session.page.close()
        app.stop()
