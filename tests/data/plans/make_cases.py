"""Regenerate ``valid_three_two_one.json`` and the malformed-plan cases made from it.

Run ``python tests/data/plans/make_cases.py``; ``tests/calib/plan/test_plan.py`` holds the expected
message of each case. The files are checked in so the CLI can be tried on them by hand.
"""

from __future__ import annotations

import copy
import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent


def _set(path: list[str | int], value: Any) -> Callable[[Any], None]:
    def edit(d: Any) -> None:
        for key in path[:-1]:
            d = d[key]
        d[path[-1]] = value

    return edit


def _delete(key: str) -> Callable[[Any], None]:
    def edit(d: Any) -> None:
        del d[key]

    return edit


def _duplicate_id(d: Any) -> None:
    d["points"][4]["id"] = "P1"


def _sha256_mismatch(d: Any) -> None:
    d["work_object"].update(mesh="box.obj", units="mm", sha256="0" * 64)


def _missing_mesh(d: Any) -> None:
    d["work_object"].update(mesh="no_such_mesh.stl", units="mm")


CASES: dict[str, Callable[[Any], None]] = {
    "unknown_field": _set(["points", 2, "colour"], "red"),
    "wrong_type": _set(["validation", "trials"], "many"),
    "nan": _set(["points", 1, "position_m", 2], float("nan")),
    "missing_schema": _delete("schema"),
    "wrong_schema_version": _set(["schema"], "wobjcal.plan/2"),
    "unknown_units": _set(["work_object", "units"], "furlong"),
    "normal_wrong_length": _set(["points", 3, "normal"], [0.0, 1.0]),
    "normal_not_unit": _set(["points", 3, "normal"], [0.0, 2.0, 0.0]),
    "duplicate_point_id": _duplicate_id,
    "malformed_sha256": lambda d: d["work_object"].update(mesh="box.obj", sha256="abc123"),
    "sha256_mismatch": _sha256_mismatch,
    "missing_mesh": _missing_mesh,
    "not_json": lambda d: d.clear(),
    "unknown_method": _set(["procedure", "method"], "guesswork"),
    "edge_without_direction": _set(["points", 5, "search", "edge_direction"], None),
}


def write_valid() -> None:
    """A small valid 3-2-1 plan on the stator section's three faces (WOCS of ARCHITECTURE.md)."""
    from calib.plan.file import Plan, PlanPoint, Pose, Search, WorkObjectSpec, save_plan
    from calib.procedures import ThreeTwoOne

    s = 1 / math.sqrt(2)
    x, y, z = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)
    edge = Search(kind="edge", start_offset_m=0.01, overtravel_m=0.01, edge_direction=z)
    points = [
        PlanPoint(id="P1", role="primary", position_m=(0.0, -0.9, -0.15), normal=x),
        PlanPoint(id="P2", role="primary", position_m=(0.0, -0.2, -0.15), normal=x),
        PlanPoint(id="P3", role="primary", position_m=(0.0, -0.5, -0.05), normal=x),
        PlanPoint(id="S1", role="secondary", position_m=(-0.05, 0.0, -0.05), normal=y),
        PlanPoint(id="S2", role="secondary", position_m=(-0.05, 0.0, -0.15), normal=y),
        PlanPoint(
            id="T1",
            role="tertiary",
            position_m=(0.0, -0.6, 0.0),
            normal=x,
            search=edge,
            edge_normal=z,
        ),
    ]
    plan = Plan(
        name="three_two_one_small",
        description="3-2-1 test plan on the stator section's faces",
        work_object=WorkObjectSpec(
            T_world_wobj=Pose(position_m=(1.4, 0.5, 0.8), quat_wxyz=(s, 0.0, 0.0, s))
        ),
        points=points,
        procedure=ThreeTwoOne(),
    )
    save_plan(plan, HERE / "valid_three_two_one.json")


def main() -> None:
    """Write the valid plan and ``bad_<case>.json`` for every case."""
    write_valid()
    valid = json.loads((HERE / "valid_three_two_one.json").read_text())
    for name, edit in CASES.items():
        data = copy.deepcopy(valid)
        edit(data)
        text = json.dumps(data, sort_keys=True, indent=2) + "\n"
        if name == "not_json":
            text = '{"schema": "wobjcal.plan/1", "points": [1, 2,]}\n'

        (HERE / f"bad_{name}.json").write_text(text)


if __name__ == "__main__":
    main()
