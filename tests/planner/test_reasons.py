"""A reason with its kind (issue 23, item 3): its words as users saw them before, and a point's
reasons in the order and words of its ``reason``."""

from __future__ import annotations

import math

import pytest

from planner.check.results import ADD_VIAS, PointCheck
from planner.reasons import KINDS, Reason, joined

NOTE = "work object plate: 0.203 x 0.305 x 0.0127 m (file units 'm', given)"


def test_a_reason_says_its_words_and_its_note() -> None:
    hit = Reason("collision", "link_4 hits table (clearance -3.0 mm)", ("link_4", "table"))
    assert str(hit) == "link_4 hits table (clearance -3.0 mm)"
    far = Reason("reach", "out of reach (2.87 m from the shoulder)", about_part=True)
    assert str(far.noted(NOTE)) == f"out of reach (2.87 m from the shoulder) ({NOTE})"
    at = hit.worded("at 23.0 mm: ")
    assert (at.kind, at.pair, at.text) == ("collision", hit.pair, f"at 23.0 mm: {hit.text}")
    assert far.noted(NOTE).worded("search path: ").to_json() == {
        "kind": "reach",
        "text": f"search path: out of reach (2.87 m from the shoulder) ({NOTE})",
    }
    assert hit.to_json()["pair"] == ["link_4", "table"]
    assert joined([far, None, hit]) == f"{far}; {hit}" and joined([]) == ""
    assert KINDS == (
        "reach", "joint_limit", "singularity", "collision", "footprint", "move", "search"
    )  # fmt: skip


def test_a_reason_needs_a_known_kind_words_and_a_pair_of_two() -> None:
    with pytest.raises(ValueError, match="unknown reason kind 'limit'; known: reach"):
        Reason("limit", "joint 3 at limit")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="needs its words"):
        Reason("reach", "")
    with pytest.raises(ValueError, match="pair must be"):
        Reason("collision", "x hits y", ("x",))  # type: ignore[arg-type]


def _check(n_vias: int = 0, **causes: Reason | None) -> PointCheck:
    return PointCheck(
        point_id="P1", role="primary", kind="approach", status="infeasible",
        pose_status="infeasible", pose_cause=causes.get("pose"),
        path_feasible=causes.get("path") is None, path_cause=causes.get("path"),
        path_fail_at_m=math.nan, face_cause=causes.get("face"),
        clearance_m=math.nan, clearance_pair=None, clearance_is_lower_bound=False,
        confdata=None, ik_kind="opw", q=None, q_path=None, T_base_flange=None,
        n_vias=n_vias, via_cause=causes.get("via"),
        search_cause=causes.get("search"), landing_cause=causes.get("landing"),
    )  # fmt: skip


def test_a_points_reasons_keep_the_words_and_order_of_its_reason() -> None:
    """What the check joined by hand before: the pose, ``search path:``, the face, ``search:``,
    the moves (``vias:``, or the advice to add some), ``landing:``."""
    pose = Reason("reach", "out of reach (2.9 m from the shoulder)", about_part=True, note=NOTE)
    path = Reason("collision", "at 4.0 mm: tool hits clamp (clearance -1.0 mm)", ("tool", "clamp"))
    face = Reason("footprint", "point is 3.00 mm from the surface", about_part=True)
    search = Reason("search", "the search ends 0.5 mm past the nominal face; and more")
    move = Reason("move", "move A -> P1 at 50 %: link_4 hits table", ("link_4", "table"))
    landing = Reason("search", "TP: the search lands off its face in 9% of calibrations")
    c = _check(pose=pose, path=path, face=face, search=search, via=move, landing=landing)
    assert c.reason == (
        f"{pose}; search path: {path}; {face}; search: {search}; {move}{ADD_VIAS}; "
        f"landing: {landing}"
    )
    assert [r.kind for r in c.causes] == [
        "reach", "collision", "footprint", "search", "move", "search"
    ]  # fmt: skip
    assert c.pose_reason == str(pose) and c.path_reason == str(path) and c.via_reason == str(move)
    assert c.search_reason == f"{search}; {landing}" and c.face_reason == str(face)
    out = c.to_json()
    assert "; ".join(r["text"] for r in out["reasons"]) == out["reason"] == c.reason
    assert out["reasons"][1]["pair"] == ["tool", "clamp"]
    with_vias = _check(via=move, n_vias=1)
    assert with_vias.reason == f"vias: {move}" and with_vias.to_json()["vias"]["count"] == 1
    assert _check().reason == "" and _check().causes == () and _check().to_json()["reasons"] == []
