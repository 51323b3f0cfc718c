"""Uploads refused from their declared size, before a byte of them is buffered.

viser buffers every part of an upload in memory and hands the whole file to the callback only
at the end, so a size check in the callback comes after a 200 MB upload has been buffered (and
a declared 3 GB upload left open was never refused). The browser declares the size first
(``FileTransferStartUpload.size_bytes``): :func:`guard_uploads` puts a handler in front of
viser's that drops a transfer declaring more than the limit, and drops the parts of a transfer
that send more than they declared, so viser never buffers them, and tells the tab why.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Any

import viser
from viser import _messages

logger = logging.getLogger(__name__)

#: ``refused(client_id, filename, message)`` is called for every refused upload.
Refused = Callable[[int, str, str], None]


def guard_uploads(server: viser.ViserServer, max_bytes: int, refused: Refused) -> None:
    """Refuse uploads to ``server`` that declare (or send) more than ``max_bytes``.

    Args:
        server: the viser server (its upload handlers are wrapped once).
        max_bytes: largest upload accepted, bytes.
        refused: told about each refused upload, with a message naming the file and sizes.
    """
    ws: Any = server._websock_server  # viser keeps its message handlers there
    handlers = ws._incoming_handlers
    start_cls, part_cls = _messages.FileTransferStartUpload, _messages.FileTransferPart
    viser_start = list(handlers.get(start_cls, []))
    viser_part = list(handlers.get(part_cls, []))
    accepted: dict[str, list[int]] = {}  # transfer uuid -> [declared bytes, received bytes]
    lock = threading.Lock()

    def on_start(client_id: Any, message: Any) -> None:
        size = int(message.size_bytes)
        if size > max_bytes:
            text = (
                f"{message.filename}: {size / 2**20:.1f} MiB is larger than the "
                f"{max_bytes / 2**20:.0f} MiB limit for uploads; refused before any byte was read"
            )
            logger.warning("%s", text)
            refused(client_id, message.filename, text)
            return
        with lock:
            accepted[message.transfer_uuid] = [size, 0]
        for handler in viser_start:
            handler(client_id, message)

    def on_part(client_id: Any, message: Any) -> None:
        with lock:
            sizes = accepted.get(message.transfer_uuid)
            if sizes is None:
                return  # refused (or never started): viser never sees it
            sizes[1] += len(message.content)
            over = sizes[1] > sizes[0]
            if over or sizes[1] == sizes[0]:
                accepted.pop(message.transfer_uuid, None)
        if over:
            states = getattr(server.gui, "_current_file_upload_states", {})
            states.pop(message.transfer_uuid, None)
            refused(client_id, "upload", "an upload sent more bytes than it declared: dropped")
            return
        for handler in viser_part:
            handler(client_id, message)

    handlers[start_cls] = [on_start]
    handlers[part_cls] = [on_part]


__all__ = ["guard_uploads"]
