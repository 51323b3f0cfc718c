"""Roles and procedures in the UI: next free role, refusals naming the points, switching the
procedure, and the points the procedure cannot use flagged at once (issue 14, item 8 and 7)."""

from __future__ import annotations

import dataclasses

import pytest

from calib.errors import PlanError
from calib.procedures import PROCEDURES
from webui.demo import demo_ui_plan
from webui.plan_adapter import plan_from_ui, with_procedure
from webui.plan_doc import NO_ROLE, UiPlan, next_free_role, place_point, role_refusal
from webui.role_check import role_flags


def _box_321() -> UiPlan:
    kind = PROCEDURES["three_two_one"]
    return UiPlan(
        roles=kind.roles,
        role_limits=tuple(kind.role_limits[r] for r in kind.roles),
        method="three_two_one",
    )


def test_new_points_take_the_next_free_role_never_a_duplicate() -> None:
    plan = _box_321()
    for k in range(8):
        plan = place_point(plan, f"P{k}", [0.01 * k, 0, 0], [0, 0, 1])
    assert [p.role for p in plan.points] == [
        "primary", "primary", "primary", "secondary", "secondary", "tertiary", NO_ROLE, NO_ROLE
    ]  # fmt: skip
    ah, _ = demo_ui_plan()
    new = place_point(ah, "I", [0, 0, 0], [0, 0, 1])
    assert new.get("I").role == NO_ROLE, "all of A-H taken: no role, not a second A"
    freed = dataclasses.replace(ah, points=tuple(p for p in ah.points if p.id != "C"))
    assert next_free_role(freed) == "C"
    assert place_point(freed, "Z", [0, 0, 0], [0, 0, 1]).get("Z").role == "C"


def test_refusals_name_the_points() -> None:
    ah, _ = demo_ui_plan()
    twice = place_point(ah, "I", [0, 0, 0], [0, 0, 1], role="A")
    assert role_refusal(twice) == "role A is taken by points A, I (hultman2013 takes 1)"
    with pytest.raises(PlanError, match="role A is taken by points A, I"):
        plan_from_ui(twice)
    unset = place_point(place_point(ah, "I", [0, 0, 0], [0, 0, 1]), "J", [0, 0, 0], [0, 0, 1])
    with pytest.raises(PlanError, match="points I, J have no role"):
        plan_from_ui(unset)
    assert role_flags(twice).by_point == {
        "A": "role A is taken by points A, I",
        "I": "role A is taken by points A, I",
    }


def test_a_point_moved_onto_a_face_its_role_cannot_use_is_flagged() -> None:
    ah, _ = demo_ui_plan()
    assert role_flags(ah).by_point == {}
    b = ah.get("B").probe
    on_top = place_point(ah, "B", [b.position_m[0] - 0.05, b.position_m[1], 0.2], [0, 0, 1])
    flags = role_flags(on_top)
    assert list(flags.by_point) == ["B"]
    assert "point B must have normal" in flags.by_point["B"] and "got (0, 0, 1)" in flags.layout


@pytest.mark.parametrize("method", list(PROCEDURES))
def test_switching_the_procedure_gives_roles_it_has(method: str) -> None:
    ah, _ = demo_ui_plan()
    other = with_procedure(ah, method)
    assert other.method == method and other.roles == PROCEDURES[method].roles
    assert other.ids == ah.ids, "the points stay, in their order"
    for p in other.points:
        assert p.role in (*other.roles, NO_ROLE)
    assert not any("taken by" in m for m in role_flags(other).by_point.values())
    assert with_procedure(other, "hultman2013").method == "hultman2013"
    with pytest.raises(PlanError, match=r"^unknown procedure \(procedure\.method\) 'nonsense'"):
        with_procedure(ah, "nonsense")


def test_three_two_one_from_the_stator_points_picks_roles_by_face() -> None:
    ah, _ = demo_ui_plan()
    three = with_procedure(ah, "three_two_one")
    roles = {p.id: p.role for p in three.points}
    assert roles["C"] == "tertiary", "C is the only point on the short side"
    assert sorted(r for r in roles.values() if r) == sorted(
        ["primary"] * 3 + ["secondary"] * 2 + ["tertiary"]
    )
    assert not role_refusal(dataclasses.replace(
        three, points=tuple(p for p in three.points if p.role != NO_ROLE)
    ))  # fmt: skip
