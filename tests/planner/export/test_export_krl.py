"""Tests of planner.export.krl: frames and E6POS parsed back from the .dat match the plan."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from calib.frames import (
    make_transform,
    matrix_from_rotvec,
    matrix_from_tait_bryan_zyx,
    random_transform,
)
from calib.plan.file import load_plan
from planner.export import export_files
from planner.export.job import ToolData, build_job, default_sensor_rotation
from tests.export_helpers import expected_ends_wobj

VALID = Path(__file__).resolve().parents[2] / "data" / "plans" / "valid_three_two_one.json"
STATOR = Path(__file__).resolve().parents[3] / "assets" / "plans" / "stator_section_ah.json"


def parse_frame(text: str) -> np.ndarray:
    """``{X 1,Y 2,Z 3,A 4,B 5,C 6}`` (mm, deg, Z-Y'-X'') to a 4x4 transform in metres."""
    vals = dict(re.findall(r"([XYZABC]) (-?\d+(?:\.\d+)?)", text))
    a, b, c = (np.radians(float(vals[k])) for k in "ABC")
    p = np.array([float(vals[k]) for k in "XYZ"]) / 1000.0
    return make_transform(matrix_from_tait_bryan_zyx(a, b, c), p)


def parse_dat(text: str) -> dict[str, np.ndarray]:
    """All ``DECL FRAME``/``E6POS`` values of a .dat file by name."""
    return {
        m.group(2): parse_frame(m.group(3))
        for m in re.finditer(r"^DECL (FRAME|E6POS) (\w+)=(\{[^}]*\})$", text, re.M)
    }


def _angle_deg(R1: np.ndarray, R2: np.ndarray) -> float:
    c = (np.trace(R1.T @ R2) - 1.0) / 2.0
    return float(np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))


def test_poses_parse_back_within_tolerance(rng: np.random.Generator) -> None:
    plan = load_plan(VALID)
    T_base_wobj = random_transform(rng, 2.0, np.pi)
    tool = ToolData(T_flange_tcp=random_transform(rng, 0.3, np.pi))
    rotations = {
        p.id: default_sensor_rotation(p.normal, p.search.edge_direction)
        @ matrix_from_rotvec([0.0, 0.0, rng.uniform(-np.pi, np.pi)])
        for p in plan.points
    }
    files = export_files(build_job(plan, T_base_wobj, tool, rotations), "krl")
    assert set(files) == {".src", ".dat"}
    frames = parse_dat(files[".dat"])
    for name, want in (("xBaseNominal", T_base_wobj), ("xToolSensor", tool.T_flange_tcp)):
        assert np.abs(frames[name][:3, 3] - want[:3, 3]).max() < 1e-5
        assert _angle_deg(frames[name][:3, :3], want[:3, :3]) < 1e-3
    ends = expected_ends_wobj(plan)
    for p in plan.points:
        for k, which in enumerate(("start", "end")):
            T = frames[f"x{p.id}_{which}"]
            assert np.abs(T[:3, 3] - ends[p.id][k]).max() < 1e-5, (p.id, which)
            assert _angle_deg(T[:3, :3], rotations[p.id]) < 1e-3


def test_program_structure() -> None:
    plan = load_plan(VALID)
    files = export_files(build_job(plan, np.eye(4), ToolData(T_flange_tcp=np.eye(4))), "krl")
    src, dat = files[".src"], files[".dat"]
    assert "DEF WobjcalThreeTwoOneSmall()" in src and "DEFDAT WobjcalThreeTwoOneSmall" in dat
    assert len(re.findall(r"^DEF ", src, re.M)) == len(re.findall(r"^END$", src, re.M)) == 6
    assert len(re.findall(r"^\s*IF .* THEN$", src, re.M)) == src.count("ENDIF")
    edge = [p.id for p in plan.points if p.search.kind == "edge"]
    assert len(re.findall(r"^ +SEARCH_FALL\(x", src, re.M)) == len(edge)
    # every point starts with an approach search (edge points: to the face they run along)
    assert len(re.findall(r"^ +SEARCH_RISE\(x", src, re.M)) == len(plan.points)
    assert "INTERRUPT DECL 20 WHEN diSensor==TRUE" in src
    assert "INTERRUPT DECL 21 WHEN diSensor==FALSE" in src
    assert "xHit=$POS_INT" in src and "RESUME" in src
    assert "SIGNAL diSensor $IN[1]" in dat
    # RESUME needs the search motion one level below the routine declaring the interrupt
    search_move = re.search(r"^DEF SEARCH_MOVE\(xTo:IN\)\n(.*?)^END$", src, re.M | re.S)
    assert search_move is not None and "  LIN xTo\n  WAIT SEC 0" in search_move.group(1)
    for routine in ("SEARCH_RISE", "SEARCH_FALL"):
        body = re.search(rf"^DEF {routine}\(.*?^END$", src, re.M | re.S)
        assert body is not None and "INTERRUPT DECL" in body.group(0)
        assert "  SEARCH_MOVE(xGoal)" in body.group(0) and "LIN" not in body.group(0)


def test_krl_names_fit_24_characters_rapid_keeps_32() -> None:
    """KRL's names have at most 24 characters; the RAPID module name keeps its 32."""
    from dataclasses import replace

    from planner.export.krl import _names, program_name

    plan = load_plan(VALID)
    job = build_job(plan, np.eye(4), ToolData(T_flange_tcp=np.eye(4)))
    job = replace(job, name="WobjcalPlateHolesThreeTwoOne")
    assert program_name(job.name) == "WobjcalPlateHolesThreeTw"
    assert "DEF WobjcalPlateHolesThreeTw()" in export_files(job, "krl")[".src"]
    assert "MODULE WobjcalPlateHolesThreeTwoOne" in export_files(job, "rapid")[".mod"]
    ids = ["A", "a", "A_2", "x" * 32, "X" * 32, "x" * 31 + "y", "_"]
    targets = tuple(replace(job.targets[0], point_id=i) for i in ids)
    names = _names(targets)
    assert names == [
        "xA",
        "xa_2",
        "xA_2_2",
        "x" * 18,
        "x" + "X" * 15 + "_2",
        "x" * 16 + "_3",
        "x",
    ]


# ---- status and turn from the checked pose (issue 10) ----------------------------------------
def test_status_and_turn_bits() -> None:
    from planner.export.job import ArmPose
    from planner.export.krl import e6pos_text, status_turn

    q = (0.1, -0.2, 0.3, -0.4, 0.5, -0.6)
    assert status_turn(ArmPose(q, True, True, False)) == (2, 0b101010)
    assert status_turn(ArmPose(q, False, False, True)) == (5, 0b101010)
    assert e6pos_text(np.eye(4), ArmPose(q, True, True, True)).endswith(",S 6,T 42}")
    assert ",S " not in e6pos_text(np.eye(4), None)


@pytest.mark.slow
def test_krl_targets_carry_the_status_and_turn_of_the_checked_pose() -> None:
    """Before: E6POS without S and T. Now each target has them, from its own IK solution next
    to the checked pose: S matches the check's ABB cfx bits on this ABB-like arm, T the signs of
    the checked joint values (away from zero)."""
    import re

    from calib.plan.file import load_plan
    from planner.check.job import check_plan
    from planner.export_plan.job import export_program

    plan = load_plan(STATOR)
    dat = export_program(plan, STATOR.parent, "krl").files[".dat"]
    check = check_plan(plan, STATOR.parent)
    for c in check.points:
        assert c.confdata is not None and c.q is not None
        cfx = c.confdata[3]
        want_s = bool(cfx & 4) | ((not cfx & 2) << 1) | ((cfx & 1) << 2)
        m = re.search(rf"DECL E6POS x{c.point_id}_safe=\{{[^}}]*,S (\d+),T (\d+)\}}", dat)
        assert m is not None, c.point_id
        assert int(m.group(1)) == want_s
        t = int(m.group(2))
        for i, v in enumerate(c.q):
            if abs(v) > np.radians(5):
                assert bool(t >> i & 1) == (v < 0), (c.point_id, i)
