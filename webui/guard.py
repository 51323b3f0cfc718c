"""The one error rule of the UI's panels: what a button or field does runs guarded.

:func:`guarded` runs a panel's action. A refusal (:class:`calib.errors.InputError`: the input
is wrong, the message says why) becomes a notification to the tab that acted, titled by the
panel ("Cell not changed", "Frame not changed", ...). Anything else is a defect: it is logged
with its traceback and shown to that same tab as one line naming the exception, never as a
traceback in the browser. Every panel uses it, so every panel answers the same tab the same way.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any, Protocol

from calib.errors import InputError

logger = logging.getLogger(__name__)


class Notifier(Protocol):
    """What :func:`guarded` needs of the app: a notification to one tab (or all)."""

    def notify(self, title: str, body: str, client: Any = None, error: bool = True) -> None:
        """Show ``title`` and ``body`` to ``client`` (``None``: every tab)."""
        ...


def guarded(
    app: Notifier,
    client: Any,
    fn: Callable[..., Any],
    *args: Any,
    title: str = "Not done",
    action: str = "panel action",
    refusal_is_error: bool = True,
    on_refusal: Callable[[str], None] | None = None,
) -> Any:
    """``fn(*args)``, or ``None`` after telling the acting tab why it did not happen.

    Args:
        app: the app (its ``notify``).
        client: the tab that acted (a viser client handle; ``None``: every tab).
        fn: the action.
        title: the notification's title, for a refusal and a defect alike.
        action: what the log calls the action when it fails unexpectedly.
        refusal_is_error: show a refusal as an error (red, stays) rather than a note.
        on_refusal: also called with a refusal's message (e.g. to show it beside a field).
    """
    try:
        return fn(*args)
    except InputError as exc:
        if on_refusal is not None:
            on_refusal(str(exc))
        app.notify(title, str(exc), client=client, error=refusal_is_error)
    except Exception as exc:  # never a traceback in the browser
        logger.exception("%s failed", action)
        app.notify(title, f"{type(exc).__name__}: {exc}", client=client)
    return None
