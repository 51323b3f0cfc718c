"""Tests of calib.plan.file: strict loading, canonical byte-identical saving, the checked-in
schema."""

from __future__ import annotations

import json
import math
from pathlib import Path

import msgspec
import numpy as np
import pytest

from calib.frames import random_transform
from calib.plan.file import (
    PLAN_SCHEMA,
    Plan,
    PlanError,
    PlanPoint,
    Pose,
    Search,
    file_sha256,
    load_plan,
    plan_digest,
    plan_from_json,
    plan_to_json,
    resolve_ref,
    save_plan,
)
from calib.plan.json_io import json_schema
from calib.probing import ProbePoint, SearchSpec
from calib.procedures import BestFit, Hultman2013, ThreeTwoOne

DATA = Path(__file__).resolve().parents[2] / "data" / "plans"
VALID = DATA / "valid_three_two_one.json"
SCHEMA_FILE = Path(__file__).resolve().parents[3] / "assets" / "schema"

#: every malformed case in tests/data/plans and the message it must give
MALFORMED = {
    "unknown_field": "points[2].colour: unknown field",
    "wrong_type": "validation.trials: must be an integer, got str",
    "nan": "points[1].position_m[2]: must be a finite number, got NaN",
    "missing_schema": "schema: required field missing (supported: 'wobjcal.plan/1')",
    "wrong_schema_version": "schema: unsupported version 'wobjcal.plan/2' "
    "(supported: 'wobjcal.plan/1')",
    "unknown_units": "work_object.units: invalid value 'furlong' (valid: 'm', 'mm', 'cm', 'in', "
    "'auto')",
    "normal_wrong_length": "points[3].normal: must have length 3, got 2",
    "normal_not_unit": "points[3].normal: must be a unit vector, got length 2",
    "duplicate_point_id": "points[4].id: duplicate id 'P1' (also points[0])",
    "malformed_sha256": "work_object.sha256: must be 64 lowercase hex digits, got 'abc123'",
    "sha256_mismatch": "work_object.sha256: ",
    "missing_mesh": "work_object.mesh: file not found: ",
    "unknown_method": "procedure.method: invalid value 'guesswork' (valid: 'hultman2013', "
    "'three_two_one', 'best_fit', 'iterative')",
    "edge_without_direction": "points[5].search.edge_direction: required for an edge search",
    "not_json": "not valid JSON (line 1, column 46)",
}


def test_every_case_file_is_in_the_table() -> None:
    files = {p.stem.removeprefix("bad_") for p in DATA.glob("bad_*.json")}
    assert files == set(MALFORMED)


@pytest.mark.parametrize("case", sorted(MALFORMED))
def test_malformed_plan_gives_its_message(case: str) -> None:
    path = DATA / f"bad_{case}.json"
    with pytest.raises(PlanError) as info:
        load_plan(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ")
    assert MALFORMED[case] in message
    assert isinstance(info.value, ValueError)


def test_sha256_mismatch_names_file_and_digests() -> None:
    with pytest.raises(PlanError, match=r"box\.obj has digest [0-9a-f]{64}, the plan says 0{64}"):
        load_plan(DATA / "bad_sha256_mismatch.json")


def test_sha256_match_loads(tmp_path: Path) -> None:
    raw = json.loads(VALID.read_text())
    (tmp_path / "box.obj").write_bytes((DATA / "box.obj").read_bytes())
    raw["work_object"].update(mesh="box.obj", units="mm", sha256=file_sha256(DATA / "box.obj"))
    (tmp_path / "plan.json").write_text(json.dumps(raw))
    plan = load_plan(tmp_path / "plan.json")
    assert resolve_ref(plan.work_object.mesh, tmp_path) == tmp_path / "box.obj"
    assert resolve_ref("builtin:stator_section", tmp_path) == "builtin:stator_section"


def test_round_trip_is_byte_identical(tmp_path: Path) -> None:
    text = VALID.read_text()
    plan = load_plan(VALID)
    assert plan_to_json(plan) == text
    out = save_plan(plan, tmp_path / "copy.json")
    assert out.read_bytes() == VALID.read_bytes()
    assert load_plan(out) == plan


def test_round_trip_of_random_poses_is_exact(tmp_path: Path, rng: np.random.Generator) -> None:
    base = load_plan(VALID)
    for i in range(20):
        T = random_transform(rng, 3.0, math.pi)
        pose = Pose.from_matrix(T)
        np.testing.assert_allclose(pose.matrix(), T, atol=1e-12)
        wo = type(base.work_object)(mesh=base.work_object.mesh, T_world_wobj=pose)
        plan = Plan(
            name=f"random {i}", work_object=wo, points=base.points, procedure=base.procedure
        )
        path = save_plan(plan, tmp_path / "p.json")
        again = load_plan(path)
        assert again == plan
        assert plan_to_json(again) == path.read_text()


def test_int_coordinates_are_accepted_and_saved_as_floats() -> None:
    raw = json.loads(VALID.read_text())
    raw["points"][0]["position_m"] = [0, -1, 0]
    plan = plan_from_json(json.dumps(raw))
    assert plan.points[0].position_m == (0.0, -1.0, 0.0)
    assert '"position_m": [\n        0.0,\n        -1.0,' in plan_to_json(plan)


def test_string_numbers_are_rejected() -> None:
    raw = json.loads(VALID.read_text())
    raw["points"][0]["position_m"][1] = "0.5"
    with pytest.raises(PlanError, match=r"points\[0\]\.position_m\[1\]: must be a number, got str"):
        plan_from_json(json.dumps(raw))


def test_duplicate_json_key_is_rejected() -> None:
    text = VALID.read_text().replace('"name": "three_two_one_small"', '"name": "a", "name": "b"')
    with pytest.raises(PlanError, match="duplicate key 'name'"):
        plan_from_json(text)


def test_top_level_must_be_object() -> None:
    with pytest.raises(PlanError, match="top level must be a JSON object"):
        plan_from_json("[1, 2]")


def test_edge_direction_must_lie_in_face() -> None:
    with pytest.raises(PlanError, match="must be perpendicular to normal"):
        PlanPoint(
            id="F",
            role="F",
            position_m=(0.0, 0.0, 0.0),
            normal=(1.0, 0.0, 0.0),
            search=Search(kind="edge", edge_direction=(1.0, 0.0, 0.0)),
        )


def test_roles_must_fit_procedure() -> None:
    plan = load_plan(VALID)
    with pytest.raises(PlanError, match=r"points\[0\]\.role: must be one of \['A'"):
        Plan(points=plan.points, procedure=Hultman2013())
    fit = [msgspec.structs.replace(p, role="fit") for p in plan.points[:2]]
    with pytest.raises(PlanError, match="best_fit needs at least 3 points, got 2"):
        Plan(points=fit, procedure=BestFit()).require_complete()
    incomplete = Plan(points=plan.points[:4], procedure=ThreeTwoOne())
    with pytest.raises(PlanError, match="three_two_one needs 2 'secondary' points, got 1"):
        incomplete.require_complete()
    plan.require_complete()
    assert plan.method == "three_two_one"


def test_probe_point_conversion_round_trip() -> None:
    plan = load_plan(VALID)
    for p in plan.points:
        probe = p.to_probe_point()
        assert isinstance(probe, ProbePoint)
        assert probe.search.kind == p.search.kind
        back = PlanPoint.from_probe_point(probe, p.role, speed_m_s=p.search.speed_m_s)
        assert back == p
    edge = plan.point("T1").to_probe_point()
    assert edge.search == SearchSpec("edge", 0.01, 0.01, (0.0, 0.0, 1.0))
    with pytest.raises(PlanError, match=r"no point 'Z' in the plan \(ids: \['P1'"):
        plan.point("Z")


def test_defaults_make_a_valid_plan() -> None:
    plan = Plan(procedure=ThreeTwoOne())
    assert plan.schema == PLAN_SCHEMA
    assert plan_from_json(plan_to_json(plan)) == plan


@pytest.mark.parametrize(
    ("type_name", "file_name"),
    [
        ("plan", "wobjcal.plan-1.schema.json"),
        ("measurements", "wobjcal.measurements-1.schema.json"),
    ],
)
def test_checked_in_schema_matches_types(type_name: str, file_name: str) -> None:
    from calib.plan.measurements import Measurements

    type_ = Plan if type_name == "plan" else Measurements
    assert (SCHEMA_FILE / file_name).read_text() == json_schema(type_), (
        f"regenerate with: wobjcal schema{' --measurements' if type_name != 'plan' else ''} "
        f"> assets/schema/{file_name}"
    )


@pytest.mark.parametrize(
    ("literal", "shown"), [("Infinity", "Infinity"), ("-Infinity", "-Infinity"), ("1e999", "inf")]
)
def test_infinite_numbers_are_rejected_with_path(literal: str, shown: str) -> None:
    raw = json.loads(VALID.read_text())
    raw["points"][2]["normal"][0] = "@"
    text = json.dumps(raw).replace('"@"', literal)
    with pytest.raises(
        PlanError, match=rf"points\[2\]\.normal\[0\]: must be a finite number, got {shown}"
    ):
        plan_from_json(text)


def test_a_plan_from_before_the_touch_probe_loads_its_proximity_sensor() -> None:
    """A plan file without ``validation.sensor.kind`` (written before the sensor union) loads
    as the proximity sensor it was, and saves with ``kind`` added."""
    from calib.models import ProximitySensor

    raw = json.loads((SCHEMA_FILE.parent / "plans" / "stator_section_ah.json").read_text())
    del raw["validation"]["sensor"]["kind"]
    raw["validation"]["sensor"]["n_rays"] = 64
    plan = plan_from_json(json.dumps(raw))
    assert plan.validation.sensor == ProximitySensor(n_rays=64)
    assert json.loads(plan_to_json(plan))["validation"]["sensor"]["kind"] == "proximity"


def test_plan_files_are_written_without_negative_zeros() -> None:
    """A zero the arithmetic signed (``-0.0``) is written ``0.0``: the same plan gives the same
    file whichever code path made it (the digest already ignored the sign)."""
    plan = load_plan(SCHEMA_FILE.parent / "plans" / "plate_holes_321.json", check_files=False)
    p = plan.points[0]
    signed = msgspec.structs.replace(p, position_m=(-0.0, p.position_m[1], p.position_m[2]))
    again = msgspec.structs.replace(plan, points=[signed, *plan.points[1:]])
    text = plan_to_json(again)
    assert "-0.0," not in text and "-0.0\n" not in text
    assert plan_digest(again) == plan_digest(plan_from_json(text))
