"""Two changes of cell at once (an undo clicked twice, an edit during an undo's reload, a redo
while an undo's cell is being built) load one after the other, and the scene ends with the
cell of the plan the session holds.

Seen in a browser test: a fixture added while two undos were reloading their cells failed
with "Cannot assign to 'visible' on a removed MeshHandle" (each reload drew the work object
and took the other's half-made nodes away), and the robot was not drawn.
"""

from __future__ import annotations

import threading
from collections.abc import Mapping
from typing import Any

import pytest

from calib.plan.file import Plan
from webui.app import WobjcalApp
from webui.cell_setup_edits import box_fixture, with_fixture
from webui.testing import wait_until

TIMEOUT_S = 120.0


def _with_box(plan: Plan, name: str, y_mm: float) -> Plan:
    """``plan`` with a 100 mm box fixture ``name`` 2 m beside the cell (world mm)."""
    return with_fixture(plan, box_fixture(plan, name, (100, 100, 100), (0.0, y_mm, 0.0)))


def test_two_undos_at_once_leave_the_cell_of_the_latest_plan_drawn(
    app: WobjcalApp, monkeypatch: pytest.MonkeyPatch
) -> None:
    plan = app.state.doc.source
    assert isinstance(plan, Plan) and plan.cell.fixtures == []
    one = _with_box(plan, "one", 2000.0)
    app.replace_source(one, "add one")
    app.replace_source(_with_box(one, "two", -2000.0), "add two")
    assert sorted(app.view.fixtures) == ["one", "two"]

    drawn: list[list[str]] = []  # the fixtures of every cell drawn, in order
    first_drawing, second_drew = threading.Event(), threading.Event()
    draw = app.scene.draw_fixtures

    def held(fixtures: Mapping[str, Any]) -> None:
        if not first_drawing.is_set():  # the first undo's cell: drawn slowly
            first_drawing.set()
            second_drew.wait(2.0)  # loads one at a time: the second cannot draw meanwhile
        else:
            second_drew.set()
        draw(fixtures)
        drawn.append(sorted(fixtures))

    monkeypatch.setattr(app.scene, "draw_fixtures", held)
    first = threading.Thread(target=app.state.undo)
    first.start()
    assert first_drawing.wait(TIMEOUT_S), "the first undo did not draw its cell"
    second = threading.Thread(target=app.state.undo)
    second.start()
    first.join(TIMEOUT_S)
    second.join(TIMEOUT_S)
    assert not first.is_alive() and not second.is_alive()

    assert app.state.doc.source.cell.fixtures == []  # both undone
    assert drawn[-1] == [], f"the scene ends with the fixtures {drawn[-1]} of an undone plan"
    assert app.view.fixtures == {}
    assert "/fixtures/one" not in app.server.scene._handle_from_node_name
    wait_until(lambda: len(app.checks()) == len(app.state.doc.points), "the points checked again")


def test_a_redo_while_the_undos_cell_is_built_leaves_the_redone_cell_drawn(
    app: WobjcalApp,
) -> None:
    """The redo's plan has the cell still shown while the undo's is being built: its change
    looks like no change of cell, and the undo's reload, which read the plan before the redo,
    must not be the last cell drawn (found by a reviewer: the scene kept the undone cell)."""
    plan = app.state.doc.source
    assert isinstance(plan, Plan) and plan.cell.fixtures == []
    app.replace_source(_with_box(plan, "one", 2000.0), "add one")
    assert sorted(app.view.fixtures) == ["one"]
    gate = threading.Event()
    app.worker.submit(lambda _: gate.wait(TIMEOUT_S))  # the undo's cell waits behind this
    undo = threading.Thread(target=app.state.undo)
    undo.start()
    wait_until(lambda: "loading the cell" in app.busy.text, "the undo to start its cell")
    app.state.redo()  # the cell shown is the redo's: nothing to load, as the change sees it
    gate.set()
    undo.join(TIMEOUT_S)
    assert not undo.is_alive()
    assert [f.name for f in app.state.doc.source.cell.fixtures] == ["one"]
    assert sorted(app.view.fixtures) == ["one"], "the scene shows the cell of the undone plan"
    wait_until(lambda: len(app.checks()) == len(app.state.doc.points), "the points checked again")
