"""The cycle-time model of the measuring program (``planner.program.cycle_time``).

A small program is timed by hand here from the model's formulas written out again (the
trapezoid and the triangle of each joint, the slowest joint per leg, the searches' travel at
their speed, the retreats, settle and I/O), independently of the module's code; the shipped
plans' totals are held to sane bounds (the paper: about 100 s for the frame and 150 s for the
x-offset run of a stator section, with a robot that waits); the header of every exported
program, a URDF without velocity limits and bad plan values are checked too.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from calib.errors import InputError, PlanError
from calib.models.cycle import CycleSettings
from calib.paper.xoffset import xoffset_probe_points
from calib.plan.file import Plan, load_plan, plan_digest, plan_from_json, plan_to_json
from calib.probing import ProbePoint, SearchSpec
from calib.procedures import RolePoint
from calib.procedures.best_fit import BestFit
from planner.check.cycle import urdf_joint_velocities
from planner.check.job import PlanCheck, check_plan
from planner.export_plan.job import export_program
from planner.program.build import build_program
from planner.program.controllers import CONTROLLERS
from planner.program.cycle_time import (
    DEFAULT_JOINT_VELOCITY_RAD_S,
    LINEAR_SPEED_M_S,
    cycle_time,
    joint_motion_limits,
    trapezoid_time,
)
from planner.program.safety import SafetySpec
from planner.robot.kinematics.chain import KinematicChain

ROOT = Path(__file__).resolve().parents[3]
PLANS = ROOT / "assets" / "plans"
URDF = ROOT / "assets" / "robots" / "irb4400" / "irb4400.urdf"


# ---- a program timed by hand -------------------------------------------------------------
def _hand_leg(q_a: list[float], q_b: list[float], v: list[float], a: float) -> float:
    """One synchronised joint move, by hand: per joint a trapezoid (accelerate to v, cruise,
    decelerate) or, when it cannot reach v, a triangle; the slowest joint's time."""
    worst = 0.0
    for qa, qb, vj in zip(q_a, q_b, v, strict=True):
        d = abs(qb - qa)
        t_ramp = vj / a  # time to reach full speed
        d_ramps = vj * t_ramp  # distance of both ramps together: 2 * (a t^2 / 2)
        t = (d - d_ramps) / vj + 2.0 * t_ramp if d >= d_ramps else 2.0 * math.sqrt(d / a)
        worst = max(worst, t)
    return worst


def test_trapezoid_and_triangle() -> None:
    # 1 rad at 2 rad/s, 5 rad/s^2: ramps 0.4 s each over 0.8 rad, 0.2 rad cruising 0.1 s
    assert trapezoid_time(1.0, 2.0, 5.0) == pytest.approx(0.9, abs=1e-12)
    # 0.2 rad never reaches 2 rad/s: a triangle, 0.1 rad in 0.2 s up and 0.2 s down
    assert trapezoid_time(0.2, 2.0, 5.0) == pytest.approx(0.4, abs=1e-12)
    assert trapezoid_time(-1.0, 2.0, 5.0) == pytest.approx(0.9, abs=1e-12)
    assert trapezoid_time(0.0, 2.0, 5.0) == 0.0


def _box_points() -> list[RolePoint]:
    """Three approach points on a box's top (z = 0) and a side (x = 0.2), wobj, m."""
    spec = SearchSpec(start_offset_m=0.030, overtravel_m=0.020)
    side = SearchSpec(start_offset_m=0.040, overtravel_m=0.010)
    return [
        RolePoint("fit", ProbePoint("P1", (0.05, 0.05, 0.0), (0.0, 0.0, 1.0), spec)),
        RolePoint("fit", ProbePoint("P2", (0.15, 0.05, 0.0), (0.0, 0.0, 1.0), spec)),
        RolePoint("fit", ProbePoint("P3", (0.2, 0.1, -0.05), (1.0, 0.0, 0.0), side)),
    ]


def test_a_small_program_timed_by_hand() -> None:
    """Three points, one via: every move, search, retreat, settle and I/O by hand."""
    # no misplacement and no sensing distance: every search starts at its plan start (the
    # 2 mm safety margin is less than the start offsets), and stops at the nominal face
    safety = SafetySpec(0.0, 0.0, (0.0, 0.0, 0.0), 0.0)
    program = build_program(_box_points(), BestFit(), safety, CONTROLLERS["fanuc"], vias={"P2": 1})
    assert program.probe_order == ("P1", "P2", "P3")
    q = {
        "P1": [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        "P2": [0.5, 0.1, -0.1, 0.0, 0.3, 0.0],
        "P3": [0.6, 0.15, -0.1, 2.0, 0.3, -1.0],
    }
    via = [0.3, -0.9, 0.2, 0.0, 0.2, 0.0]
    v = [2.0, 2.0, 2.0, 4.0, 4.0, 6.0]
    acc = 5.0
    speeds = {"P1": 0.010, "P2": 0.020, "P3": 0.005}
    settings = CycleSettings(settle_s=0.25, io_s=0.15, joint_acceleration_rad_s2=acc)
    limits = joint_motion_limits([f"j{i}" for i in range(1, 7)], v, acc)
    got = cycle_time(program, q, {"P2": [via]}, speeds, limits, settings)

    move_p2 = _hand_leg(q["P1"], via, v, acc) + _hand_leg(via, q["P2"], v, acc)
    move_p3 = _hand_leg(q["P2"], q["P3"], v, acc)
    # P2 <- via: J2 1 rad at 2 rad/s, ramps 0.4 s each over 0.8 rad: 0.1 s cruising + 0.8 s
    assert _hand_leg(via, q["P2"], v, acc) == pytest.approx(0.9, abs=1e-12)
    # P3 <- P2: J4 2 rad at 4 rad/s: 0.8 s ramps over 3.2 rad > 2 rad: a triangle, 2 sqrt(0.4)
    assert move_p3 == pytest.approx(2.0 * math.sqrt(2.0 / 5.0), abs=1e-12)
    searches = {  # (to the face, whole length) of each search, m
        "P1": (0.030, 0.050),
        "P2": (0.030, 0.050),
        "P3": (0.040, 0.050),
    }
    want = {}
    for pid, move in (("P1", 0.0), ("P2", move_p2), ("P3", move_p3)):
        near, full = searches[pid]
        search = near / speeds[pid]
        retreat = near / LINEAR_SPEED_M_S  # back to the safe start, straight
        want[pid] = move + search + retreat + 0.25 + 0.15
        row = next(r for r in got.rows if r.key == pid)
        assert row.move_s == pytest.approx(move, abs=1e-12)
        assert row.search_s == pytest.approx(search, abs=1e-12)
        assert row.search_max_s == pytest.approx(full / speeds[pid], abs=1e-12)
        assert row.linear_max_s == pytest.approx(full / LINEAR_SPEED_M_S, abs=1e-12)
        assert row.total_s == pytest.approx(want[pid], abs=1e-12)
    assert [r.key for r in got.rows] == ["P1", "P2", "P3"]
    assert got.total_s == pytest.approx(sum(want.values()), abs=1e-12)
    assert got.total_max_s > got.total_s
    assert got.notes == () and got.untimed == ()
    # a point without a pose: its move is not timed, and said
    blind = cycle_time(program, {**q, "P3": None}, {"P2": [via]}, speeds, limits, settings)
    assert blind.untimed == ("P3",) and "P3" in blind.summary() and "P3" in blind.notes[-1]


def test_a_search_speed_that_is_missing_is_named() -> None:
    program = build_program(_box_points(), BestFit(), SafetySpec(), CONTROLLERS["fanuc"], vias={})
    limits = joint_motion_limits(["j1"], [1.0], 5.0)
    q = {p.point.id: [0.0] for p in _box_points()}
    with pytest.raises(InputError, match="point P1: search speed"):
        cycle_time(program, q, {}, {}, limits, CycleSettings())


# ---- the shipped plans -------------------------------------------------------------------
@pytest.fixture(scope="module")
def stator() -> tuple[Plan, PlanCheck]:
    plan = load_plan(PLANS / "stator_section_ah.json")
    return plan, check_plan(plan, PLANS)


@pytest.fixture(scope="module")
def plate() -> tuple[Plan, PlanCheck]:
    plan = load_plan(PLANS / "plate_holes_321.json")
    return plan, check_plan(plan, PLANS)


@pytest.mark.slow
def test_the_stator_program_takes_minutes_as_in_the_paper(
    stator: tuple[Plan, PlanCheck],
) -> None:
    """The paper: about 100 s for the frame and 150 s for the x-offset run (4 minutes per
    section, with a robot that waits and searches slower); ours runs at the URDF's speeds."""
    plan, check = stator
    c = check.cycle
    assert c is not None and c.program == "RAPID, adaptive A-H"
    keys = [r.key for r in c.rows]
    assert keys == ["A", "B", "C", "D", "E", "F", "G", "H", "C2", "D2", "x-offset run"]
    run = plan.procedure.xoffset  # type: ignore[union-attr]
    n_px = sum(len(r) for r in xoffset_probe_points(run.grid, run.layers, run.teeth))
    xo = c.rows[-1]
    assert xo.searches == n_px and xo.move_s is not None and xo.move_s > 0.0
    # edge points run two searches (the face, then the edge), the others one
    assert {r.key: r.searches for r in c.rows[:-1]} == {
        k: 2 if k in ("F", "H") else 1 for k in keys[:-1]
    }
    frame_s = sum(r.total_s for r in c.rows[:-1])
    assert 30.0 < frame_s < 200.0 and 40.0 < xo.total_s < 300.0
    assert 60.0 < c.total_s < 600.0 and c.total_s < c.total_max_s < 3.0 * c.total_s
    assert c.total_s == pytest.approx(sum(r.total_s for r in c.rows))
    assert c.notes == ()  # the IRB 4400 URDF gives every joint's velocity limit
    out = check.to_json()
    assert out["cycle_time_s"] == pytest.approx(c.total_s)
    rows = out["cycle_time"]["rows"]
    assert sum(r["total_s"] for r in rows) == pytest.approx(out["cycle_time_s"])
    assert out["cycle_time"]["searches"] == sum(r["searches"] for r in rows)


@pytest.mark.reference
@pytest.mark.slow
def test_the_plate_program_takes_seconds(plate: tuple[Plan, PlanCheck]) -> None:
    _, check = plate
    c = check.cycle
    assert c is not None and [r.key for r in c.rows] == ["P1", "P2", "P3", "S1", "S2", "T1"]
    assert all(r.move_s is not None for r in c.rows)
    assert 5.0 < c.total_s < 120.0


@pytest.mark.reference
@pytest.mark.slow
def test_every_program_header_says_its_cycle_time(plate: tuple[Plan, PlanCheck]) -> None:
    plan, check = plate
    assert check.cycle is not None
    for fmt, comment in COMMENTS.items():
        files = export_program(plan, PLANS, fmt).files
        text = _comment_text(files[next(iter(files))], comment)
        if fmt == "rapid":  # the check's program: the same number
            assert f"Estimated cycle time {check.cycle.total_s:.0f} s (up to" in text
        assert re.search(r"Estimated cycle time \d+ s \(up to \d+ s when every", text), fmt
        bare = export_program(plan, PLANS, fmt, run_check=False).files
        assert "Cycle time not estimated: built without a cell check" in _comment_text(
            bare[next(iter(bare))], comment
        ), fmt


#: A comment line of each language: its text in group 1.
COMMENTS = {
    "rapid": r"^\s*! ?(.*)$",
    "krl": r"^\s*; ?(.*)$",
    "urscript": r"^\s*# ?(.*)$",
    "fanuc": r"^\s*\d+:\s*!(.*?) ;$",
}


def _comment_text(program: str, comment: str) -> str:
    """The program's comment lines joined into one text (wrapped lines made whole)."""
    found = (re.match(comment, line) for line in program.splitlines())
    return " ".join(m.group(1).strip() for m in found if m)


@pytest.mark.reference
def test_the_linear_speed_is_what_every_program_commands() -> None:
    """The model's speed of the moves that are no search, against the exported texts."""
    plan = load_plan(PLANS / "plate_holes_321.json")
    mm_s = round(LINEAR_SPEED_M_S * 1e3)
    want = {
        "rapid": f"vApproach:=[{mm_s},",
        "krl": f"$VEL.CP={LINEAR_SPEED_M_S:g}",
        "urscript": f"v={LINEAR_SPEED_M_S:g}",
        "fanuc": f"{mm_s}mm/sec",
    }
    for fmt, needle in want.items():
        files = export_program(plan, PLANS, fmt, run_check=False).files
        assert needle in "".join(files.values()), fmt


# ---- a URDF without velocity limits ----------------------------------------------------------
def test_a_urdf_without_velocity_limits_gets_the_default_and_says_so(tmp_path: Path) -> None:
    bare = tmp_path / "irb4400_no_velocity.urdf"
    bare.write_text(re.sub(r'\s+velocity="[^"]*"', "", URDF.read_text()))
    assert "velocity=" not in bare.read_text()
    chain = KinematicChain.from_urdf(bare)
    cell: Any = SimpleNamespace(chain=chain, query_cache={})
    assert urdf_joint_velocities(cell) == (0.0,) * chain.n_joints
    limits = joint_motion_limits(chain.joint_names, urdf_joint_velocities(cell), 5.0)
    assert limits.defaulted == chain.joint_names
    np.testing.assert_array_equal(limits.velocity, DEFAULT_JOINT_VELOCITY_RAD_S)
    program = build_program(_box_points(), BestFit(), SafetySpec(), CONTROLLERS["fanuc"], vias={})
    q = {p.point.id: np.zeros(chain.n_joints) for p in _box_points()}
    q["P2"] = np.full(chain.n_joints, 2.0)  # 2 rad at 1 rad/s: 2 s + 1/5 s of ramps
    speeds = {p.point.id: 0.01 for p in _box_points()}
    c = cycle_time(program, q, {}, speeds, limits, CycleSettings())
    assert c.rows[1].move_s == pytest.approx(2.0 / 1.0 + 1.0 / 5.0)
    assert "no velocity limit" in c.notes[0] and chain.joint_names[0] in c.notes[0]
    assert "where it gives none" in c.model_text() and "some assumed" in c.summary()
    # with the URDF's limits (150 deg/s and more) the same move is faster
    full = SimpleNamespace(chain=KinematicChain.from_urdf(URDF), query_cache={})
    velocities = urdf_joint_velocities(full)  # type: ignore[arg-type]
    assert all(v > DEFAULT_JOINT_VELOCITY_RAD_S for v in velocities)


# ---- the plan's fields ---------------------------------------------------------------------
def _with_cycle(cycle: object) -> str:
    raw = json.loads(plan_to_json(load_plan(PLANS / "plate_holes_321.json", check_files=False)))
    raw["validation"]["cycle"] = cycle
    return json.dumps(raw)


def test_the_cycle_fields_round_trip_and_keep_old_digests() -> None:
    plan = load_plan(PLANS / "plate_holes_321.json", check_files=False)
    assert "cycle" not in json.loads(plan_to_json(plan))["validation"]  # left out unset
    assert plan.validation.cycle_settings == CycleSettings()
    given = plan_from_json(_with_cycle({"settle_s": 0.5, "io_s": 0.0}))
    assert given.validation.cycle_settings == CycleSettings(settle_s=0.5, io_s=0.0)
    assert plan_from_json(plan_to_json(given)) == given
    assert plan_digest(given) != plan_digest(plan)


@pytest.mark.parametrize(
    ("cycle", "message"),
    [
        (
            {"settle_s": -0.1},
            "validation.cycle.settle_s: must be 0 <= settle_s <= 60 (s), got -0.1",
        ),
        ({"io_s": 3600.0}, "validation.cycle.io_s: must be 0 <= io_s <= 60 (s), got 3600.0"),
        (
            {"joint_acceleration_rad_s2": 0.0},
            "validation.cycle.joint_acceleration_rad_s2: must be 0 < joint_acceleration_rad_s2 "
            "<= 1000 (rad/s^2), got 0.0",
        ),
        ({"settle_s": "0.2"}, "validation.cycle.settle_s: must be a number, got str"),
        ({"settle": 0.2}, "validation.cycle.settle: unknown field"),
    ],
)
def test_a_bad_cycle_value_gives_one_clear_error(cycle: object, message: str) -> None:
    with pytest.raises(PlanError) as err:
        plan_from_json(_with_cycle(cycle))
    assert message in str(err.value)
    assert str(err.value).count("validation.cycle") == 1


@pytest.mark.reference
def test_the_ui_status_says_the_cycle_time(plate: tuple[Plan, PlanCheck]) -> None:
    """The Points tab's status table ends with the check's estimate (the same program)."""
    from webui.server import run
    from webui.testing import free_port

    _, check = plate
    assert check.cycle is not None
    app = run(PLANS / "plate_holes_321.json", port=free_port(), block=False, autosave_path=None)
    try:
        assert app.cycle_future is not None
        app.cycle_future.result(120)  # estimated on the cell worker, after the rows are drawn
        assert app.cycle is not None and app.cycle.program == check.cycle.program
        assert app.cycle.total_s == pytest.approx(check.cycle.total_s, rel=1e-9)
        want = f"cycle time ~ {check.cycle.total_s:.0f} s"
        assert want in app.points_panel.status_md.content
    finally:
        app.stop()


# ---- each controller's joint moves as its program commands them ------------------------------
def test_each_controllers_joint_moves_are_timed_as_its_program_commands_them() -> None:
    """Was: every program's joint moves timed at the URDF's full speed, though FANUC's run at
    20 %, URScript's movej at 1.05 rad/s and 1.4 rad/s^2, and RAPID's MoveJ vApproach keeps
    the TCP under 100 mm/s: a header that described a program nobody exports."""
    from planner.program.cycle_time import joint_move_time

    v, acc = [2.0, 2.0, 2.0, 4.0, 4.0, 6.0], 5.0
    names = [f"j{i}" for i in range(1, 7)]
    a, b = np.zeros(6), np.array([1.2, 0.0, 0.0, 0.0, 0.0, 0.0])  # J1 turns 1.2 rad
    full = joint_motion_limits(names, v, acc, CONTROLLERS["krl"].joint_move)
    # KRL PTP at 100 %: J1 at 2 rad/s, ramps 0.4 s over 0.8 rad: 0.2 s cruising + 0.8 s
    assert joint_move_time(a, b, full) == pytest.approx(1.0, abs=1e-12)
    fanuc = joint_motion_limits(names, v, acc, CONTROLLERS["fanuc"].joint_move)
    # FANUC J 20 %: J1 at 0.4 rad/s, ramps 0.08 s over 0.032 rad: 1.168 rad / 0.4 + 0.16 s
    assert joint_move_time(a, b, fanuc) == pytest.approx(1.168 / 0.4 + 0.16, abs=1e-12)
    ur = joint_motion_limits(names, v, acc, CONTROLLERS["urscript"].joint_move)
    # URScript movej v=1.05, a=1.4: ramps 0.75 s over 0.7875 rad, 0.4125 rad cruising
    assert joint_move_time(a, b, ur) == pytest.approx(0.4125 / 1.05 + 1.5, abs=1e-12)
    # RAPID MoveJ vApproach: the TCP 1 m from J1's axis sweeps 1.2 m: at most 100 mm/s, 12 s
    # (the path sampled every degree: its chords are 1.2 m x (1 - 2e-5))
    tcp = lambda qs: np.array(  # noqa: E731
        [
            [[math.cos(q[0]), -math.sin(q[0]), 0, math.cos(q[0])],
             [math.sin(q[0]), math.cos(q[0]), 0, math.sin(q[0])],
             [0, 0, 1, 0], [0, 0, 0, 1]]
            for q in qs
        ]
    )  # fmt: skip
    rapid = joint_motion_limits(names, v, acc, CONTROLLERS["rapid"].joint_move, tcp)
    assert joint_move_time(a, b, rapid) == pytest.approx(12.0, rel=1e-4)
    # ... and its tool at most 50 deg/s: a wrist turn of 1.2 rad with the TCP still, 1.375 s
    wrist = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1.2])
    spin = lambda qs: np.array(  # noqa: E731
        [
            [[math.cos(q[5]), -math.sin(q[5]), 0, 0], [math.sin(q[5]), math.cos(q[5]), 0, 0],
             [0, 0, 1, 0], [0, 0, 0, 1]]
            for q in qs
        ]
    )  # fmt: skip
    rapid = joint_motion_limits(names, v, acc, CONTROLLERS["rapid"].joint_move, spin)
    assert joint_move_time(a, wrist, rapid) == pytest.approx(1.2 / math.radians(50), rel=1e-9)


@pytest.mark.reference
def test_the_programs_command_the_joint_speeds_the_model_times() -> None:
    """The exporters write their joint-move speeds from the same registry the model reads."""
    from planner.export.fanuc_text import JOINT_PCT
    from planner.export.urscript_probe import MOVEJ

    plan = load_plan(PLANS / "plate_holes_321.json")
    texts = {
        fmt: "\n".join(export_program(plan, PLANS, fmt, run_check=False).files.values())
        for fmt in ("rapid", "urscript", "fanuc")
    }
    assert "CONST speeddata vApproach:=[100,50,5000,1000];" in texts["rapid"]
    assert MOVEJ == "a=1.4, v=1.05" and f"{MOVEJ})" in texts["urscript"]
    assert JOINT_PCT == 20 and re.search(r"J P\[\d+\] 20% FINE", texts["fanuc"])
