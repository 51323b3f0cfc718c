"""The UI's layout panel on the server side: live quality after an edit, the predicted error
on the part, and Suggest replacing the points (one undo step)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from calib.errors import InputError
from webui.app import WobjcalApp
from webui.server import run
from webui.testing import free_port

AH = Path(__file__).resolve().parents[2] / "assets" / "plans" / "stator_section_ah.json"


@pytest.fixture(scope="module")
def app(tmp_path_factory: pytest.TempPathFactory) -> Iterator[WobjcalApp]:
    folder = tmp_path_factory.mktemp("layout")
    a = run(AH, port=free_port(), block=False, autosave_path=folder / "auto.json", fresh=True)
    yield a
    a.stop()


@pytest.mark.slow
def test_quality_is_live_and_follows_an_edit(app: WobjcalApp) -> None:
    panel = app.layout_panel
    q = panel.refresh().result(60)
    assert q is not None and q.rating == "ok"
    before = q.worst_poi_m(95.5)
    assert "Layout: ok" in panel.quality_md.content
    assert "WOCS yz-plane at epsilon" in panel.quality_md.content
    # E (the rotation the F and H searches are aimed by, with D: 60 mm apart) moved to 5 mm
    # below D: their edge tracks tilt with its noise, weaker, seen live (not B towards A: the
    # RAPID program runs F's and H's edge searches from their measured face points, and the
    # final rotation is H, F, D's, so A and B no longer reach the frame)
    d = app.state.doc.get("D").probe.position_m
    app.move_point_to("E", [d[0], d[1], d[2] - 0.005])
    q2 = panel.refresh().result(60)
    assert q2 is not None and q2.worst_poi_m(95.5) > 1.5 * before
    app.state.undo()
    q3 = panel.refresh().result(60)
    assert q3 is not None and q3.worst_poi_m(95.5) == pytest.approx(before, rel=1e-9)


def test_error_map_paints_every_vertex(app: WobjcalApp, monkeypatch: pytest.MonkeyPatch) -> None:
    painted: list[Any] = []
    monkeypatch.setattr(app.scene, "color_work_object", lambda rgb, **_kw: painted.append(rgb))
    panel = app.layout_panel
    panel.refresh().result(60)
    panel.show_map.value = True
    panel._paint()
    assert painted and painted[-1] is not None
    assert np.asarray(painted[-1]).shape == (len(app.view.wobj_mesh.vertices), 3)  # type: ignore[union-attr]
    panel.show_map.value = False
    panel._paint()
    assert painted[-1] is None


@pytest.mark.slow
def test_suggest_keeps_the_procedure_and_applies_only_on_accept(app: WobjcalApp) -> None:
    from webui.layout_panel import KEEP

    panel = app.layout_panel
    before = app.state.doc.ids
    panel.target.value = 0.3
    assert panel.procedure.value == KEEP
    with pytest.raises(InputError, match="procedure is hultman2013"):
        panel.suggest()  # the A-H plan's own procedure: never switched silently
    assert app.state.doc.ids == before and panel.pending is None
    panel.procedure.value = "best fit"
    res = panel.suggest().result(300)
    assert res.met and panel.pending is res
    assert app.state.doc.ids == before, "shown, not applied"
    shown = panel.compare_md.content
    assert "| points | 8 | " in shown and "| procedure | hultman2013 | best_fit |" in shown
    assert "| landing risk |" in shown and "| cycle time |" in shown
    panel.discard()
    assert panel.pending is None and app.state.doc.ids == before
    res = panel.suggest().result(300)
    panel.accept()
    doc = app.state.doc
    assert len(doc.points) >= 6 and all(p.role == "fit" for p in doc.points)
    assert panel.refresh().result(60) is not None
    app.state.undo()
    assert app.state.doc.ids == before


def test_add_best_point_keeps_a_procedure_that_grows() -> None:
    """ "Add best point" keeps the iterative best fit (and the best fit) rather than turning the
    plan into a plain best fit; a 3-2-1 or A-H plan kept becomes a best fit, as suggest says."""
    from webui.layout_panel import suggest_procedure

    assert suggest_procedure("", "iterative", 1, "time") == ("iterative", "accuracy")
    assert suggest_procedure("", "best_fit", 1, "accuracy") == ("best_fit", "accuracy")
    assert suggest_procedure("iterative", "best_fit", 1, "accuracy") == ("iterative", "accuracy")
    assert suggest_procedure("best_fit", "iterative", 1, "accuracy") == ("best_fit", "accuracy")
    assert suggest_procedure("", "hultman2013", 1, "accuracy") == ("best_fit", "accuracy")
    assert suggest_procedure("", "three_two_one", 1, "accuracy") == ("best_fit", "accuracy")
    with pytest.raises(InputError, match="pick best fit or iterative best fit under Suggested"):
        suggest_procedure("three_two_one", "iterative", 1, "accuracy")  # picked: not switched
    # without add: the plan's procedure or the one picked, as before
    assert suggest_procedure("", "iterative", 0, "time") == ("iterative", "time")
    assert suggest_procedure("three_two_one", "hultman2013", 0, "accuracy")[0] == "three_two_one"


def test_the_messages_name_every_procedure_suggest_offers() -> None:
    from webui.layout_panel import suggest_procedure

    with pytest.raises(InputError, match="pick 3-2-1, best fit or iterative best fit under"):
        suggest_procedure("", "hultman2013", 0, "accuracy")
    with pytest.raises(
        InputError, match=r"grows point by point \(best fit or iterative best fit\)"
    ):
        suggest_procedure("three_two_one", "best_fit", 0, "time")


def test_add_best_point_on_an_iterative_plan_suggests_an_iterative_plan(
    app: WobjcalApp, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The panel passes the plan's iterative best fit to suggest (it used to force best_fit)."""
    import planner.check.job
    import planner.suggest.job
    from calib.procedures import PROCEDURES
    from planner.suggest.job import as_procedure
    from webui.layout_panel import KEEP
    from webui.plan_adapter import plan_from_ui, ui_plan_from_plan

    asked: list[dict[str, Any]] = []

    def fake_suggest(*_args: Any, **kwargs: Any) -> Any:
        asked.append(kwargs)
        raise InputError("not designed in this test")

    def no_check(*_args: Any, **_kwargs: Any) -> Any:
        raise InputError("not checked in this test")

    monkeypatch.setattr(planner.suggest.job, "suggest_plan", fake_suggest)
    monkeypatch.setattr(planner.check.job, "check_plan", no_check)
    panel = app.layout_panel
    before = app.state.doc
    iterative = as_procedure(plan_from_ui(before), PROCEDURES["iterative"])
    app.state.apply(ui_plan_from_plan(iterative, name=before.name), "iterative best fit")
    try:
        assert app.state.doc.method == "iterative"
        panel.procedure.value = KEEP
        panel.objective.value = "accuracy"
        with pytest.raises(InputError, match="not designed in this test"):
            panel.suggest(1).result(120)
        assert asked and asked[-1]["procedure"] == "iterative" and asked[-1]["add"] == 1
    finally:
        app.state.undo()
    assert app.state.doc is before
