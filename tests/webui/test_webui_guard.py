"""The one error rule of the UI's panels (:func:`webui.guard.guarded`): a refusal is told to the
tab that acted, a defect is logged and told to that same tab in one line, never a traceback;
every panel's guard goes through it."""

from __future__ import annotations

import ast
import logging
from pathlib import Path
from typing import Any

import pytest

from calib.errors import InputError
from webui.guard import guarded

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


def test_every_panel_guard_goes_through_the_one_rule() -> None:
    """No panel catches ``InputError`` for a notification on its own any more."""
    guards = [
        (path.name, node)
        for path in sorted(WEBUI.glob("*.py"))
        for node in ast.walk(ast.parse(path.read_text()))
        if isinstance(node, ast.FunctionDef) and node.name == "_guard"
    ]
    assert len(guards) >= 7
    own = [
        f"{name}:{node.lineno}"
        for name, node in guards
        if not any(isinstance(n, ast.Name) and n.id == "guarded" for n in ast.walk(node))
    ]
    assert own == []
