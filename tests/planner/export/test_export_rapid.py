"""Tests of planner.export.rapid: the poses parsed back from the module match the plan."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from calib.frames import make_transform, matrix_from_quat_wxyz, matrix_from_rotvec, random_transform
from calib.plan.file import load_plan
from planner.export.job import ToolData, build_job, default_sensor_rotation
from planner.export.rapid import export_rapid
from tests.export_helpers import expected_ends_wobj

VALID = Path(__file__).resolve().parents[2] / "data" / "plans" / "valid_three_two_one.json"
NUM = r"-?\d+(?:\.\d+)?(?:E[+-]?\d+)?"


def _nums(text: str) -> list[float]:
    return [float(x) for x in re.findall(NUM, text)]


def _pose(trans: str, rot: str) -> np.ndarray:
    return make_transform(matrix_from_quat_wxyz(_nums(rot)), np.array(_nums(trans)) / 1000.0)


def parse_rapid(text: str) -> dict[str, object]:
    """Read tooldata, wobjdata, robtargets (pose, confdata) and SearchL lines from a module."""
    tool = re.search(r"PERS tooldata tSensor:=\[TRUE,\[\[([^\]]*)\],\[([^\]]*)\]\]", text)
    wobj = re.search(
        r'PERS wobjdata wobjNominal:=\[FALSE,TRUE,"",\[\[([^\]]*)\],\[([^\]]*)\]\]', text
    )
    assert tool and wobj
    targets = {}
    for m in re.finditer(
        r"CONST robtarget p(\w+)_(start|end|safe|face):=\[\[([^\]]*)\],\[([^\]]*)\],\[([^\]]*)\],",
        text,
    ):
        conf = tuple(int(c) for c in m.group(5).split(","))
        targets[(m.group(1), m.group(2))] = (_pose(m.group(3), m.group(4)), conf)
    searches = re.findall(r"SearchL\\SStop,diSensor(\\NegFlank)?,pMeas,p\w+,vSearch_p(\w+),", text)
    return {
        "tool": _pose(tool.group(1), tool.group(2)),
        "wobj": _pose(wobj.group(1), wobj.group(2)),
        "targets": targets,
        "searches": {pid: bool(flank) for flank, pid in searches},
    }


@pytest.fixture
def job_inputs(rng: np.random.Generator):  # type: ignore[no-untyped-def]
    plan = load_plan(VALID)
    T_base_wobj = random_transform(rng, 2.0, np.pi)
    tool = ToolData(T_flange_tcp=random_transform(rng, 0.3, np.pi), mass_kg=7.5)
    rotations = {
        p.id: default_sensor_rotation(p.normal, p.search.edge_direction)
        @ matrix_from_rotvec([0.0, 0.0, rng.uniform(-np.pi, np.pi)])
        for p in plan.points
    }
    confs = {
        p.id: (int(rng.integers(-2, 2)), 0, int(rng.integers(-1, 2)), i % 8)
        for i, p in enumerate(plan.points)
    }
    return plan, T_base_wobj, tool, rotations, confs


def test_poses_parse_back_within_tolerance(job_inputs) -> None:  # type: ignore[no-untyped-def]
    plan, T_base_wobj, tool, rotations, confs = job_inputs
    job = build_job(plan, T_base_wobj, tool, rotations, confs)
    parsed = parse_rapid(export_rapid(job))
    ends = expected_ends_wobj(plan)
    assert np.abs(parsed["wobj"][:3, 3] - T_base_wobj[:3, 3]).max() < 1e-5  # 0.01 mm
    assert np.abs(parsed["tool"][:3, 3] - tool.T_flange_tcp[:3, 3]).max() < 1e-5
    for T_got, T_want in ((parsed["wobj"], T_base_wobj), (parsed["tool"], tool.T_flange_tcp)):
        assert _angle_deg(T_got[:3, :3], T_want[:3, :3]) < 1e-3
    for p in plan.points:
        for which, k in (("start", 0), ("end", 1)):
            T, conf = parsed["targets"][(p.id, which)]
            assert np.abs(T[:3, 3] - ends[p.id][k]).max() < 1e-5, (p.id, which)
            assert _angle_deg(T[:3, :3], rotations[p.id]) < 1e-3
            # the sensor axis looks into the face
            assert np.degrees(np.arccos(np.clip(T[:3, 2] @ -np.array(p.normal), -1, 1))) < 1e-3
            assert conf == confs[p.id]
    assert parsed["searches"] == {p.id: p.search.kind == "edge" for p in plan.points}


def _angle_deg(R1: np.ndarray, R2: np.ndarray) -> float:
    c = (np.trace(R1.T @ R2) - 1.0) / 2.0
    return float(np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))


def test_module_structure(job_inputs) -> None:  # type: ignore[no-untyped-def]
    plan, T_base_wobj, tool, rotations, confs = job_inputs
    text = export_rapid(build_job(plan, T_base_wobj, tool, rotations, confs))
    n = len(plan.points)
    assert text.startswith("MODULE WobjcalThreeTwoOneSmall\n")
    assert text.rstrip().endswith("ENDMODULE")
    assert text.count("ERR_WHLSEARCH") == n and text.count("ERR_SIGSUPSEARCH") == n
    assert f"PERS pos measured{{{n}}}" in text
    assert "ConfL\\On;" in text
    # every PROC is closed, every IF has its ENDIF
    assert text.count("PROC ") == text.count("ENDPROC")
    assert len(re.findall(r"\bIF .* THEN$", text, re.M)) == text.count("ENDIF")
    assert all(len(s) <= 80 for s in re.findall(r'"((?:[^"]|"")*)"', text))
    assert "[7.5,[0,0,100]" in text


def test_unknown_confdata_turns_configuration_checks_off() -> None:
    plan = load_plan(VALID)
    text = export_rapid(build_job(plan, np.eye(4), ToolData(T_flange_tcp=np.eye(4))))
    assert "ConfJ\\Off;" in text and "ConfL\\Off;" in text
    assert "confdata unknown: run wobjcal check" in text


def test_numbers_keep_the_zeros_of_their_integer_part() -> None:
    """``fmt`` trims the trailing zeros of decimals only: a tenth point's index stays 10 (it
    once became 1 in the adaptive best fit's ``nOrder``, and the last update refitted point 1
    twice instead of point 10: found by replaying a validate trial through the module)."""
    from planner.export.text import fmt

    assert [fmt(10, 0), fmt(100.0, 4), fmt(1.2300, 4), fmt(-0.0, 3), fmt(-1e-9, 3)] == [
        "10",
        "100",
        "1.23",
        "0",
        "0",
    ]
