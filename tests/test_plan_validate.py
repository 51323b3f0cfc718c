"""Tests of ``planner.validate``: the one validation entry point of the CLI and the UI."""

from __future__ import annotations

import json
from pathlib import Path

import msgspec
import numpy as np
import pytest

from calib.plan.file import PlanError, load_plan
from planner.cli.main import main
from planner.cli.validate import report_json
from planner.sim.montecarlo import DEFAULT_EDGE_INSET_M
from planner.validate import validate_plan, validation_models

REPO = Path(__file__).resolve().parent.parent
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"
THREE_TWO_ONE = REPO / "tests" / "data" / "plans" / "valid_three_two_one.json"
TRIALS = 3


def test_models_follow_the_plan() -> None:
    plan = load_plan(STATOR)
    models = validation_models(plan)
    s = plan.validation.sensor
    assert models.sensor.sensing_distance_m == s.sensing_distance_m
    assert models.sensor.n_rays == s.n_rays
    assert models.robot_error.accuracy_terms == plan.validation.robot_error.accuracy_terms
    assert models.misplacement.max_translation_m == plan.validation.misplacement.max_translation_m
    assert models.settings.beta1_rad == plan.procedure.beta1_rad  # type: ignore[union-attr]
    # the plan leaves the edge-event offset unset: the sensor model's straight-edge value
    expected = models.sensor.edge_event_offset_m(DEFAULT_EDGE_INSET_M)
    assert expected > 0 and models.settings.edge_event_offset_m == expected


def test_plan_edge_offset_overrides_the_sensor_model() -> None:
    plan = load_plan(STATOR)
    proc = msgspec.structs.replace(plan.procedure, edge_event_offset_m=0.0042)
    models = validation_models(msgspec.structs.replace(plan, procedure=proc))
    assert models.settings.edge_event_offset_m == 0.0042


def test_same_seed_same_report_other_seed_differs() -> None:
    plan = load_plan(STATOR)
    a = validate_plan(plan, trials=TRIALS, seed=11, workers=1)
    b = validate_plan(plan, trials=TRIALS, seed=11, workers=1)
    c = validate_plan(plan, trials=TRIALS, seed=12, workers=1)
    assert a.n_trials == TRIALS and a.n_ok == TRIALS
    np.testing.assert_array_equal(a.delta_procedure, b.delta_procedure)
    assert report_json(a)["rows"] == report_json(b)["rows"]
    assert not np.array_equal(a.delta_procedure, c.delta_procedure)


def test_progress_reaches_the_trial_count() -> None:
    calls: list[tuple[int, int]] = []
    validate_plan(
        load_plan(STATOR), trials=2, seed=3, workers=1, progress=lambda d, t: calls.append((d, t))
    )
    assert calls and calls[-1] == (2, 2)


def test_cli_and_function_agree(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "report.json"
    argv = ["validate", str(STATOR), "--trials", str(TRIALS), "--seed", "5", "--workers", "1"]
    assert main([*argv, "--json", str(out)]) == 0, capsys.readouterr().err
    from_cli = json.loads(out.read_text())
    report = validate_plan(load_plan(STATOR), trials=TRIALS, seed=5, workers=1)
    assert from_cli["rows"] == report_json(report)["rows"]
    assert from_cli["failures"] == report.failures and from_cli["seed"] == 5


def test_three_two_one_plan_names_the_procedure() -> None:
    with pytest.raises(PlanError, match=r"^procedure\.method: .*hultman2013.*'three_two_one'"):
        validate_plan(load_plan(THREE_TWO_ONE), trials=2, seed=0)


def test_mesh_work_object_names_the_mesh() -> None:
    plan = load_plan(STATOR)
    wo = msgspec.structs.replace(plan.work_object, mesh="part.stl")
    with pytest.raises(PlanError, match=r"^work_object\.mesh: .*builtin:stator_section.*part\.stl"):
        validate_plan(msgspec.structs.replace(plan, work_object=wo), trials=2, seed=0)


def test_reach_checked_trials_draw_the_same_numbers() -> None:
    """Vetting the first trials in the cell changes what is checked, not what is drawn."""
    plan = load_plan(STATOR)
    plain = validate_plan(plan, trials=60, seed=5)
    vetted = validate_plan(plan, trials=60, seed=5, reach_trials=3, plan_dir=STATOR.parent)
    assert plain.reach_checked == 0 and vetted.reach_checked == 3
    assert "checked in the cell on 3 of 60 trials" in vetted.to_markdown()
    np.testing.assert_array_equal(plain.delta_procedure, vetted.delta_procedure)
