"""Tests of the ``wobjcal`` command line: help, exit codes, errors without tracebacks, outputs."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from calib.frames import motion_between, random_transform, transform_points
from calib.plan.file import load_plan, plan_to_json
from calib.plan.measurements import Measurements, save_measurements
from planner.cli.main import main
from planner.plan_cell import nominal_T_base_wobj

REPO = Path(__file__).resolve().parents[3]
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"
DATA = REPO / "tests" / "data" / "plans"
COMMANDS = ["check", "validate", "calibrate", "export", "sweep", "schema", "ui", "demo"]


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("command", COMMANDS)
def test_help_of_every_command(command: str, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, command, "--help")
    assert code == 0
    assert f"usage: wobjcal {command}" in out
    assert "example:\n  wobjcal " + command in out


def test_top_level_help_lists_commands(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys)
    assert code == 0
    assert all(c in out for c in COMMANDS)
    assert "exit codes" in out


def test_bad_arguments_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "export", str(STATOR), "--format", "cobol", "-o", "x")
    assert code == 2 and "invalid choice: 'cobol'" in err


@pytest.mark.parametrize("case", sorted(p.stem for p in DATA.glob("bad_*.json")))
@pytest.mark.parametrize("command", ["check", "export", "calibrate", "validate"])
def test_malformed_plan_exits_2_with_one_line(
    case: str, command: str, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    from tests.calib.plan.test_plan import MALFORMED

    plan = str(DATA / f"{case}.json")
    extra = {
        "check": [],
        "export": ["--format", "rapid", "-o", str(tmp_path / "x.mod")],
        "calibrate": [str(tmp_path / "m.json")],
        "validate": ["--trials", "2"],
    }[command]
    code, out, err = run(capsys, command, plan, *extra)
    assert code == 2
    assert "Traceback" not in err + out
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"wobjcal {command}: error: {plan}: ")
    assert MALFORMED[case.removeprefix("bad_")] in lines[0]


def test_missing_file_exits_2(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, _, err = run(capsys, "check", str(tmp_path / "nope.json"))
    assert code == 2
    assert (
        err.strip() == f"wobjcal check: error: {tmp_path / 'nope.json'}: No such file or directory"
    )


def test_schema_matches_checked_in_files(capsys: pytest.CaptureFixture[str]) -> None:
    _, out, _ = run(capsys, "schema")
    assert out == (REPO / "assets" / "schema" / "wobjcal.plan-1.schema.json").read_text()
    _, out, _ = run(capsys, "schema", "--measurements")
    assert out == (REPO / "assets" / "schema" / "wobjcal.measurements-1.schema.json").read_text()


@pytest.mark.slow
def test_shipped_plan_equals_regenerated(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, _ = run(capsys, "demo", "--write-plan", str(tmp_path / "ah.json"))
    assert code == 0
    assert (tmp_path / "ah.json").read_bytes() == STATOR.read_bytes(), (
        "regenerate with: wobjcal demo --write-plan assets/plans/stator_section_ah.json"
    )
    plan = load_plan(STATOR)
    assert [p.role for p in plan.points] == list("ABCDEFGH")
    assert plan.method == "hultman2013"


@pytest.mark.parametrize("fmt", ["rapid", "krl", "urscript", "json"])
def test_export_writes_files(fmt: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = (
        tmp_path / f"prog.{ {'rapid': 'mod', 'krl': 'src', 'urscript': 'script'}.get(fmt, 'json') }"
    )
    code, _, err = run(capsys, "export", str(STATOR), "--format", fmt, "-o", str(out), "--no-check")
    assert code == 0, err
    text = out.read_text()
    if fmt == "json":
        assert text == plan_to_json(load_plan(STATOR))
    elif fmt == "rapid":
        assert (
            text.startswith("MODULE WobjcalStatorSectionAh") and text.count("SearchL\\SStop") == 11
        )  # 10 A-H searches and the x-offset run's one (in a loop)
        assert "PROC XOffsetRun()" in text and "FUNC robtarget SlotTarget(" in text
    elif fmt == "krl":
        dat = (tmp_path / "prog.dat").read_text()
        assert len(re.findall(r"DECL E6POS x\w+_(?:start|end)=", dat)) == 16
    else:
        assert text.count(' = probe("') == 8


def _ideal_stator(tmp_path: Path) -> Path:
    """The shipped stator plan with an ideal sensor (edge-event offset measured as 0; unset,
    every face would take the sensor model's 6.3 mm), written to ``tmp_path``."""
    import msgspec

    from calib.plan.file import save_plan
    from planner.suggest import moved_plan

    plan = load_plan(STATOR)
    proc = msgspec.structs.replace(plan.procedure, edge_event_offset_m=0.0)
    out = tmp_path / "stator_ideal.json"
    ideal = msgspec.structs.replace(plan, procedure=proc)
    save_plan(moved_plan(ideal, STATOR.parent, tmp_path), out)
    return out


def _synthetic(tmp_path: Path, rng: np.random.Generator) -> tuple[Path, np.ndarray]:
    plan = load_plan(STATOR)
    T_true = nominal_T_base_wobj(plan) @ random_transform(rng, 0.010, np.radians(2.0))
    pts = {p.id: transform_points(T_true, p.position_m) for p in plan.points}
    path = save_measurements(Measurements.from_points_m(pts, units="mm"), tmp_path / "m.json")
    return path, T_true


@pytest.mark.parametrize("method", ["hultman2013", "three_two_one", "best_fit"])
def test_calibrate_recovers_known_motion(
    method: str, tmp_path: Path, rng: np.random.Generator, capsys: pytest.CaptureFixture[str]
) -> None:
    meas, T_true = _synthetic(tmp_path, rng)
    ideal = str(_ideal_stator(tmp_path))
    code, out, err = run(capsys, "calibrate", ideal, str(meas), "--method", method, "--json")
    assert code == 0, err
    res = json.loads(out)
    T = np.array(res["T_base_wobj"])
    assert np.abs(motion_between(T_true, T)).max() < 1e-6
    np.testing.assert_allclose(res["origin_m"], T_true[:3, 3], atol=1e-6)
    assert len(res["quat_wxyz"]) == 4 and len(res["tait_bryan_zyx_deg"]) == 3
    assert set(res["residuals_m"]) == set("ABCDEFGH")


def test_calibrate_text_has_paste_lines(
    tmp_path: Path, rng: np.random.Generator, capsys: pytest.CaptureFixture[str]
) -> None:
    meas, T_true = _synthetic(tmp_path, rng)
    code, out, _ = run(capsys, "calibrate", str(_ideal_stator(tmp_path)), str(meas))
    assert code == 0
    assert 'PERS wobjdata wobjCalibrated:=[FALSE,TRUE,"",[[' in out
    assert "BASE_DATA[10]={X " in out
    assert "wobj_calibrated = p[" in out and "UFRAME[9]=PR[1] ;" in out  # every format's
    assert f"x {T_true[0, 3] * 1e3:.3f}" in out
    code, out, _ = run(
        capsys, "calibrate", str(_ideal_stator(tmp_path)), str(meas), "--format", "krl"
    )
    assert code == 0 and "BASE_DATA[10]={X " in out
    assert "PERS wobjdata" not in out and "UFRAME" not in out and "p[" not in out


def test_calibrate_gross_error_exits_1_without_paste_lines(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Item 1: D 10 mm off printed a 17 deg frame ready to paste, exit 0. Now exit 1, D named on
    stderr, no wobjdata/BASE_DATA lines and no frame in --json unless --force."""
    plan = load_plan(STATOR)
    T = nominal_T_base_wobj(plan)
    pts = {
        p.id: transform_points(T, np.add(p.position_m, (0.01, 0, 0) if p.id == "D" else 0))
        for p in plan.points
    }
    meas = save_measurements(Measurements.from_points_m(pts, units="mm"), tmp_path / "m.json")
    code, out, err = run(capsys, "calibrate", str(STATOR), str(meas))
    assert code == 1
    assert "re-measure D" in err and "max_angle_rad" in err
    assert "PERS wobjdata" not in out and "BASE_DATA" not in out
    code, out, err = run(capsys, "calibrate", str(STATOR), str(meas), "--json")
    res = json.loads(out)
    assert code == 1 and res["trusted"] is False and "T_base_wobj" not in res
    assert res["screen"]["remeasure"] == ["D"]
    code, out, err = run(capsys, "calibrate", str(STATOR), str(meas), "--force")
    assert code == 0 and "PERS wobjdata" in out and "NOT TRUSTED" in out


def test_calibrate_json_has_covariance_and_sigma(
    tmp_path: Path, rng: np.random.Generator, capsys: pytest.CaptureFixture[str]
) -> None:
    meas, _ = _synthetic(tmp_path, rng)
    code, out, _ = run(capsys, "calibrate", str(STATOR), str(meas), "--json")
    res = json.loads(out)
    assert code == 0 and res["trusted"] is True
    cov = np.array(res["covariance"]["matrix"])
    assert cov.shape == (6, 6) and np.allclose(cov, cov.T)
    assert np.all(np.linalg.eigvalsh(cov) > 0)
    assert res["sigma"]["x_m"] == pytest.approx(np.sqrt(cov[0, 0]))
    assert res["sigma"]["ry_deg"] == pytest.approx(np.degrees(np.sqrt(cov[4, 4])))


def test_calibrate_missing_point_exits_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "m.json").write_text(
        json.dumps(
            {
                "schema": "wobjcal.measurements/1",
                "points": {"A": [1, 2, 3]},
                "failed": {"B": "no detection within 110 mm"},
            }
        )
    )
    code, _, err = run(capsys, "calibrate", str(STATOR), str(tmp_path / "m.json"))
    assert code == 2
    assert "points.B: not measured (failed on the robot: no detection within 110 mm)" in err


def test_ui_passes_flags_to_webui(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from types import SimpleNamespace

    import webui.server

    calls = []

    def fake_run(*a, **k):  # type: ignore[no-untyped-def]
        calls.append((a, k))
        server = SimpleNamespace(get_port=lambda: k["port"])
        state = SimpleNamespace(autosave_path=None)
        return SimpleNamespace(server=server, state=state, autosave_note="")

    monkeypatch.setattr(webui.server, "run", fake_run)

    def fake_serve(app, announce):  # type: ignore[no-untyped-def]
        announce()  # the address is printed once serving
        return 0

    monkeypatch.setattr(webui.server, "serve", fake_serve)
    assert main(["ui", str(STATOR), "--host", "0.0.0.0", "--port", "8123"]) == 0
    assert "wobjcal UI on http://0.0.0.0:8123" in capsys.readouterr().err
    assert main(["demo"]) == 0
    flags = {"block": False, "fresh": False}
    assert calls[0] == ((str(STATOR),), {"host": "0.0.0.0", "port": 8123, **flags})
    assert calls[1] == ((None,), {"host": "127.0.0.1", "port": 8080, **flags})
    code, _, err = run(capsys, "ui", "no_such_plan.json")
    assert code == 2 and "no_such_plan.json: No such file or directory" in err
    code, _, err = run(capsys, "ui", str(DATA / "bad_nan.json"))
    assert code == 2 and "must be a finite number, got NaN" in err
    assert len(calls) == 2  # no server was started for bad plans


def test_unwritable_output_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "no_dir" / "x.mod"
    code, _, err = run(
        capsys, "export", str(STATOR), "--format", "rapid", "-o", str(out), "--no-check"
    )
    assert code == 2
    want = f"{out}: cannot write into {out.parent}: No such file or directory"
    assert err.strip().splitlines()[-1] == f"wobjcal export: error: {want}"


@pytest.mark.slow
def test_python_m_planner_runs() -> None:
    res = subprocess.run(
        [sys.executable, "-m", "planner", "--version"], capture_output=True, text=True, check=False
    )
    assert res.returncode == 0 and res.stdout.startswith("wobjcal ")


@pytest.mark.slow
def test_validate_small_run_writes_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    report = tmp_path / "report.json"
    args = ["validate", str(STATOR), "--trials", "3", "--seed", "7", "--json", str(report)]
    code, out, err = run(capsys, *args, "--plots", str(tmp_path / "plots"))
    assert code == 0, err
    assert "| WOCS origin x-axis | 95.5 |" in out
    pngs = sorted(p.name for p in (tmp_path / "plots").glob("*.png"))
    assert pngs and all((tmp_path / "plots" / n).stat().st_size > 1000 for n in pngs)
    data = json.loads(report.read_text())
    assert data["n_trials"] == 3 and data["n_ok"] == 3 and data["seed"] == 7
    row = next(r for r in data["rows"] if r["key"] == "origin_x")
    assert row["paper"] == pytest.approx(0.10) and row["procedure"] > 0
    # the same seed gives the same numbers
    run(capsys, *args[:-1], str(tmp_path / "again.json"))
    again = json.loads((tmp_path / "again.json").read_text())
    assert again["rows"] == data["rows"]


@pytest.mark.slow
def test_validate_refuses_a_plan_that_cannot_work_naming_its_points(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The 3-2-1 test plan's searches end 20 mm past their faces, less than the 20 mm, 3 deg
    misplacement may move them away (the program starts them at their safe starts, so their
    30 mm start no longer matters): refused before any trial, every point and problem named:
    by check first (exit 1, as ``wobjcal check``); with --force, by the simulation's own
    preflight (exit 2: it cannot be simulated)."""
    argv = ["validate", str(DATA / "valid_three_two_one.json"), "--trials", "2"]
    code, _, err = run(capsys, *argv)
    assert code == 1
    assert "check refuses this plan for the program RAPID" in err
    lines = [line for line in err.splitlines() if line.startswith("error: point ")]
    assert [line.split(":")[1].strip() for line in lines] == [
        "point P1", "point P2", "point P3", "point S1", "point S2", "point T1"
    ]  # fmt: skip
    assert all("the search ends 20.0 mm past the nominal face" in line for line in lines[:2])
    assert "nothing simulated" in err
    code, _, err = run(capsys, *argv, "--force")
    assert code == 2
    assert "points[0] (P1): the search ends 20.0 mm past the nominal face" in err
    assert "overtravel at least" in err
    assert "points[2] (P3): not on a planar face" in err


def _moved_copy(tmp_path: Path, point_id: str, offset_m: tuple[float, float, float]) -> Path:
    raw = json.loads(STATOR.read_text())
    for p in raw["points"]:
        if p["id"] == point_id:
            p["position_m"] = [a + b for a, b in zip(p["position_m"], offset_m, strict=True)]
    path = tmp_path / "moved.json"
    path.write_text(json.dumps(raw))
    return path


@pytest.mark.slow
def test_check_names_a_point_moved_5_m_away(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    moved = _moved_copy(tmp_path, "F", (0.0, -5.0, 0.0))
    code, out, err = run(capsys, "check", str(moved), "--json")
    assert code == 1, err
    res = json.loads(out)  # stdout is pure JSON (PyBullet's banner goes to stderr)
    rows = {r["id"]: r for r in res["points"]}
    assert res["feasible"] is False
    assert rows["F"]["status"] == "infeasible" and "reach" in rows["F"]["reason"]
    code, out, _ = run(capsys, "check", str(moved))
    assert code == 1
    assert re.search(r"point F: infeasible: out of reach", out)


@pytest.mark.slow
def test_check_shipped_plan_passes(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "check", str(STATOR))
    assert code == 0, out
    assert "8 of 8 points feasible" in out


@pytest.mark.slow
def test_export_takes_orientation_and_confdata_from_check(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from tests.planner.export.test_export_rapid import parse_rapid

    out = tmp_path / "ah.mod"
    code, _, err = run(capsys, "export", str(STATOR), "--format", "rapid", "-o", str(out))
    assert code == 0, err
    code, checked, _ = run(capsys, "check", str(STATOR), "--json")
    rows = {r["id"]: r for r in json.loads(checked)["points"]}
    parsed = parse_rapid(out.read_text())
    plan = load_plan(STATOR)
    n_confs = 0
    for p in plan.points:
        T, conf = parsed["targets"][(p.id, "start")]
        axis_err = np.degrees(np.arccos(np.clip(T[:3, 2] @ -np.array(p.normal), -1, 1)))
        assert axis_err < 1e-3  # the sensor looks into the face, whoever chose the rotation
        if rows[p.id]["confdata"] is not None:
            assert list(conf) == rows[p.id]["confdata"]
            n_confs += 1
    assert n_confs >= 1
