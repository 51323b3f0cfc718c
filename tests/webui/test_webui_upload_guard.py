"""Uploads refused from their declared size before buffering (issue 10, item 7)."""

from __future__ import annotations

import pytest
from viser import _messages

from webui.app import WobjcalApp
from webui.files_panel import MAX_UPLOAD_BYTES


def _send(app: WobjcalApp, message: object) -> None:
    """Deliver ``message`` as viser's websocket server would (its handlers, in order)."""
    for handler in list(app.server._websock_server._incoming_handlers[type(message)]):
        handler(0, message)


def _start(app: WobjcalApp, uuid: str, size: int, parts: int) -> None:
    source = app.files_panel.plan_upload._impl.uuid  # the "Upload plan" button
    _send(
        app,
        _messages.FileTransferStartUpload(
            source_component_uuid=source,
            transfer_uuid=uuid,
            filename="huge.json",
            mime_type="application/json",
            part_count=parts,
            size_bytes=size,
        ),
    )


def test_a_declared_3_gb_upload_is_refused_before_any_byte(
    app: WobjcalApp, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Before: a 200 MB upload was buffered whole before being refused (server memory 336 ->
    712 MB), and a declared 3 GB upload left open was never refused."""
    said: list[str] = []
    monkeypatch.setattr(app, "notify", lambda title, body, **kw: said.append(body))
    states = app.server.gui._current_file_upload_states
    _start(app, "t-huge", 3 << 30, 100_000)
    assert "t-huge" not in states  # viser keeps no state: nothing will be buffered
    assert said and "3072.0 MiB is larger than the 50 MiB limit" in said[0]
    _send(app, _messages.FileTransferPart(None, "t-huge", 0, b"x" * 1024))
    assert "t-huge" not in states


def test_an_upload_within_the_limit_goes_through_and_cannot_overrun(
    app: WobjcalApp, monkeypatch: pytest.MonkeyPatch
) -> None:
    said: list[str] = []
    monkeypatch.setattr(app, "notify", lambda title, body, **kw: said.append(body))
    states = app.server.gui._current_file_upload_states
    _start(app, "t-ok", 10, 2)
    assert "t-ok" in states and MAX_UPLOAD_BYTES == 50 << 20
    _send(app, _messages.FileTransferPart(None, "t-ok", 0, b"x" * 5))
    assert states["t-ok"]["transferred_bytes"] == 5
    _send(app, _messages.FileTransferPart(None, "t-ok", 1, b"y" * 4096))  # more than declared
    assert "t-ok" not in states and "more bytes than it declared" in said[-1]
