"""Via points: the plan field, the check of the moves through them, and every export format.

The demo (stator) plan, a point B given two vias: the checked pose of A and of B lifted by
J2 -0.2 rad (retracted above the part: the moves A -> via 1 -> via 2 -> B are clear). Each
exporter's joint targets are parsed back from the program text and compared with the plan's
joint values in the controller's units (degrees; URScript rad) and the URDF's joint order
(the exporters apply no joint offsets).
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Iterator
from pathlib import Path

import msgspec
import numpy as np
import pytest

from calib.errors import InputError
from calib.plan import Plan, PlanError, ViaPoint, load_plan, plan_from_json, plan_to_json
from planner.check.job import check_plan
from planner.export import FORMATS
from planner.export_plan.job import export_program
from planner.plan_cell import open_cell
from planner.reasons import Reason

PLANS = Path(__file__).resolve().parents[3] / "assets" / "plans"
DEMO = PLANS / "stator_section_ah.json"
LIFT = np.array([0.0, -0.2, 0.0, 0.0, 0.0, 0.0])


def with_vias(plan: Plan, index: int, vias: list[list[float]]) -> Plan:
    points = list(plan.points)
    points[index] = points[index].with_vias([ViaPoint(q_rad=q) for q in vias])
    return msgspec.structs.replace(plan, points=points)


@pytest.fixture(scope="module")
def demo() -> Plan:
    """The demo without its shipped vias: the tests give it their own."""
    plan = load_plan(DEMO)
    points = [msgspec.structs.replace(p, vias=msgspec.UNSET) for p in plan.points]
    return msgspec.structs.replace(plan, points=points)


@pytest.fixture(scope="module")
def demo_cell(demo: Plan) -> Iterator[object]:
    with open_cell(demo, PLANS) as cell:
        yield cell


@pytest.fixture(scope="module")
def poses(demo: Plan, demo_cell: object) -> dict[str, np.ndarray]:
    check = check_plan(demo, cell=demo_cell)  # type: ignore[arg-type]
    return {c.point_id: np.asarray(c.q) for c in check.points if c.q is not None}


@pytest.fixture(scope="module")
def via_plan(demo: Plan, poses: dict[str, np.ndarray]) -> Plan:
    vias = [(poses["A"] + LIFT).tolist(), (poses["B"] + LIFT).tolist()]
    return with_vias(demo, 1, vias)


# ---- the plan field ------------------------------------------------------------------------
@pytest.mark.slow
def test_old_plans_save_unchanged_and_vias_round_trip(demo: Plan, via_plan: Plan) -> None:
    for path in sorted(PLANS.glob("*.json")):
        text = path.read_text()
        assert plan_to_json(plan_from_json(text)) == text, path.name
    assert '"vias"' not in plan_to_json(demo)
    text = plan_to_json(via_plan)
    back = plan_from_json(text)
    assert back == via_plan
    assert [v.q_rad for v in back.points[1].via_points] == [
        v.q_rad for v in via_plan.points[1].via_points
    ]
    assert back.points[0].via_points == ()
    assert plan_to_json(msgspec.structs.replace(back, points=[*back.points])) == text


@pytest.mark.parametrize(
    ("q", "message"),
    [
        ([0.1, float("nan"), 0, 0, 0, 0], "points[1].vias[0].q_rad[1]: must be a finite number"),
        ([], "points[1].vias[0].q_rad: needs at least 1 items"),
        ([0.0] * 13, "points[1].vias[0].q_rad: holds at most 12 items"),
        (["a", 0, 0, 0, 0, 0], "points[1].vias[0].q_rad[0]: must be a number, got str"),
    ],
)
def test_bad_vias_are_named(demo: Plan, q: list[object], message: str) -> None:
    raw = json.loads(plan_to_json(demo))
    raw["points"][1]["vias"] = [{"q_rad": q}]
    with pytest.raises(PlanError) as err:
        plan_from_json(json.dumps(raw))  # json writes NaN, as some tools do
    assert message in str(err.value)


def test_vias_of_one_plan_have_one_joint_count(demo: Plan) -> None:
    with pytest.raises(PlanError, match=r"points\[2\]\.vias\[0\]\.q_rad: 5 joint values"):
        with_vias(with_vias(demo, 1, [[0.0] * 6]), 2, [[0.0] * 5])
    with pytest.raises(PlanError, match=r"q_rad\[2\]: must be a finite number"):
        ViaPoint(q_rad=[0.0, 0.0, math.inf])


# ---- check ---------------------------------------------------------------------------------
@pytest.mark.slow
def test_clear_vias_keep_the_point_feasible(via_plan: Plan, demo_cell: object) -> None:
    check = check_plan(via_plan, cell=demo_cell)  # type: ignore[arg-type]
    b = check.points[1]
    assert b.n_vias == 2
    assert b.via_reason == ""
    assert b.status != "infeasible"
    assert check.to_json()["points"][1]["vias"] == {"count": 2, "reason": ""}
    assert "vias" not in check.to_json()["points"][0]


@pytest.mark.slow
def test_via_outside_the_joint_limits_is_named(
    demo: Plan, demo_cell: object, poses: dict[str, np.ndarray]
) -> None:
    q = poses["C"].copy()
    q[2] = math.radians(80.0)  # the IRB 4400's J3 stops at 65 deg
    plan = with_vias(demo, 2, [(poses["B"] + LIFT).tolist(), q.tolist()])
    c = check_plan(plan, cell=demo_cell).points[2]  # type: ignore[arg-type]
    assert c.status == "infeasible"
    assert c.via_reason.startswith("via 2: J3 (joint_3) 80.00 deg outside [-60.00, 65.00]")
    assert "vias: via 2" in c.reason


@pytest.mark.slow
def test_colliding_via_move_names_the_via_and_the_pair(
    demo: Plan, demo_cell: object, poses: dict[str, np.ndarray]
) -> None:
    # the straight joint move from A's pose to halfway to B drags the sensor through the part
    mid = (poses["A"] + poses["B"]) / 2.0
    plan = with_vias(demo, 1, [mid.tolist()])
    c = check_plan(plan, cell=demo_cell).points[1]  # type: ignore[arg-type]
    assert c.status == "infeasible"
    m = re.match(r"move A -> via 1 at \d+ %: (\S+) hits (\S+)", c.via_reason)
    assert m, c.via_reason
    assert m.group(2) == "stator_section"


@pytest.mark.slow
def test_wrong_joint_count_is_named(demo: Plan, demo_cell: object) -> None:
    plan = with_vias(demo, 1, [[0.0] * 7])
    c = check_plan(plan, cell=demo_cell).points[1]  # type: ignore[arg-type]
    assert c.status == "infeasible"
    assert c.via_reason.startswith("via 1: 7 joint values, the robot has 6 joints")


# ---- export --------------------------------------------------------------------------------
NUM = r"-?\d+(?:\.\d+)?(?:[eE]-?\d+)?"


def _vias_in(fmt: str, files: dict[str, str]) -> list[list[float]]:
    """The via joint values a program moves to, in program order, in its own units."""
    if fmt == "rapid":
        text = files[".mod"]
        decl = {
            m.group(1): [float(v) for v in m.group(2).split(",")]
            for m in re.finditer(r"CONST jointtarget (\w+):=\[\[([^\]]+)\]", text)
        }
        return [decl[n] for n in re.findall(r"MoveAbsJ (\w+),vApproach,fine,tSensor;", text)]
    if fmt == "krl":
        decl = {
            m.group(1): [float(v) for v in re.findall(rf"A\d ({NUM})", m.group(2))]
            for m in re.finditer(r"DECL AXIS (\w+)=\{([^}]+)\}", files[".dat"])
        }
        return [decl[n] for n in re.findall(r"^  PTP (\w+) ; via", files[".src"], re.M)]
    if fmt == "urscript":
        rows = re.findall(r"movej\(\[([^\]]+)\]", files[".script"])
        return [[float(v) for v in r.split(",")] for r in rows]
    if fmt == "fanuc":
        text = files[".ls"]
        pos = {
            m.group(1): [float(v) for v in re.findall(rf"J\d= ({NUM}) deg", m.group(2))]
            for m in re.finditer(r"P\[(\d+):\"[^\"]*\"\]\{([^}]*J1=[^}]*)\}", text)
        }
        return [pos[n] for n in re.findall(r"^\s*\d+:J P\[(\d+)\] \d+% FINE", text, re.M)
                if n in pos]  # fmt: skip
    raise AssertionError(f"no parser for {fmt}")


@pytest.mark.slow
def test_every_format_moves_through_the_vias_first(via_plan: Plan, demo_cell: object) -> None:
    assert set(FORMATS) == {"rapid", "krl", "urscript", "fanuc"}  # a new format needs a parser
    want = np.array([v.q_rad for v in via_plan.points[1].via_points])
    for fmt in FORMATS:
        out = export_program(via_plan, PLANS, fmt, cell=demo_cell)  # type: ignore[arg-type]
        got = np.array(_vias_in(fmt, out.files))
        scale = 1.0 if fmt == "urscript" else 180.0 / math.pi
        tol = 1e-6 if fmt == "urscript" else 1e-4
        assert got.shape == want.shape, fmt
        np.testing.assert_allclose(got, want * scale, atol=tol, err_msg=fmt)
    rapid = export_program(via_plan, PLANS, "rapid", cell=demo_cell).files[".mod"]  # type: ignore[arg-type]
    proc = rapid[rapid.index("PROC Probe_pB") :]
    assert proc.index("MoveAbsJ pB_via1") < proc.index("MoveAbsJ pB_via2") < proc.index("MoveJ")
    urs = export_program(via_plan, PLANS, "urscript", cell=demo_cell).files[".script"]  # type: ignore[arg-type]
    assert urs.index('probe("A"') < urs.index("movej([") < urs.index('probe("B"')


def test_a_seven_joint_via_is_refused_by_the_writers(demo: Plan) -> None:
    plan = with_vias(demo, 1, [[0.0] * 7])
    for fmt in ("rapid", "krl", "urscript"):
        with pytest.raises(InputError, match=r"point B, via 1: 7 joint values"):
            export_program(plan, PLANS, fmt, run_check=False)


# ---- the orders the programs probe in ------------------------------------------------------
def test_probe_orders_follow_the_adaptive_rapid_program(demo: Plan) -> None:
    from planner.program.build import probe_orders

    ids = [p.id for p in demo.points]
    role = {p.role: i for i, p in enumerate(demo.points)}
    orders = probe_orders(demo)
    assert orders[0] == list(range(len(ids)))
    adaptive = [role[r] for r in "ABCDEFGH"] + [role["C"], role["D"]]  # C and D retaken
    assert adaptive in orders
    # the RAPID main really calls the probes in that order
    main = export_program(demo, PLANS, "rapid", run_check=False).files[".mod"]
    main = main[main.index("PROC main") :]
    called = re.findall(r"^\s*Probe_p(\w+) \d+", main, re.M)
    assert called == [ids[i] for i in adaptive]


@pytest.mark.slow
def test_vias_are_checked_from_every_point_a_program_comes_from(
    demo: Plan, demo_cell: object, poses: dict[str, np.ndarray], monkeypatch: pytest.MonkeyPatch
) -> None:
    """C is probed after B (plan order) and after H (the RAPID program's retake): both legs
    into its vias are checked, and a problem on the retake's leg only is reported with H."""
    import planner.cell.moves as moves  # where check_plan imports check_via_path

    seen: list[str] = []

    def only_from_h(*args: object, point_name: str = "point") -> moves.ViaPath:
        name = str(args[-1])
        if point_name != "C":  # the moves into the other points: clear here
            return moves.ViaPath(())
        seen.append(name)
        hit = Reason("move", "move H -> via 1 at 50 %: link_4 hits table", ("link_4", "table"))
        return moves.ViaPath((), hit if name == "H" else None)

    monkeypatch.setattr(moves, "check_via_path", only_from_h)
    plan = with_vias(demo, 2, [(poses["C"] + LIFT).tolist()])
    c = check_plan(plan, cell=demo_cell).points[2]  # type: ignore[arg-type]
    assert seen == ["B", "H"], seen
    assert c.status == "infeasible"
    assert c.via_reason == "move H -> via 1 at 50 %: link_4 hits table"
    assert "vias: move H -> via 1" in c.reason


def test_vias_on_a_robot_with_a_prismatic_joint_are_refused() -> None:
    """The programs write via joint targets in degrees: a sliding joint would be written as
    metres x 57.3, so the check refuses the vias and names the joint."""
    from types import SimpleNamespace

    from planner.cell.moves.joint_moves import check_via_path

    chain = SimpleNamespace(joint_names=("j1", "rail"), joint_types=("revolute", "prismatic"))
    path = check_via_path(SimpleNamespace(chain=chain), None, [[0.0, 0.1]], None, "tcp")  # type: ignore[arg-type]
    assert path.problem == "vias need a robot of rotary joints; rail is prismatic"
    assert check_via_path(SimpleNamespace(chain=chain), None, [], None, "tcp").problem == ""  # type: ignore[arg-type]


def test_a_layout_the_adaptive_program_refuses_leaves_the_plan_order(demo: Plan) -> None:
    """H moved 5 m: the adaptive RAPID program refuses the layout, so no program probes in its
    order; the vias are checked in plan order and nothing raises."""
    from planner.program.build import probe_orders

    raw = json.loads(plan_to_json(demo))
    for p in raw["points"]:
        if p["id"] == "H":
            p["position_m"] = [p["position_m"][0] + 5.0, *p["position_m"][1:]]
    moved = plan_from_json(json.dumps(raw))
    assert probe_orders(moved) == [list(range(len(moved.points)))]
