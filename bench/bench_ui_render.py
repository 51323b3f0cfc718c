"""Where the page's time goes after a click on the demo, in headless Chromium (issue 14).

For each setting (the server's lights, shadows and environment map; the status table sent
before or after the scene update), the same page and the same run measure:

- ``frame_ms``: the page's frame interval while it renders (a scene update opens viser's
  250 ms settle window of continuous frames; the intervals of ``requestAnimationFrame`` in it);
- ``reference_ms``: a bare Markdown update until the page shows it (Playwright polls on
  animation frames, so this is the floor of any update the page shows);
- ``click_ms``: a click on the part until the new point's row is on the page;
- ``ws_per_click``: websocket frames (and bytes) the server sends per click.

Run: ``python bench/bench_ui_render.py [--clicks 8]``; writes
``bench/results/ui_render.json``. Ratios are against the baseline setting of the same run.
"""

from __future__ import annotations

import argparse
import logging
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from bench.bench_ui_latency import page_targets
from bench.result_file import write_result
from webui.server import run
from webui.testing import free_port

RESULTS = Path(__file__).resolve().parent / "results" / "ui_render.json"
ARGS = ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"]

FRAMES_JS = """() => new Promise(done => {
    const t = []; const t0 = performance.now();
    function frame(now) { t.push(now); if (now - t0 < 1500) requestAnimationFrame(frame);
                          else done(t); }
    requestAnimationFrame(frame); })"""


def _median(x: list[float]) -> float:
    return float(statistics.median(x)) if x else float("nan")


def _frame_ms(app: Any, page: Any) -> float:
    """Median frame interval while the scene renders (kept rendering by scene updates)."""
    node = app.server.scene.add_frame("/bench_tick", show_axes=False)
    stop = [False]

    def tick() -> None:
        k = 0
        while not stop[0]:
            k += 1
            node.position = (0.0, 0.0, 1e-6 * (k % 2))  # a scene change: a render request
            time.sleep(0.1)

    import threading

    th = threading.Thread(target=tick, daemon=True)
    th.start()
    try:
        stamps = page.evaluate(FRAMES_JS)
    finally:
        stop[0] = True
        th.join()
        node.remove()
    return _median(list(np.diff(stamps)))


def _reference_ms(app: Any, page: Any, n: int) -> list[float]:
    md = app.server.gui.add_markdown("")
    out = []
    for k in range(n):
        token = f"ref-{k}-{time.perf_counter_ns()}"
        t0 = time.perf_counter()
        md.content = token
        page.wait_for_function("t => document.body.innerText.includes(t)", arg=token)
        out.append((time.perf_counter() - t0) * 1000.0)
        time.sleep(0.3)
    md.remove()
    return out


def _clicks(app: Any, page: Any, n: int, rng: np.random.Generator, ws: list) -> dict[str, Any]:
    from planner.cell.probe.reachability import sample_surface

    client = next(iter(app.server.get_clients().values()))
    cam, view = client.camera, app.view
    pts, nrm, _ = sample_surface(view.wobj_mesh, 300, rng)
    box = page.locator("canvas").first.bounding_box()
    ms: list[float] = []
    sent: list[float] = []
    frames: list[int] = []
    nbytes: list[int] = []
    for x, y in page_targets(view, cam, box, pts, nrm):
        if len(ms) >= n:
            break
        pid = f"Z{len(ms)}"
        app.points_panel.place.value = pid
        time.sleep(0.5)  # let the page settle: each click starts from an idle page
        del ws[:]
        t0 = time.perf_counter()
        page.mouse.click(float(x), float(y))
        deadline = t0 + 30.0
        while app.check_of(pid) is None and time.perf_counter() < deadline:
            time.sleep(0.001)
        if app.check_of(pid) is None:
            continue
        sent.append((time.perf_counter() - t0) * 1000.0)
        page.locator(f"td:text-is('{pid}')").first.wait_for(timeout=30000)
        ms.append((time.perf_counter() - t0) * 1000.0)
        time.sleep(0.3)
        frames.append(len(ws))
        nbytes.append(sum(ws))
        app.state.undo()
    return {"click_ms": ms, "sent_ms": sent, "ws_frames": frames, "ws_bytes": nbytes}


def _scene_first(app: Any) -> Callable[..., None]:
    """``WobjcalApp._redraw`` as it was before the table went first (one batch, scene first)."""

    def redraw(point_ids: list[str] | None = None) -> None:
        from webui.role_check import role_flags

        doc = app.state.doc
        before, app.flags = app.flags, role_flags(doc)
        if point_ids is not None:
            moved = set(before.by_point) ^ set(app.flags.by_point)
            point_ids = [*point_ids, *(i for i in moved if i not in point_ids and i in doc.ids)]
        app.scene.draw_points(doc, app.checks(), None, only=point_ids, flags=app.flags.by_point)
        app.points_panel.refresh()
        app.server.flush()

    return redraw


def _settings(app: Any) -> dict[str, Callable[[], None]]:
    scene = app.server.scene
    ours_redraw = app._redraw
    old_redraw = _scene_first(app)

    def lights_off() -> None:
        app.scene.wobj_mesh_handle.visible = True
        for k in range(4):
            scene.remove_by_name(f"/lights/side_{k}")
        scene.remove_by_name("/lights/fill")

    def base() -> None:  # viser's default lighting, the table after the scene (before issue 14)
        lights_off()
        scene.configure_default_lights(True, True)
        scene.configure_environment_map("warehouse")
        app._redraw = old_redraw

    def no_shadows() -> None:
        lights_off()
        app._redraw = old_redraw
        scene.configure_default_lights(True, False)
        scene.configure_environment_map("warehouse")

    def no_env() -> None:
        lights_off()
        app._redraw = old_redraw
        scene.configure_default_lights(True, True)
        scene.configure_environment_map(None)

    def neither() -> None:
        lights_off()
        app._redraw = old_redraw
        scene.configure_default_lights(True, False)
        scene.configure_environment_map(None)

    def ours_lighting() -> None:  # the app's lighting, the table after the scene
        from webui.scene import configure_lighting

        configure_lighting(scene)
        app._redraw = old_redraw

    def ours() -> None:  # what the app does: its lighting, the table first
        from webui.scene import configure_lighting

        configure_lighting(scene)
        app.scene.wobj_mesh_handle.visible = True
        app._redraw = ours_redraw

    def ours_no_part() -> None:  # the part's triangles not drawn (what they cost a frame)
        ours()
        app.scene.wobj_mesh_handle.visible = False

    return {
        "baseline": base,
        "no_shadows": no_shadows,
        "no_env_map": no_env,
        "neither": neither,
        "ours_lighting": ours_lighting,
        "ours": ours,
        "ours_no_part": ours_no_part,
    }


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and write ``bench/results/ui_render.json``."""
    from playwright.sync_api import sync_playwright

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clicks", type=int, default=8)
    parser.add_argument("--refs", type=int, default=8)
    parser.add_argument(
        "--order",
        nargs="*",
        default=["baseline", "ours_lighting", "ours"] * 2,
        help="settings in the order to run them (repeats allowed: interleave against drift)",
    )
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.WARNING)
    rng = np.random.default_rng(7)
    result: dict[str, Any] = {"benchmark": "ui_render", "viewport": [1400, 900]}
    with tempfile.TemporaryDirectory() as tmp, sync_playwright() as pw:
        app = run(None, port=free_port(), block=False, autosave_path=Path(tmp) / "a.json")
        browser = pw.chromium.launch(executable_path="/usr/bin/chromium", args=ARGS)
        try:
            page = browser.new_page(viewport={"width": 1400, "height": 900})
            ws: list[int] = []
            page.on(
                "websocket",
                lambda s: s.on("framereceived", lambda f: ws.append(len(f) if f else 0)),
            )
            page.goto(f"http://127.0.0.1:{app.server.get_port()}/")
            page.locator("canvas").first.wait_for(timeout=60000)
            while len(app.checks()) < 8 or not app.server.get_clients():
                time.sleep(0.05)
            client = next(iter(app.server.get_clients().values()))
            while client.camera.image_width == 0:
                time.sleep(0.05)
            time.sleep(2.0)
            rows: dict[str, Any] = {}
            settings = _settings(app)
            for k, name in enumerate(args.order):
                settings[name]()
                time.sleep(1.5)
                frame = _frame_ms(app, page)
                ref = _reference_ms(app, page, args.refs)
                clicks = _clicks(app, page, args.clicks, rng, ws)
                rows[f"{k}:{name}"] = {
                    "frame_ms": frame,
                    "reference_median_ms": _median(ref),
                    "click_median_ms": _median(clicks["click_ms"]),
                    "click_to_status_sent_median_ms": _median(clicks["sent_ms"]),
                    "click_p90_ms": float(np.percentile(clicks["click_ms"], 90)),
                    "ws_frames_per_click": _median(clicks["ws_frames"]),
                    "ws_bytes_per_click": _median(clicks["ws_bytes"]),
                    "clicks": len(clicks["click_ms"]),
                }
                logging.getLogger(__name__).warning("%s: %s", name, rows[f"{k}:{name}"])
            result["settings"] = rows
            result["triangles"] = {
                "work_object": len(app.view.wobj_mesh.faces),
                "fixtures": sum(len(m.faces) for m, _ in app.view.fixtures.values()),
            }
        finally:
            browser.close()
            app.stop()
    base = [r for key, r in result["settings"].items() if key.endswith(":baseline")]
    if base:
        click0 = _median([r["click_median_ms"] for r in base])
        frame0 = _median([r["frame_ms"] for r in base])
        for row in result["settings"].values():
            row["click_over_baseline"] = row["click_median_ms"] / click0
            row["frame_over_baseline"] = row["frame_ms"] / frame0
    write_result(RESULTS, result)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
