"""The points' status table (issue 22, item 6): one row per point with an icon, a short first
cause without the part's repeated size note, details on demand; the role flag never hides an
infeasible point. The causes are the check's reasons with their kinds (issue 23, item 3): the
note and the pair are read from them, never found in the words."""

from __future__ import annotations

import math

from calib.probing import ProbePoint
from planner.check.job import PointCheck
from planner.reasons import Reason
from webui.plan_doc import UiPlan, UiPoint
from webui.scene import STATUS_RGB
from webui.status_table import (
    SHORT_CHARS,
    causes,
    details_markdown,
    first_cause,
    part_note,
    short_cause,
    shorten,
    status_cell,
    table_rows,
)

NOTE = "work object plate: 0.203 x 0.305 x 0.0127 m (file units 'm', given)"
REACH = Reason("reach", "out of reach (2.87 m from the shoulder)", about_part=True, note=NOTE)
PATH = Reason(
    "collision",
    "search from the safe start at 46.0 mm: sensor_body is too near table (clearance 4.7 mm)",
    ("sensor_body", "table"),
)
PATH_WORDS = f"search path: {PATH.text}"


def _check(
    pid: str, status: str, pose: Reason | None = None, path: Reason | None = None
) -> PointCheck:
    return PointCheck(
        point_id=pid, role="primary", kind="approach", status=status,  # type: ignore[arg-type]
        pose_status=status, pose_cause=pose,  # type: ignore[arg-type]
        path_feasible=path is None, path_cause=path, path_fail_at_m=math.nan, face_cause=None,
        clearance_m=0.0123, clearance_pair=("link_6", "table"), clearance_is_lower_bound=False,
        confdata=None, ik_kind="opw", q=None, q_path=None, T_base_flange=None,
    )  # fmt: skip


def _doc() -> UiPlan:
    pts = tuple(
        UiPoint(ProbePoint(pid, (0.01 * k, 0.0, 0.0), (0.0, 0.0, 1.0)), role=role)
        for k, (pid, role) in enumerate((("P1", "primary"), ("P2", "primary"), ("S1", "")))
    )
    return UiPlan(points=pts, roles=("primary", "secondary", "tertiary"))


def test_the_part_note_is_said_once_not_in_every_reason() -> None:
    check = _check("P1", "infeasible", REACH, PATH)
    assert check.reason == f"out of reach (2.87 m from the shoulder) ({NOTE}); {PATH_WORDS}"
    assert [c.text for c in causes(check)] == [
        "out of reach (2.87 m from the shoulder)",
        PATH_WORDS,
    ]
    assert [c.kind for c in causes(check)] == ["reach", "collision"]
    assert part_note(check) == NOTE
    assert part_note(_check("P2", "infeasible", path=PATH)) == "" and causes(None) == []


def test_the_first_cause_is_short_and_cut_at_a_word() -> None:
    short = shorten(PATH_WORDS)
    assert len(short) <= SHORT_CHARS + 2 and short.endswith(" …")
    assert PATH_WORDS.startswith(short[:-2])
    assert shorten("joint 3 at limit (joint_3)") == "joint 3 at limit (joint_3)"
    # a long collision is named by its kind and pair, which cutting the words would lose
    (path,) = causes(_check("P1", "infeasible", path=PATH))
    assert short_cause(path) == "collision: sensor_body – table"
    move = Reason("move", "move B -> via 1 at 50 %: " + PATH.text, PATH.pair)
    assert short_cause(move) == "move: sensor_body – table"
    assert short_cause(REACH) == "out of reach (2.87 m from the shoulder)", "short: as it is"


def test_rows_have_an_icon_a_short_cause_and_infeasible_wins_over_the_role_flag() -> None:
    doc = _doc()
    checks = {
        "P1": _check("P1", "infeasible", REACH, PATH),
        "P2": _check("P2", "feasible"),
    }
    flags = {"P1": "role P1 is odd", "P2": "three_two_one: P2 must have normal (0, 0, 1)"}
    rows = table_rows(doc, checks, flags, "(none)")
    assert len(rows) == 2 + 3, "one row per point"
    p1, p2, s1 = rows[2:]
    assert "✗</span> infeasible" in p1 and "**role**" in p1
    assert "| P1 | primary | out of reach (2.87 m from the shoulder) |" in p1
    assert "file units" not in "\n".join(rows)
    assert "✓</span> feasible" in p2 and "must have normal" in p2, "the flag says why"
    assert "| S1 | (none) |" in s1 and "checking..." in s1
    r, g, b = STATUS_RGB["infeasible"]
    assert f"rgb({r},{g},{b})'>✗" in status_cell(checks["P1"], flags["P1"])
    assert first_cause(checks["P2"], "") == ""


def test_details_give_every_cause_the_note_once_and_the_point() -> None:
    doc = _doc()
    check = _check("P1", "infeasible", REACH, PATH)
    md = details_markdown(doc.get("P1"), check, "")
    lines = md.splitlines()
    assert lines[0].startswith("**P1**: ") and "infeasible" in lines[0]
    assert "- out of reach (2.87 m from the shoulder)" in lines
    assert any("sensor\\_body is too near table" in line for line in lines)
    assert md.count("file units") == 1 and f"- part: {NOTE}".replace("_", "\\_") in lines
    assert "- clearance 12.3 mm (link\\_6 – table)" in lines
    assert "- at (0.0, 0.0, 0.0) mm, normal (0.000, 0.000, 1.000), wobj frame" in lines
    assert "- approach search: start 30.0 mm, overtravel 20.0 mm" in lines


def test_an_infeasible_rows_first_cause_is_what_fails_not_a_marginal_pose() -> None:
    """helper-56 (D6): C's row read "joint 5 near its upper limit" (a marginal pose) while its
    search path is what fails."""
    from dataclasses import replace

    near = Reason("joint_limit", "joint 5 near its upper limit (joint_5, 3.9 deg to go)")
    check = replace(_check("P1", "infeasible", near, PATH), pose_status="marginal")
    assert first_cause(check, "") == short_cause(PATH.worded("search path: "))
    # a pose that fails by itself stays first
    assert first_cause(_check("P1", "infeasible", REACH, PATH), "") == short_cause(REACH)
