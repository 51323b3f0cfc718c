"""Limits and messages (issue 10, items 7 and 8): counts that would allocate without bound,
deeply nested JSON and out-of-range arguments are refused naming the field."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from calib.plan.file import PlanError, plan_from_json
from planner.cli.main import main

REPO = Path(__file__).resolve().parents[2]
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"


def _with(path: list[str], value: object) -> str:
    doc = json.loads(STATOR.read_text())
    node = doc
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return json.dumps(doc)


@pytest.mark.parametrize(
    ("path", "value", "message"),
    [
        (["validation", "trials"], 10**12, r"validation\.trials: must be at most 100,000, got 1,0"),
        (
            ["validation", "trials"],
            10**30,
            r"validation\.trials: must be at most 100,000, got 1e\+30",
        ),
        (["validation", "seed"], -1, r"validation\.seed: must be an integer >= 0, got -1"),
        (["validation", "sensor", "n_rays"], 10**9, r"sensor\.n_rays: must be at most 65,536"),
        (
            ["validation", "robot_error", "accuracy_terms"],
            10**7,
            r"accuracy_terms: must be at most",
        ),
    ],
)
def test_counts_are_bounded_and_named(path: list[str], value: object, message: str) -> None:
    """Item 8: these were 'internal error' (OverflowError, ValueError, a broken process pool)
    or, for trials = 10^12, seeds allocated up front without bound (item 7)."""
    with pytest.raises(PlanError, match=message):
        plan_from_json(_with(path, value))


def test_deeply_nested_json_is_named() -> None:
    text = '{"schema": "wobjcal.plan/1", "x": ' + "[" * 100_000 + "]" * 100_000 + "}"
    with pytest.raises(PlanError, match=r"JSON nested too deeply"):
        plan_from_json(text)


def test_cli_ranges(capsys: pytest.CaptureFixture[str]) -> None:
    for args, words in (
        (["--trials", "1000000000000"], "must be at most 100,000"),
        (["--seed", "-1"], "must be >= 0"),
        (["--workers", "100000"], "must be at most 64"),
    ):
        assert main(["validate", str(STATOR), *args]) == 2
        assert words in capsys.readouterr().err


def test_a_urdf_without_joints_is_named(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    urdf = tmp_path / "one_link.urdf"
    urdf.write_text('<robot name="r"><link name="base"/></robot>')
    plan = tmp_path / "plan.json"
    plan.write_text(_with(["cell", "robot", "urdf"], str(urdf)))
    assert main(["check", str(plan)]) == 2
    err = capsys.readouterr().err
    assert "one_link.urdf: no moving joint between base link 'base'" in err
    assert "internal error" not in err
