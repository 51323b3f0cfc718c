"""Tests of planner.export.urscript: poses parsed back from the script match the plan."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from calib.frames import make_transform, matrix_from_rotvec, random_transform
from calib.plan.file import load_plan
from planner.export import export_files
from planner.export.job import ToolData, build_job, default_sensor_rotation
from tests.export_helpers import expected_ends_wobj

VALID = Path(__file__).resolve().parents[2] / "data" / "plans" / "valid_three_two_one.json"
POSE = r"p\[([^\]]*)\]"


def parse_pose(text: str) -> np.ndarray:
    """``x, y, z, rx, ry, rz`` (m, rotation vector) to a 4x4 transform."""
    v = [float(x) for x in text.split(",")]
    return make_transform(matrix_from_rotvec(v[3:]), v[:3])


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
    text = export_files(build_job(plan, T_base_wobj, tool, rotations), "urscript")[".script"]
    wobj = parse_pose(re.search(rf"wobj = {POSE}", text).group(1))  # type: ignore[union-attr]
    tcp = parse_pose(re.search(rf"set_tcp\({POSE}\)", text).group(1))  # type: ignore[union-attr]
    for got, want in ((wobj, T_base_wobj), (tcp, tool.T_flange_tcp)):
        assert np.abs(got[:3, 3] - want[:3, 3]).max() < 1e-5
        assert _angle_deg(got[:3, :3], want[:3, :3]) < 1e-3
    calls = re.findall(rf'meas_(\w+) = probe\("(\w+)", {POSE}, {POSE}, (True|False), ', text)
    assert [c[1] for c in calls] == [p.id for p in plan.points]
    ends = expected_ends_wobj(plan)
    for _, pid, start, end, want in calls:
        p = plan.point(pid)
        assert want == ("False" if p.search.kind == "edge" else "True")
        for k, txt in enumerate((start, end)):
            T = parse_pose(txt)
            assert np.abs(T[:3, 3] - ends[pid][k]).max() < 1e-5
            assert _angle_deg(T[:3, :3], rotations[pid]) < 1e-3


def test_script_structure() -> None:
    plan = load_plan(VALID)
    text = export_files(build_job(plan, np.eye(4), ToolData(T_flange_tcp=np.eye(4))), "urscript")
    script = text[".script"]
    assert script.startswith("def wobjcalthreetwoonesmall():\n")
    assert "get_standard_digital_in(SENSOR_IN)" in script
    assert "pose_trans(wobj, safe_wobj)" in script and "pose_inv(wobj)" in script
    # block structure: every def/thread/if/while is closed by an end
    opens = len(re.findall(r"^\s*(def |thread |if |while )", script, re.M))
    assert opens == len(re.findall(r"^\s*end$", script, re.M))
