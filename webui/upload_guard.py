"""Uploads refused from their declared size, before a byte of them is buffered.

viser buffers every part of an upload in memory and hands the whole file to the callback only
at the end, so a size check in the callback comes after a 200 MB upload has been buffered (and
a declared 3 GB upload left open was never refused). The browser declares the size first
(``FileTransferStartUpload.size_bytes``): :func:`guard_uploads` puts a handler in front of
viser's that drops a transfer declaring more than the limit, and drops the parts of a transfer
that send more than they declared, so viser never buffers them, and tells the tab why. It also
bounds the uploads under way: per tab and for all tabs together (their declared bytes), and
drops an unfinished upload that went silent or whose tab left (issue 27).
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import viser
from viser import _messages

from calib.limits import MAX_UPLOADS_IN_FLIGHT_BYTES, MAX_UPLOADS_PER_CLIENT, UPLOAD_IDLE_TIMEOUT_S

logger = logging.getLogger(__name__)

#: ``refused(client_id, filename, message)`` is called for every refused upload.
Refused = Callable[[int, str, str], None]


def guard_uploads(
    server: viser.ViserServer,
    max_bytes: int,
    refused: Refused,
    *,
    per_client: int = MAX_UPLOADS_PER_CLIENT,
    in_flight_bytes: int = MAX_UPLOADS_IN_FLIGHT_BYTES,
    idle_s: float = UPLOAD_IDLE_TIMEOUT_S,
) -> None:
    """Refuse uploads to ``server`` that declare (or send) more than ``max_bytes``, or that
    would make one tab's unfinished uploads more than ``per_client`` or all tabs' more than
    ``in_flight_bytes`` (issue 27: 24 unfinished uploads took the server from 697 to 1,552 MB).

    An unfinished upload that sent nothing for ``idle_s`` seconds is dropped when another one
    starts; a tab's unfinished uploads are dropped when it disconnects.

    Args:
        server: the viser server (its upload handlers are wrapped once).
        max_bytes: largest upload accepted, bytes.
        refused: told about each refused upload, with a message naming the file and sizes.
        per_client: most unfinished uploads of one tab.
        in_flight_bytes: most bytes declared by the unfinished uploads of all tabs.
        idle_s: an unfinished upload silent this long is dropped, s.
    """
    ws: Any = server._websock_server  # viser keeps its message handlers there
    handlers = ws._incoming_handlers
    start_cls, part_cls = _messages.FileTransferStartUpload, _messages.FileTransferPart
    viser_start = list(handlers.get(start_cls, []))
    viser_part = list(handlers.get(part_cls, []))
    accepted: dict[str, _Transfer] = {}  # transfer uuid -> the upload under way
    lock = threading.Lock()

    def drop(uuid: str) -> None:  # with ``lock`` held
        accepted.pop(uuid, None)
        getattr(server.gui, "_current_file_upload_states", {}).pop(uuid, None)

    def admit(client_id: Any, message: Any, size: int) -> str:
        """Why the upload cannot start now (``""``: it is accepted and counted)."""
        name = message.filename
        if size > max_bytes:
            return (
                f"{name}: {size / 2**20:.1f} MiB is larger than the "
                f"{max_bytes / 2**20:.0f} MiB limit for uploads; refused before any byte was read"
            )
        now = time.monotonic()
        with lock:
            for uuid in [u for u, t in accepted.items() if now - t.last > idle_s]:
                logger.warning("dropped an upload silent for %.0f s", now - accepted[uuid].last)
                drop(uuid)
            mine = sum(t.client == client_id for t in accepted.values())
            if mine >= per_client:
                return (
                    f"{name}: this tab has {mine} uploads under way, at most {per_client} at a "
                    "time (each is held in the server's memory until it is complete); wait "
                    "for them to finish"
                )
            busy = sum(t.declared for t in accepted.values())
            if busy + size > in_flight_bytes:
                return (
                    f"{name}: {size / 2**20:.1f} MiB more would make the uploads under way "
                    f"{(busy + size) / 2**20:.1f} MiB, at most {in_flight_bytes / 2**20:.0f} MiB "
                    "at a time for all tabs (they are held in the server's memory until "
                    "complete); try again when they are done"
                )
            accepted[message.transfer_uuid] = _Transfer(client_id, size, 0, now)
        return ""

    def on_start(client_id: Any, message: Any) -> None:
        why = admit(client_id, message, int(message.size_bytes))
        if why:
            logger.warning("%s", why)
            refused(client_id, message.filename, why)
            return
        for handler in viser_start:
            handler(client_id, message)

    def on_part(client_id: Any, message: Any) -> None:
        with lock:
            transfer = accepted.get(message.transfer_uuid)
            if transfer is None:
                return  # refused, dropped (or never started): viser never sees it
            transfer.received += len(message.content)
            transfer.last = time.monotonic()
            over = transfer.received > transfer.declared
            if over:
                drop(message.transfer_uuid)
            elif transfer.received == transfer.declared:
                accepted.pop(message.transfer_uuid, None)
        if over:
            refused(client_id, "upload", "an upload sent more bytes than it declared: dropped")
            return
        for handler in viser_part:
            handler(client_id, message)

    def on_disconnect(client: Any) -> None:
        with lock:
            for uuid in [u for u, t in accepted.items() if t.client == client.client_id]:
                drop(uuid)

    handlers[start_cls] = [on_start]
    handlers[part_cls] = [on_part]
    server.on_client_disconnect(on_disconnect)


@dataclass
class _Transfer:
    """An upload under way: whose, declared and received bytes, last activity (monotonic s)."""

    client: Any
    declared: int
    received: int
    last: float


__all__ = ["guard_uploads"]
