"""The status table's GUI updates go out before the scene's, in a websocket message of their own."""

from __future__ import annotations

import functools
import threading
import time
from collections.abc import Callable
from typing import Any

from webui.gui_first import _broadcast_buffer, flush_gui_first
from webui.testing import free_port


def _off_any_loop(test: Callable[[], None]) -> Callable[[], None]:
    """Run ``test`` on a thread of its own: in a pytest worker that ran a browser test before,
    Playwright's sync API keeps an event loop running on the main thread, where
    :func:`flush_gui_first` rightly does not wait."""

    @functools.wraps(test)
    def run() -> None:
        failure: list[BaseException] = []

        def body() -> None:
            try:
                test()
            except BaseException as exc:  # re-raised on the test's thread
                failure.append(exc)

        thread = threading.Thread(target=body)
        thread.start()
        thread.join()
        if failure:
            raise failure[0]

    return run


class _Buffer:
    """A viser broadcast buffer as far as :func:`flush_gui_first` reads it."""

    def __init__(self, counter: int, cursors: dict[int, int]) -> None:
        self.message_counter = counter
        self.generator_cursors = cursors


class _Websock:
    def __init__(self, buffer: Any) -> None:
        self.buffer = buffer

    def get_message_buffer(self) -> Any:
        return self.buffer


class _Server:
    def __init__(self, buffer: Any) -> None:
        self._websock_server = _Websock(buffer)
        self.flushes = 0

    def flush(self) -> None:
        self.flushes += 1


@_off_any_loop
def test_waits_until_every_tab_took_what_is_queued() -> None:
    buffer = _Buffer(counter=10, cursors={1: 9, 2: 4})  # tab 2 has not taken messages 5-9 yet
    server = _Server(buffer)

    def take() -> None:
        time.sleep(0.02)
        buffer.generator_cursors[2] = 9

    threading.Thread(target=take).start()
    t0 = time.monotonic()
    assert flush_gui_first(server, wait_s=5.0)  # type: ignore[arg-type]
    assert 0.015 < time.monotonic() - t0 < 4.0 and server.flushes == 1


@_off_any_loop
def test_gives_up_after_the_wait_and_without_tabs_does_not_wait() -> None:
    stuck = _Server(_Buffer(counter=10, cursors={1: 3}))
    t0 = time.monotonic()
    assert not flush_gui_first(stuck, wait_s=0.05)  # type: ignore[arg-type]
    assert 0.04 < time.monotonic() - t0 < 2.0
    assert flush_gui_first(_Server(_Buffer(counter=10, cursors={})))  # type: ignore[arg-type]


class _TabsServer(_Server):
    """Each flush queues one message more; the ``healthy`` tabs take it at once, the others
    (stalled) do not move."""

    def __init__(self, buffer: _Buffer, healthy: set[int]) -> None:
        super().__init__(buffer)
        self.buffer, self.healthy = buffer, healthy

    def flush(self) -> None:
        super().flush()
        self.buffer.message_counter += 1
        for c in self.healthy:
            self.buffer.generator_cursors[c] = self.buffer.message_counter - 1


@_off_any_loop
def test_a_stalled_tab_costs_one_wait_not_one_per_redraw() -> None:
    buffer = _Buffer(counter=10, cursors={1: 9, 2: 3, 3: 3})  # tabs 2 and 3 stalled
    server = _TabsServer(buffer, healthy={1})
    stalled: set[int] = set()
    t0 = time.monotonic()
    assert not flush_gui_first(server, wait_s=0.1, stalled=stalled)  # type: ignore[arg-type]
    first = time.monotonic() - t0
    assert 0.09 < first < 1.0, "one wait in all for both stalled tabs, not one each"
    assert stalled == {2, 3}
    t0 = time.monotonic()
    for _ in range(10):  # the next redraws: the healthy tab is not held up by the stalled ones
        assert flush_gui_first(server, wait_s=0.2, stalled=stalled)  # type: ignore[arg-type]
    assert time.monotonic() - t0 < 1.0, "10 redraws took no stalled tab's wait (2 s if they did)"
    assert stalled == {2, 3}
    # tab 2 catches up, tab 3 goes: both are waited for again (tab 2 from now on)
    buffer.generator_cursors[2] = buffer.message_counter - 1
    del buffer.generator_cursors[3]
    server.healthy.add(2)
    assert flush_gui_first(server, wait_s=0.1, stalled=stalled)  # type: ignore[arg-type]
    assert stalled == set()
    server.healthy.discard(2)  # and when it stalls again, it costs one wait again
    assert not flush_gui_first(server, wait_s=0.05, stalled=stalled)  # type: ignore[arg-type]
    assert stalled == {2}


@_off_any_loop
def test_without_a_stalled_set_every_flush_waits() -> None:
    """The plain call (no state kept) waits for every tab each time, at most ``wait_s``."""
    server = _TabsServer(_Buffer(counter=10, cursors={1: 9, 2: 3}), healthy={1})
    for _ in range(2):
        t0 = time.monotonic()
        assert not flush_gui_first(server, wait_s=0.05)  # type: ignore[arg-type]
        assert 0.04 < time.monotonic() - t0 < 1.0


@_off_any_loop
def test_a_viser_without_that_buffer_gets_a_plain_flush() -> None:
    server = _Server(buffer=None)
    assert not flush_gui_first(server)  # type: ignore[arg-type]
    assert server.flushes == 1


@_off_any_loop
def test_the_installed_viser_has_the_buffer_it_reads() -> None:
    """A viser that renamed its buffer's counter or cursors would lose the ordering silently."""
    import viser

    server = viser.ViserServer(host="127.0.0.1", port=free_port(), verbose=False)
    try:
        assert _broadcast_buffer(server) is not None
        assert flush_gui_first(server)  # no tab connected: nothing to wait for
    finally:
        server.stop()


@_off_any_loop
def test_on_an_event_loop_it_does_not_wait() -> None:
    """viser's sender runs on its event loop: waiting there would stop it."""
    import asyncio

    stuck = _Server(_Buffer(counter=10, cursors={1: 3}))

    async def on_loop() -> bool:
        return flush_gui_first(stuck, wait_s=5.0)  # type: ignore[arg-type]

    t0 = time.monotonic()
    assert not asyncio.run(on_loop())
    assert time.monotonic() - t0 < 1.0 and stuck.flushes == 1
