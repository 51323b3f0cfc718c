"""The one error rule of the UI's panels (:func:`webui.guard.guarded`): a refusal is told to the
tab that acted, a defect is logged and told to that same tab in one line, never a traceback.
Every panel derives from :class:`webui.panel.Panel` and runs its controls through its
:meth:`~webui.panel.Panel.guard`: checked here from the source, and by firing one real control
of every panel of a running app with an action that refuses."""

from __future__ import annotations

import ast
import logging
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from calib.errors import InputError
from webui.guard import guarded
from webui.panel import Panel

WEBUI = Path(__file__).resolve().parents[2] / "webui"


class _App:
    def __init__(self) -> None:
        self.said: list[tuple[str, str, Any, bool]] = []

    def notify(self, title: str, body: str, client: Any = None, error: bool = True) -> None:
        self.said.append((title, body, client, error))


def test_the_result_passes_and_nothing_is_said() -> None:
    app = _App()
    assert guarded(app, "tab", lambda a, b: a + b, 2, 3) == 5
    assert app.said == []


def test_a_refusal_is_told_to_the_acting_tab_and_beside_the_field() -> None:
    app, beside = _App(), []

    def refuse() -> None:
        raise InputError("J3: 200 deg is beyond its limit 180 deg")

    out = guarded(app, "tab 2", refuse, title="Not moved", refusal_is_error=False,
                  on_refusal=beside.append)  # fmt: skip
    assert out is None
    assert app.said == [("Not moved", "J3: 200 deg is beyond its limit 180 deg", "tab 2", False)]
    assert beside == ["J3: 200 deg is beyond its limit 180 deg"]


def test_a_defect_is_logged_and_told_to_the_same_tab_in_one_line(
    caplog: pytest.LogCaptureFixture,
) -> None:
    app = _App()

    def broken() -> None:
        raise KeyError("x")

    with caplog.at_level(logging.ERROR, logger="webui.guard"):
        assert guarded(app, "tab 1", broken, title="Cell not changed", action="cell edit") is None
    assert app.said == [("Cell not changed", "KeyError: 'x'", "tab 1", True)]
    assert "cell edit failed" in caplog.text and "Traceback" in caplog.text


def _sources() -> dict[str, ast.Module]:
    return {path.name: ast.parse(path.read_text()) for path in sorted(WEBUI.glob("*.py"))}


def _panel_classes() -> dict[str, list[str]]:
    """``{name: names of its bases}`` of every class of ``webui`` named ``...Panel``, the base
    aside (read from the source: importing the UI takes seconds)."""
    return {
        node.name: [getattr(b, "id", "") for b in node.bases]
        for tree in _sources().values()
        for node in tree.body
        if isinstance(node, ast.ClassDef) and node.name.endswith("Panel") and node.name != "Panel"
    }


def test_every_panel_derives_from_the_base_and_no_panel_guards_on_its_own() -> None:
    """No ``_guard`` copies any more; ``guarded`` is called by the base and, for a click on the
    3D view (which no panel owns), by the app; no handler catches an input error to notify
    by hand, except where a shared background run tells every tab how it ended."""
    panels = _panel_classes()
    assert len(panels) >= 8
    assert [name for name, bases in panels.items() if bases != ["Panel"]] == []
    sources = _sources()
    guards = [
        f"{name}:{node.lineno}"
        for name, tree in sources.items()
        for node in ast.walk(tree)
        if isinstance(node, ast.FunctionDef) and node.name == "_guard"
    ]
    assert guards == []
    callers = {
        name
        for name, tree in sources.items()
        for node in ast.walk(tree)
        if isinstance(node, ast.Call) and getattr(node.func, "id", "") == "guarded"
    }
    assert callers == {"panel.py", "app.py"}
    own = []
    for name, tree in sources.items():
        for fn in ast.walk(tree):
            if not isinstance(fn, ast.FunctionDef):
                continue
            for h in ast.walk(fn):
                if not isinstance(h, ast.ExceptHandler) or h.type is None:
                    continue
                caught = {n.id for n in ast.walk(h.type) if isinstance(n, ast.Name)}
                notifies = any(
                    isinstance(n, ast.Attribute) and n.attr == "notify"
                    for b in h.body
                    for n in ast.walk(b)
                )
                if notifies and caught & {"InputError", "PlanError", "UploadError"}:
                    own.append(f"{name}:{fn.name}")
    assert sorted(own) == ["guard.py:guarded", "validate_panel.py:_show"]


#: One control of every panel: the widget, the panel's action its handler runs (replaced by
#: one that fails) and the value the event carries (an upload's file).
_UPLOAD = SimpleNamespace(name="measured.json", content=b"{}")
CONTROLS: dict[str, tuple[str, str, Any]] = {
    "PointsPanel": ("drag", "_update_gizmo", None),
    "CellPanel": ("apply", "apply_fields", None),
    "FramePanel": ("start", "begin", None),
    "TeachPanel": ("teach_button", "teach", None),
    "ValidatePanel": ("button", "start", None),
    "FilesPanel": ("accept", "accept_mesh", None),
    "CalibratePanel": ("upload", "calibrate", _UPLOAD),
    "LayoutPanel": ("suggest_button", "suggest", None),
}


def _failing(exc: Exception) -> Callable[..., None]:
    def action(*_args: Any) -> None:
        raise exc

    return action


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["refusal", "defect"])
def test_a_failure_in_any_panels_control_is_told_to_the_tab_that_used_it(
    app: Any, kind: str, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """For every panel of the app: its control's handler, fired from one browser tab with an
    action that refuses (or breaks), tells that tab, under the panel's title."""
    panels = {type(v).__name__: v for v in vars(app).values() if isinstance(v, Panel)}
    assert set(panels) == set(CONTROLS) == set(_panel_classes())
    assert all(p.TAB in app.tabs.names for p in panels.values())  # the tab it builds in
    said: list[tuple[str, str, Any, bool]] = []
    monkeypatch.setattr(
        app, "notify", lambda t, b, client=None, error=True: said.append((t, b, client, error))
    )
    for name, (widget, action, value) in CONTROLS.items():
        panel, tab = panels[name], SimpleNamespace(client_id=-7)
        exc = InputError(f"{name} refuses") if kind == "refusal" else KeyError(name)
        monkeypatch.setattr(panel, action, _failing(exc))
        handle = getattr(panel, widget)
        event = SimpleNamespace(client=tab, client_id=-7, target=SimpleNamespace(value=value))
        said.clear()
        with caplog.at_level(logging.ERROR, logger="webui.guard"):
            for callback in list(handle._impl.update_cb):
                callback(event)
        body = f"{name} refuses" if kind == "refusal" else f"KeyError: {name!r}"
        assert said == [(panel.REFUSED, body, tab, True)], name
    if kind == "defect":
        assert caplog.text.count("Traceback") == len(CONTROLS)
