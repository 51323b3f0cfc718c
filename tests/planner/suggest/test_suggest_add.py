"""``wobjcal suggest --add`` never writes a point where the plan has one already.

helper-55 (D3): on the inch STEP interface plate (proximity sensor, edge searches), `wobjcal
check` advised ``suggest PLAN --add 4``; doing so added S9 and S10 exactly on the kept edge
points S5 and S4, predicted "nan mm", and wrote a plan check refuses ("points 'S4' and 'S10'
coincide"). A kept point's candidate is no candidate any more.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from calib.estimators.layout import COINCIDENT_TOL_M
from calib.plan.file import load_plan
from planner.check.job import layout_problem
from planner.cli.main import main

TEMPLATE = Path(__file__).resolve().parents[3] / "assets" / "plans" / "plate_holes_best_fit.json"


def _step_plate(reference_dir: Path, folder: Path) -> Path:
    """The interface plate (STEP, modelled in inches) on a table, one hand-placed point."""
    step = reference_dir / "cad" / "base_interface_AP214.STEP"
    p = json.loads(TEMPLATE.read_text())
    p["name"], p["description"] = "step_plate_in", "inch STEP interface plate on a table"
    p["cell"]["fixtures"] = [
        {
            "T_world_fixture": {"position_m": [1.2, 0.0, 0.36], "quat_wxyz": [1, 0, 0, 0]},
            "box_size_m": [0.4, 0.4, 0.72], "mesh": None, "name": "table", "sha256": None,
            "units": "m",
        }
    ]  # fmt: skip
    p["work_object"] = {
        "T_world_wobj": {"position_m": [1.2, 0.0, 0.74], "quat_wxyz": [1, 0, 0, 0]},
        "mesh": str(step), "sha256": None, "units": "auto",
    }  # fmt: skip
    p["validation"]["sensor"] = {"kind": "proximity"}
    p["validation"]["misplacement"] = {
        "max_translation_m": 0.005, "max_angle_rad": math.radians(1)
    }  # fmt: skip
    search = {
        "edge_direction": None, "kind": "approach", "overtravel_m": 0.015, "speed_m_s": 0.01,
        "start_offset_m": 0.015,
    }  # fmt: skip
    p["points"] = [
        {
            "edge_normal": None, "id": "T1", "normal": [0, 0, 1],
            "position_m": [0.1, 0.1, 0.00238125], "role": "fit", "search": search,
        }
    ]  # fmt: skip
    path = folder / "step_plate_in.json"
    path.write_text(json.dumps(p))
    return path


@pytest.mark.slow
def test_added_points_never_coincide_with_kept_ones(
    reference_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    start = _step_plate(reference_dir, tmp_path)
    first, more = tmp_path / "sug.json", tmp_path / "sug10.json"
    assert main(["suggest", str(start), "-o", str(first)]) == 0, capsys.readouterr().err
    kept = load_plan(first)
    assert any(p.search.kind == "edge" for p in kept.points)  # the case: kept edge points
    code = main(["suggest", str(first), "--add", "4", "-o", str(more)])
    out = capsys.readouterr().out
    assert code == 0, out
    plan = load_plan(more)
    assert [p.id for p in plan.points[: len(kept.points)]] == [p.id for p in kept.points]
    pos = np.array([p.position_m for p in plan.points])
    gap = np.linalg.norm(pos[:, None] - pos[None], axis=-1) + np.eye(len(pos))
    assert gap.min() >= COINCIDENT_TOL_M, gap.min()
    assert layout_problem(plan) == ""
    assert "nan mm" not in out
