"""The shipped plate plans are what their generator writes, and they pass the plan check."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from calib.plan.file import load_plan, plan_to_json
from tests.data.plans.make_plate_plans import PLANS, plate_plans


def _same(a: Any, b: Any, where: str = "$") -> list[str]:
    """Where two JSON documents differ, numbers compared to 1e-12 relative and ``-0.0`` equal
    to ``0.0`` (a fresh clone's numpy may compute either sign, or the last bit, differently)."""
    if isinstance(a, dict) and isinstance(b, dict):
        if a.keys() != b.keys():
            return [f"{where}: keys {sorted(a)} != {sorted(b)}"]
        return [d for k in a for d in _same(a[k], b[k], f"{where}.{k}")]
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{where}: {len(a)} items != {len(b)}"]
        return [
            d
            for i, (x, y) in enumerate(zip(a, b, strict=True))
            for d in _same(x, y, f"{where}[{i}]")
        ]
    numbers = (int, float)
    if isinstance(a, numbers) and isinstance(b, numbers) and not isinstance(a, bool | str):
        ok = math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-15)
        return [] if ok else [f"{where}: {a!r} != {b!r}"]
    return [] if a == b else [f"{where}: {a!r} != {b!r}"]


def test_the_comparison_sees_a_changed_number_but_not_the_sign_of_zero() -> None:
    assert _same({"q": [0.0, 1.0]}, {"q": [-0.0, 1.0]}) == []
    assert _same({"q": [0.0, 1.0]}, {"q": [0.0, 1.0001]}) == ["$.q[1]: 1.0 != 1.0001"]
    assert _same({"q": 1}, {"r": 1}) != [] and _same({"s": "a"}, {"s": "b"}) != []


@pytest.mark.slow
def test_shipped_plate_plans_equal_the_generator(reference_dir: Path) -> None:
    for name, plan in plate_plans().items():
        shipped, made = json.loads((PLANS / name).read_text()), json.loads(plan_to_json(plan))
        assert _same(shipped, made) == [], (
            "regenerate with: python tests/data/plans/make_plate_plans.py"
        )
        assert load_plan(PLANS / name) == plan  # files found, digests match


@pytest.mark.slow
def test_every_plate_point_is_reachable_on_its_face(reference_dir: Path) -> None:
    from planner.check.job import check_plan

    for name in plate_plans():
        res = check_plan(load_plan(PLANS / name), PLANS)
        assert res.feasible, [(p.point_id, p.reason) for p in res.points if p.status != "feasible"]
