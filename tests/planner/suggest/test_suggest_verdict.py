"""Suggest never proposes a point ``wobjcal check`` refuses when another layout exists, and a
refusal says what would make a layout exist.

When check refuses points of the written plan (here: a check that refuses the first design's
first point, as a landing risk would), their candidates are set aside and the design redone;
the result passes check and says so. The refusal on a part whose faces cannot hold the layout
names the bound at which one exists, or the adaptive program that has one.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import msgspec
import numpy as np
import pytest

import planner.suggest.job as suggest_mod
from calib.models import Misplacement
from calib.plan.file import load_plan
from planner.check.results import PlanCheck
from planner.reasons import Reason
from planner.suggest import SuggestError, suggest_plan

#: every test here runs a shipped plate plan, whose mesh is in ../shared/reference
pytestmark = pytest.mark.reference

PLANS = Path(__file__).resolve().parents[3] / "assets" / "plans"


@pytest.mark.slow
def test_a_point_check_refuses_is_set_aside_and_the_layout_redone(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    plan = load_plan(PLANS / "plate_holes_321.json")
    real = suggest_mod.check_plan
    refused: list[np.ndarray] = []

    def check_once(new_plan: Any, *args: Any, **kw: Any) -> PlanCheck:
        checked = real(new_plan, *args, **kw)
        if refused:
            return checked
        first = checked.points[0]
        refused.append(np.asarray(new_plan.points[0].position_m))
        why = Reason("search", "lands off its face in 5% of calibrations")
        bad = dataclasses.replace(first, status="infeasible", landing_cause=why)
        return dataclasses.replace(checked, points=(bad, *checked.points[1:]))

    monkeypatch.setattr(suggest_mod, "check_plan", check_once)
    res = suggest_plan(plan, PLANS, procedure="three_two_one")
    assert len(refused) == 1
    assert res.problems == () and "1 candidates check refused were set aside" in res.message
    positions = np.array([p.position_m for p in res.plan.points])
    assert np.min(np.linalg.norm(positions - refused[0], axis=1)) > 1e-6  # not proposed again
    assert real(res.plan, PLANS).feasible


@pytest.mark.slow
def test_a_refusal_says_at_which_bound_a_layout_exists() -> None:
    """The plate's 12.7 mm side faces under a 25 mm / 4 deg bound: no 3-2-1 fits them for
    the nominal TP program; the message says the adaptive program or the bound that would."""
    plan = load_plan(PLANS / "plate_holes_321.json")
    bound = Misplacement(max_translation_m=0.025, max_angle_rad=float(np.radians(4.0)))
    plan = msgspec.structs.replace(
        plan, validation=msgspec.structs.replace(plan.validation, misplacement=bound)
    )
    with pytest.raises(SuggestError) as err:
        suggest_plan(plan, PLANS, procedure="three_two_one", fmt="fanuc")
    msg = str(err.value)
    assert "no layout fixes all 6 degrees of freedom" in msg
    assert "the TP program" in msg
    assert (
        "the footprints fit a layout at a misplacement bound of" in msg
        or "no layout exists even at" in msg
    ), msg
