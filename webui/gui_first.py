"""Send the GUI's updates on their own, before the scene's: the status row is not held for a frame.

The page applies a websocket message that holds GUI updates only (a Markdown table, a
dropdown) at once, but one that holds any scene update only in its next frame, and with
software WebGL (headless Chromium, SwiftShader) a frame of the demo cell takes 0.2-1 s on a
loaded machine. viser groups whatever is queued when its sender wakes up into one message, so
a table flushed 1 ms before the markers often went out with them and waited for that frame
(``bench/bench_ui_latency.py --demo-browser``: the row of a click arrived with the markers,
and was shown 0.5-1 s after it was sent).

:func:`flush_gui_first` flushes and waits until every connected tab's sender has taken what
is queued (a few ms, at most :data:`WAIT_S` in all, however many tabs), so the scene updates
that follow go out in the next message. A tab that has not taken them by then is *stalled*
(a slow network, a tab in the background, a page busy drawing): the caller's ``stalled`` set
remembers it, and later flushes do not wait for it until it has caught up, so one stalled tab
costs the other tabs' clicks one wait, not one per redraw. It reads the viser server's broadcast
buffer (``AsyncMessageBuffer``'s message counter and each connection's cursor, by client id); a
viser without them gets a plain flush.
"""

from __future__ import annotations

import asyncio
import time
from typing import Any

import viser

#: Longest wait for the sender to take the queued GUI updates, s; after it, the scene updates
#: are queued anyway (and may go out together with them, as before).
WAIT_S = 0.1
#: Poll interval while waiting, s.
POLL_S = 0.001


def _broadcast_buffer(server: viser.ViserServer) -> Any:
    """The server's broadcast message buffer, or ``None`` when this viser has none we know."""
    websock = getattr(server, "_websock_server", None)
    get = getattr(websock, "get_message_buffer", None)
    buffer = get() if callable(get) else None
    if not hasattr(buffer, "message_counter") or not hasattr(buffer, "generator_cursors"):
        return None
    return buffer


def _on_event_loop() -> bool:
    """True on a thread that runs an asyncio event loop (viser's own)."""
    try:
        asyncio.get_running_loop()
    except RuntimeError:
        return False
    return True


def flush_gui_first(
    server: viser.ViserServer, wait_s: float = WAIT_S, stalled: set[int] | None = None
) -> bool:
    """Flush the server-wide updates queued so far and wait (at most ``wait_s`` in all, s)
    until every connected tab's sender has taken them, so that what is queued next goes out in
    a later websocket message. With no tab connected it returns at once.

    Args:
        server: the viser server.
        wait_s: the longest wait, s, for all the tabs together.
        stalled: the client ids of tabs that did not take an earlier flush in time, kept by
            the caller from one flush to the next (updated in place; ``None``: wait for every
            tab each time). A stalled tab is not waited for until it has taken everything
            queued, or has gone; a tab that times out joins it.

    Returns:
        True when every tab waited for took them in time (False: timed out, called on an event
        loop's thread, or a viser whose buffer this does not know: a plain flush).
    """
    server.flush()
    buffer = _broadcast_buffer(server)
    if buffer is None or _on_event_loop():  # there, waiting would stop the very sender
        return False
    last = int(buffer.message_counter) - 1
    skip = stalled if stalled is not None else set()
    deadline = time.monotonic() + wait_s
    while True:
        cursors = dict(buffer.generator_cursors)
        # a stalled tab that caught up (or went) is waited for again from the next flush on
        skip.difference_update([c for c in tuple(skip) if cursors.get(c, last) >= last])
        behind = [c for c, at in cursors.items() if at < last and c not in skip]
        if not behind:
            return True
        if time.monotonic() >= deadline:
            skip.update(behind)  # not waited for again until it has caught up
            return False
        time.sleep(POLL_S)
