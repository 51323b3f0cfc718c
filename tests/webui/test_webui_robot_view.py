"""The robot in the UI scene (issue 10, item 10): a URDF whose COLLADA visuals cannot be read
(pycollada missing) said "internal error: ImportError"; now the robot is not drawn, the reason
names the file and the fix, and everything else works."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
import trimesh

from planner.builtins import robot_urdf
from webui.server import run
from webui.testing import free_port

REPO = Path(__file__).resolve().parents[2]
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"


def _plan_with_dae_visual(folder: Path) -> Path:
    (folder / "box.dae").write_bytes(
        trimesh.exchange.dae.export_collada(trimesh.creation.box([0.1, 0.1, 0.1]))
    )
    text = robot_urdf("builtin:irb4400").read_text()
    i = text.index("<visual>")
    j = text.index("</visual>", i) + len("</visual>")
    visual = '<visual><geometry><mesh filename="box.dae"/></geometry></visual>'
    (folder / "robot.urdf").write_text(text[:i] + visual + text[j:])
    doc = json.loads(STATOR.read_text())
    doc["cell"]["robot"]["urdf"] = "robot.urdf"
    (folder / "plan.json").write_text(json.dumps(doc))
    return folder / "plan.json"


@pytest.mark.slow
def test_dae_visuals_are_drawn_with_pycollada(tmp_path: Path) -> None:
    pytest.importorskip("collada")  # declared in pyproject.toml for this
    app = run(_plan_with_dae_visual(tmp_path), port=free_port(), block=False, autosave_path=None)
    try:
        assert app.robot is not None
    finally:
        app.stop()


def test_without_pycollada_the_robot_is_not_drawn_and_it_says_why(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    plan = _plan_with_dae_visual(tmp_path)
    monkeypatch.setitem(sys.modules, "collada", None)  # as if pycollada were not installed
    said: list[str] = []
    import webui.app

    monkeypatch.setattr(
        webui.app.WobjcalApp, "notify", lambda self, title, body, **kw: said.append(body)
    )
    app = run(plan, port=free_port(), block=False, autosave_path=None)
    try:
        assert app.robot is None and app.view is not None
        assert said and "robot.urdf cannot be read" in said[0] and "pycollada" in said[0]
        assert app.check_of("A") is not None  # the checks still run
    finally:
        app.stop()
