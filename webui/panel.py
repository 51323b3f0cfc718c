"""The base of every panel of the control panel: its tab and the one error rule.

A panel (:class:`Panel`) builds its widgets in one tab of the control panel (:attr:`Panel.TAB`,
:mod:`webui.tabs`) and runs what each of its buttons and fields does through
:meth:`Panel.guard`, which is :func:`webui.guard.guarded` for the browser tab whose event it
was: a refusal (:class:`calib.errors.InputError`) is a notification to that browser tab, titled
by the panel (or by the control), and anything else is logged and told to that tab in one line.
The sections a panel is made of (the Cell tab's tool, sensor and fixtures; the Teach tab's fine
jog; each browser tab's selected point) get the panel's :meth:`Panel.guard`, so they follow the
same rule.

The outcome of a run every tab shares (a validation's report, a suggested layout, a drawn
calibrated frame) is told to every tab: it is not an error of one tab's input.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any, ClassVar

from webui.guard import guarded

if TYPE_CHECKING:
    from webui.context import AppContext

#: What a section calls to run an action of its panel: ``guard(event, fn, *args, **options)``.
Guard = Callable[..., Any]


def client_of(event: Any) -> Any:
    """The browser tab (viser client handle) an event came from, ``None`` when it has none."""
    return getattr(event, "client", None)


class Panel:
    """A panel of the control panel: its widgets in :attr:`TAB`, its actions guarded.

    Subclasses set the class attributes, call ``super().__init__(app)`` first and build their
    widgets inside ``app.tab(self.TAB)``.

    Args:
        app: the app (what a panel may use of it: :class:`webui.context.AppContext`).
    """

    #: The control panel's tab the panel's widgets are in (:data:`webui.tabs.TAB_ORDER`).
    TAB: ClassVar[str]
    #: The title of the notification when an action did not happen, e.g. "Cell not changed".
    REFUSED: ClassVar[str] = "Not done"
    #: What the log calls the panel's actions when one fails unexpectedly.
    ACTION: ClassVar[str] = "panel action"

    def __init__(self, app: AppContext) -> None:
        self._app = app

    def guard(
        self,
        event: Any,
        fn: Callable[..., Any],
        *args: Any,
        title: str | None = None,
        refusal_is_error: bool = True,
        on_refusal: Callable[[str], None] | None = None,
    ) -> Any:
        """``fn(*args)`` for ``event``, or ``None`` after telling its browser tab why not.

        Args:
            event: the GUI event (its ``client`` is told; without one, every tab).
            fn: the action.
            title: the notification's title (default :attr:`REFUSED`).
            refusal_is_error: show a refusal as an error (red, stays) rather than a note.
            on_refusal: also called with a refusal's message (e.g. beside a field).
        """
        return guarded(
            self._app,
            client_of(event),
            fn,
            *args,
            title=self.REFUSED if title is None else title,
            action=self.ACTION,
            refusal_is_error=refusal_is_error,
            on_refusal=on_refusal,
        )
