"""Helpers of the end-to-end UI tests: waiting, starting the UI, opening a page.

The tests must pass on a loaded machine (two test suites at once on two cores): they wait on
conditions, never for a fixed time, with generous limits (:data:`TIMEOUT_S`; Playwright's own
waits get the same through the page's default timeout).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from webui.app import WobjcalApp
from webui.server import run
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
#: The page's WebGL contexts without multisampling: the scene is drawn by SwiftShader on the
#: CPU, and its 4x multisampling took about two thirds of that (the demo module: 36 of 39 s of
#: Chromium's CPU in the rasteriser's threads, 16 s without it). Only edges are drawn
#: differently, as on a GPU without multisampling.
NO_MSAA_JS = """
(() => {
  const get = HTMLCanvasElement.prototype.getContext;
  HTMLCanvasElement.prototype.getContext = function (kind, attrs) {
    if (kind === "webgl2" || kind === "webgl") attrs = { ...(attrs || {}), antialias: false };
    return get.call(this, kind, attrs);
  };
})();
"""
#: The canvas drawn at half the page's pixel density (viser's ``fixedDpr`` setting: the scene
#: at a quarter of the pixels, scaled up by the page) unless the docs' screenshots are being
#: rewritten (WOBJCAL_UPDATE_SCREENSHOTS=1). SwiftShader draws every frame on the CPU, and the
#: tests read the page's text and the scene's nodes, not its pixels: over the demo, setup and
#: glance modules, Chromium's GPU process took 58-64 s of CPU at full density, 40-43 s at half.
#: Clicks on the canvas go through its CSS box (:func:`click_world`), the same at any density.
FIXED_DPR = "" if os.environ.get("WOBJCAL_UPDATE_SCREENSHOTS") == "1" else "?fixedDpr=0.5"
REPO = Path(__file__).resolve().parents[2]
#: How long a test waits for a condition before it fails, s (generous: a loaded machine).
TIMEOUT_S = 120.0


def wait_for(pred: Callable[[], Any], timeout: float = TIMEOUT_S, what: str = "condition") -> Any:
    """Poll ``pred`` until it returns something truthy; fail the test after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = pred()
        if value:
            return value
        time.sleep(0.05)
    pytest.fail(f"timed out after {timeout} s waiting for {what}")


def act_until(
    act: Callable[[], Any],
    pred: Callable[[], Any],
    what: str,
    timeout: float = TIMEOUT_S,
    retry_s: float = 10.0,
) -> Any:
    """Do ``act`` (a click, a fill: idempotent) until ``pred`` holds: on a loaded machine a
    click can land while the panel is re-rendered by a server update and be lost; it is done
    again after ``retry_s`` without the effect, never in less. Fails after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while True:
        act()
        again = min(deadline, time.monotonic() + retry_s)
        while time.monotonic() < again:
            value = pred()
            if value:
                return value
            time.sleep(0.05)
        if time.monotonic() >= deadline:
            pytest.fail(f"timed out after {timeout} s waiting for {what}")


class UiSession:
    """A running UI server and one connected browser page."""

    def __init__(self, app: WobjcalApp, page: Any, url: str) -> None:
        self.app = app
        self.page = page
        self.url = url

    def client(self) -> Any:
        """The server-side handle of the page's connection, once the app has set the tab up
        (its own widgets, robot and first camera: a camera set before that would be undone)."""
        return wait_for(
            lambda: next(
                (
                    c
                    for c in self.app.server.get_clients().values()
                    if c.client_id in self.app.ready_clients
                ),
                None,
            ),
            what="the tab to be set up",
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
    page.add_init_script(NO_MSAA_JS)
    page.set_default_timeout(TIMEOUT_S * 1000)  # every Playwright wait: generous under load
    url = f"http://127.0.0.1:{app.server.get_port()}/{FIXED_DPR}"
    page.goto(url)
    page.locator("canvas").first.wait_for()
    session = UiSession(app, page, url)
    session.client()
    return session


def set_camera(client: Any, position: Any, look_at: Any) -> None:
    """Put the page's camera at ``position`` looking at ``look_at`` (z up) and wait until the
    browser has applied it and reported it back (not for a fixed time).

    The camera is sent again every :data:`RESEND_S` while the browser has not reported it: on a
    loaded machine a camera report the page sent before it applied ours can arrive after ours
    and stand as the page's camera (seen once in a full CI run).
    """
    want_p, want_l = np.asarray(position, float), np.asarray(look_at, float)

    def applied() -> bool:
        return bool(
            np.allclose(client.camera.position, want_p, atol=1e-3)
            and np.allclose(client.camera.look_at, want_l, atol=1e-3)
        )

    deadline = time.monotonic() + TIMEOUT_S
    while True:
        sent = client.camera._state  # replaced by each camera report from the browser
        with client.atomic():
            client.camera.up_direction = (0.0, 0.0, 1.0)
            client.camera.position = tuple(float(v) for v in position)
            client.camera.look_at = tuple(float(v) for v in look_at)
        client.flush()
        wait_until = min(deadline, time.monotonic() + RESEND_S)
        while time.monotonic() < wait_until:
            if client.camera._state is not sent and applied():
                return
            time.sleep(0.05)
        if time.monotonic() >= deadline:
            pytest.fail(
                f"timed out after {TIMEOUT_S} s waiting for the browser to apply the camera"
            )


#: How long :func:`set_camera` waits for the browser's report before it sends the camera again.
RESEND_S = 15.0


def rendered(page: Any) -> None:
    """Wait until the page has drawn two more animation frames (the new view is on screen)."""
    page.evaluate("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")


def close_notifications(page: Any) -> None:
    """Close every notification on the page (the page shows a few at a time and queues the
    rest: a test that waits for a new one must not find the stack full of earlier ones)."""
    for _ in range(50):
        buttons = page.locator(".mantine-Notification-root button")
        if buttons.count() == 0:
            return
        try:
            buttons.first.click(timeout=5000)
        except Exception:  # it closed on its own meanwhile
            continue


def open_tab(page: Any, name: str) -> None:
    """Show the control panel's tab ``name`` (Points, Cell, Teach, Validate, Files)."""
    tab = page.get_by_role("tab", name=name, exact=True)
    tab.click()
    wait_for(lambda: tab.get_attribute("aria-selected") == "true", what=f"the {name} tab")


def choose(page: Any, label: str, value: str) -> None:
    """Pick ``value`` in the dropdown labelled ``label``, as a user does (open, click)."""
    page.get_by_label(label, exact=True).click()
    page.get_by_role("option", name=value, exact=True).click()


#: Screenshots for the docs: every run writes them to ``artifacts/`` (git-ignored); with
#: WOBJCAL_UPDATE_SCREENSHOTS=1 they are also copied to ``docs/img/`` (commit them yourself).
ARTIFACTS = REPO / "artifacts"
DOCS_IMG = REPO / "docs" / "img"


def save_screenshot(page: Any, name: str, tmp_path: Path) -> Path:
    """Screenshot the page (notifications hidden) into ``artifacts/<name>``, and into
    ``docs/img/<name>`` when WOBJCAL_UPDATE_SCREENSHOTS=1; returns this run's own file."""
    import shutil

    from calib.atomic_io import write_bytes_atomic

    hidden = page.add_style_tag(content=".mantine-Notification-root { display: none !important; }")
    rendered(page)
    shot = tmp_path / name
    page.screenshot(path=str(shot))
    # shown again: a hidden notification cannot be closed (close_notifications then waited
    # 5 s on each of 50 tries) and fills the page's stack
    hidden.evaluate("e => e.remove()")
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    write_bytes_atomic(ARTIFACTS / name, shot.read_bytes())
    if os.environ.get("WOBJCAL_UPDATE_SCREENSHOTS") == "1":
        shutil.copyfile(shot, DOCS_IMG / name)
    return shot


def click_world(page: Any, client: Any, p_world: Any) -> None:
    """Click the canvas of ``page`` where ``p_world`` appears in its camera (``client``: the
    page's connection), keeping clear of the control panel."""
    from webui.testing import project_to_screen

    cam = client.camera
    u, v = project_to_screen(
        p_world, cam.position, cam.wxyz, cam.fov, cam.image_width, cam.image_height
    )
    box = page.locator("canvas").first.bounding_box()
    x = box["x"] + u * box["width"] / cam.image_width
    y = box["y"] + v * box["height"] / cam.image_height
    assert 0 < x < VIEWPORT["width"] * 0.6, "keep the target clear of the control panel"
    page.mouse.click(float(x), float(y))


def canvas_point(ui: UiSession, p_world: Any) -> tuple[float, float]:
    """Page coordinates where the world point ``p_world`` appears in the page's camera."""
    from webui.testing import project_to_screen

    cam = ui.client().camera
    u, v = project_to_screen(
        p_world, cam.position, cam.wxyz, cam.fov, cam.image_width, cam.image_height
    )
    box = ui.page.locator("canvas").first.bounding_box()
    return box["x"] + u * box["width"] / cam.image_width, box["y"] + v * box[
        "height"
    ] / cam.image_height
