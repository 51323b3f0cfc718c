"""``wobjcal check`` and the planar-face check: points off a face, footprints, no face at all."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from calib.plan.file import load_plan
from planner.cell.scene.workobject import load_work_object
from planner.cli.main import main
from planner.faces.checks import plan_face_reasons

REPO = Path(__file__).resolve().parents[3]
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def _copy(tmp_path: Path, edit: Any) -> Path:
    raw = json.loads(STATOR.read_text())
    edit(raw)
    path = tmp_path / "plan.json"
    path.write_text(json.dumps(raw))
    return path


def _point(raw: dict[str, Any], point_id: str) -> dict[str, Any]:
    return next(p for p in raw["points"] if p["id"] == point_id)


@pytest.mark.slow
def test_shipped_plan_points_all_lie_on_planar_faces(capsys: pytest.CaptureFixture[str]) -> None:
    plan = load_plan(STATOR)
    wo = load_work_object(plan.work_object.mesh, units=plan.work_object.units)
    reasons = plan_face_reasons(wo.mesh, [p.to_probe_point() for p in plan.points])
    assert reasons == [None] * 8
    code, out, _ = run(capsys, "check", str(STATOR), "--json")
    assert code == 0
    rows = json.loads(out)["points"]
    assert all(r["feasible"] for r in rows)
    assert not any(w in r["reason"] for r in rows for w in ("face", "footprint", "surface"))


@pytest.mark.slow
def test_footprint_over_a_slot_hole_is_infeasible(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    def edit(raw: dict[str, Any]) -> None:  # D from the tooth centre towards slot 4
        _point(raw, "D")["position_m"][1] += 0.008

    code, out, _ = run(capsys, "check", str(_copy(tmp_path, edit)), "--json")
    assert code == 1
    rows = {r["id"]: r for r in json.loads(out)["points"]}
    assert rows["D"]["status"] == "infeasible"
    assert rows["D"]["reason"].startswith("footprint over a hole/edge")
    assert all(rows[k]["feasible"] for k in "ABCEFGH")


@pytest.mark.slow
def test_normal_disagreeing_with_the_face_is_infeasible(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    def edit(raw: dict[str, Any]) -> None:
        a = math.radians(8.0)
        _point(raw, "A")["normal"] = [math.cos(a), math.sin(a), 0.0]

    code, out, _ = run(capsys, "check", str(_copy(tmp_path, edit)))
    assert code == 1
    assert "point A: infeasible" in out and "8.0 deg from the face normal" in out


@pytest.mark.slow
def test_plan_on_a_raw_scan_fails_with_no_planar_face(
    tmp_path: Path, reference_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scan = reference_dir / "parts" / "noether_raw_mesh.ply"

    def edit(raw: dict[str, Any]) -> None:
        raw["work_object"].update(mesh=str(scan), units="m", sha256=None)

    code, out, err = run(capsys, "check", str(_copy(tmp_path, edit)))
    assert code == 1
    assert "noether_raw_mesh: no planar face: largest flat region" in err
    assert "mm^2" in err and "RMS" in err
    assert "Traceback" not in err
    assert "0 of 8 points feasible" in out  # the table still shows every point, each refused
    code, out, _ = run(capsys, "check", str(_copy(tmp_path, edit)), "--json")
    data = json.loads(out)
    assert code == 1 and not data["feasible"] and "no planar face" in data["error"]
    assert all("no planar face" in p["face_reason"] for p in data["points"])
