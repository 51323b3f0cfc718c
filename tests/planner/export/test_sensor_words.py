"""Every program header names the plan's sensor: a touch-probe plan's programs said "Probes each
point with the proximity sensor" (helper-56, M1)."""

from __future__ import annotations

from pathlib import Path

import pytest

from calib.plan.file import load_plan
from planner.export_plan.job import export_program

PLANS = Path(__file__).resolve().parents[3] / "assets" / "plans"


@pytest.mark.parametrize(
    ("plan", "words", "not_words"),
    [
        ("plate_holes_321.json", "touch probe", "proximity sensor"),
        ("stator_section_ah.json", "proximity sensor", "touch probe"),
    ],
)
@pytest.mark.parametrize("fmt", ["rapid", "krl", "urscript"])
def test_the_header_names_the_plans_sensor(plan: str, words: str, not_words: str, fmt: str) -> None:
    loaded = load_plan(PLANS / plan, check_files=False)  # writing needs no mesh
    files = export_program(loaded, PLANS, fmt, run_check=False).files
    text = "\n".join(files.values())
    assert words in text and not_words not in text
