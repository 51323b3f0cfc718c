"""Tests of planner.export.krl: frames and E6POS parsed back from the .dat match the plan."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

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

VALID = Path(__file__).resolve().parent / "data" / "plans" / "valid_three_two_one.json"


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
    assert len(re.findall(r"^DEF ", src, re.M)) == len(re.findall(r"^END$", src, re.M)) == 5
    assert len(re.findall(r"^\s*IF .* THEN$", src, re.M)) == src.count("ENDIF")
    edge = [p.id for p in plan.points if p.search.kind == "edge"]
    assert len(re.findall(r"^ +SEARCH_FALL\(x", src, re.M)) == len(edge)
    # every point starts with an approach search (edge points: to the face they run along)
    assert len(re.findall(r"^ +SEARCH_RISE\(x", src, re.M)) == len(plan.points)
    assert "INTERRUPT DECL 20 WHEN diSensor==TRUE" in src
    assert "INTERRUPT DECL 21 WHEN diSensor==FALSE" in src
    assert "xHit=$POS_INT" in src and "RESUME" in src
    assert "SIGNAL diSensor $IN[1]" in dat
