"""Helpers of the end-to-end UI tests: waiting, starting the UI, opening a page."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from webui.app import WobjcalApp, run
from webui.testing import free_port

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]
VIEWPORT = {"width": 1100, "height": 720}
REPO = Path(__file__).resolve().parents[2]


def wait_for(pred: Callable[[], Any], timeout: float = 30.0, what: str = "condition") -> Any:
    """Poll ``pred`` until it returns something truthy; fail the test after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = pred()
        if value:
            return value
        time.sleep(0.05)
    pytest.fail(f"timed out after {timeout} s waiting for {what}")


class UiSession:
    """A running UI server and one connected browser page."""

    def __init__(self, app: WobjcalApp, page: Any, url: str) -> None:
        self.app = app
        self.page = page
        self.url = url

    def client(self) -> Any:
        """The server-side handle of the page's connection."""
        return wait_for(
            lambda: next(iter(self.app.server.get_clients().values()), None), what="client"
        )

    def notifications(self) -> str:
        """Text of the notifications on the page."""
        return " ".join(self.page.locator(".mantine-Notification-root").all_inner_texts())


def start_ui(plan: Path | None, tmp_path: Path) -> WobjcalApp:
    """Start the UI in-process on a free port, autosaving into ``tmp_path``."""
    return run(plan, port=free_port(), block=False, autosave_path=tmp_path / "autosave.json")


def open_page(browser: Any, app: WobjcalApp) -> UiSession:
    """Open a page on ``app`` and wait until its canvas is there and it is connected."""
    page = browser.new_page(viewport=VIEWPORT, accept_downloads=True)
    url = f"http://127.0.0.1:{app.server.get_port()}/"
    page.goto(url)
    page.locator("canvas").first.wait_for(timeout=20000)
    session = UiSession(app, page, url)
    session.client()
    return session
