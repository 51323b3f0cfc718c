"""When a status row came into the page and when the page drew it, timed by the page itself.

A Playwright locator's ``wait_for`` polls the page at 0, 20, 50, 100, 100 and then every
500 ms, so a row that came 300 ms after a click can be seen at up to 800 ms; a
``wait_for_function`` polled on animation frames sees it only at the next frame, which with
software WebGL can be half a second behind. Neither says where the time went. The page can:
:data:`INIT_JS` (an init script) stamps every ``pointerdown`` (the user's click, page clock),
and :func:`watch_row` arms a ``MutationObserver`` that stamps the moment the row of a point
enters (or leaves) the DOM and then the next animation frame, the frame that paints it.
:func:`row_times` reads both, in ms after the ``pointerdown``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

#: Stamps the latest ``pointerdown`` and defines ``window.__watchRow(id, present)``.
INIT_JS = """
window.__bench = {down: null, dom: null, frame: null};
document.addEventListener('pointerdown', () => { window.__bench.down = performance.now(); }, true);
window.__watchRow = (id, present) => {
  const w = window.__bench;
  w.dom = null; w.frame = null;
  if (w.observer) w.observer.disconnect();
  const holds = () => Array.from(document.querySelectorAll('td'))
    .some(td => td.textContent.trim() === id) === present;
  const stamp = () => {
    w.dom = performance.now();
    requestAnimationFrame(() => { w.frame = performance.now(); });
  };
  w.observer = new MutationObserver(() => {
    if (w.dom === null && holds()) { w.observer.disconnect(); stamp(); }
  });
  w.observer.observe(document.body, {subtree: true, childList: true, characterData: true});
};
"""


@dataclass(frozen=True)
class RowTimes:
    """One row's change as the page saw it.

    Attributes:
        dom_ms: from the ``pointerdown`` until the row was in (or out of) the DOM, ms.
        painted_ms: from the ``pointerdown`` until the next animation frame after that, the
            frame that paints the change, ms.
    """

    dom_ms: float
    painted_ms: float


def watch_row(page: Any, point_id: str, present: bool = True) -> None:
    """Arm the page to stamp when the row of ``point_id`` comes (``present``) or goes; call it
    before the click."""
    page.evaluate("([id, present]) => window.__watchRow(id, present)", [point_id, present])


def row_times(page: Any, timeout_ms: float = 30000) -> RowTimes:
    """The stamps of the watched row once its frame came (polled every 20 ms)."""
    page.wait_for_function("() => window.__bench.frame !== null", polling=20, timeout=timeout_ms)
    down, dom, frame = page.evaluate(
        "() => [window.__bench.down, window.__bench.dom, window.__bench.frame]"
    )
    return RowTimes(dom_ms=float(dom - down), painted_ms=float(frame - down))
