"""The shipped plate plans are what their generator writes, and they pass the plan check."""

from __future__ import annotations

from pathlib import Path

from calib.plan.file import load_plan, plan_to_json
from tests.data.plans.make_plate_plans import PLANS, plate_plans


def test_shipped_plate_plans_equal_the_generator(reference_dir: Path) -> None:
    for name, plan in plate_plans().items():
        assert (PLANS / name).read_text() == plan_to_json(plan), (
            "regenerate with: python tests/data/plans/make_plate_plans.py"
        )
        assert load_plan(PLANS / name) == plan  # files found, digests match


def test_every_plate_point_is_reachable_on_its_face(reference_dir: Path) -> None:
    from planner.check import check_plan

    for name in plate_plans():
        res = check_plan(load_plan(PLANS / name), PLANS)
        assert res.feasible, [(p.point_id, p.reason) for p in res.points if p.status != "feasible"]
