"""``wobjcal export`` refuses a plan with an infeasible point unless told to write it anyway."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.planner.cli.test_cli import STATOR, _moved_copy, run


@pytest.mark.slow
def test_export_of_infeasible_plan_exits_1_naming_the_point(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    moved = _moved_copy(tmp_path, "A", (0.0, -5.0, 0.0))
    out = tmp_path / "prog.mod"
    code, _, err = run(capsys, "export", str(moved), "--format", "rapid", "-o", str(out))
    assert code == 1
    assert "point A is not feasible" in err and "--force" in err
    assert not out.exists()
    for flag in ("--force", "--no-check"):
        code, _, err = run(capsys, "export", str(moved), "--format", "rapid", "-o", str(out), flag)
        assert code == 0, err
        assert out.read_text().startswith("MODULE ")
        out.unlink()


@pytest.mark.slow
def test_export_of_feasible_plan_checks_and_writes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "ah.mod"
    code, _, err = run(capsys, "export", str(STATOR), "--format", "rapid", "-o", str(out))
    assert code == 0, err
    text = out.read_text()
    assert "ADAPTIVE" in text and "confdata unknown" not in text


# ---- program injection, incomplete plans, read-only and linked targets (issue 10, item 5) ----
HOSTILE = 'A"\nEVIL();\n! x'


def test_a_point_id_with_a_newline_or_quote_is_refused_by_the_plan() -> None:
    import json

    from calib.plan.file import PlanError, plan_from_json

    doc = json.loads(STATOR.read_text())
    doc["points"][0]["id"] = HOSTILE
    with pytest.raises(PlanError, match=r"points\[0\]\.id: must be a name matching"):
        plan_from_json(json.dumps(doc))
    doc["points"][0]["id"] = "A"
    doc["name"] = "plan\nEVIL"
    with pytest.raises(PlanError, match=r"^plan: name: must be a name matching"):
        plan_from_json(json.dumps(doc))


@pytest.mark.parametrize("fmt", ["rapid", "krl", "urscript", "fanuc"])
def test_every_writer_escapes_ids_and_names(fmt: str) -> None:
    """A job built in code (no plan to restrict it) with a hostile id and plan name: no line of
    any program starts with the injected statement, and string literals stay closed."""
    from dataclasses import replace

    from calib.plan.file import load_plan
    from planner.export import export_files
    from planner.export.job import ToolData, build_job
    from planner.plan_cell import nominal_T_base_wobj

    plan = load_plan(STATOR)
    job = build_job(plan, nominal_T_base_wobj(plan), ToolData(np.eye(4)))
    targets = (replace(job.targets[0], point_id=HOSTILE, role=HOSTILE), *job.targets[1:])
    job = replace(job, targets=targets, plan_name=HOSTILE, adaptive=None)
    if fmt == "fanuc":  # its CONFIG needs a configuration at every target
        from tests.planner.export.test_export_fanuc import with_arms

        job = with_arms(job)
    comment = {"rapid": "!", "krl": ";", "urscript": "#", "fanuc": "!"}[fmt]
    for text in export_files(job, fmt).values():
        for line in text.splitlines():
            body = line.split(":", 1)[1] if fmt == "fanuc" and line[:5].strip().isdigit() else line
            body = body.strip()
            assert not body.startswith("EVIL"), line
            if "EVIL" in body and not body.startswith(comment):
                assert body.count('"') % 2 == 0, line  # no literal left open


@pytest.mark.slow
def test_an_incomplete_a_h_plan_is_refused_unless_forced(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Exporting an A-H plan without E silently wrote a non-adaptive program."""
    import json

    doc = json.loads(STATOR.read_text())
    doc["points"] = [p for p in doc["points"] if p["id"] != "E"]
    plan = tmp_path / "no_e.json"
    plan.write_text(json.dumps(doc))
    out = tmp_path / "prog.mod"
    for extra in ((), ("--no-check",)):
        code, _, err = run(capsys, "export", str(plan), "--format", "rapid", "-o", str(out), *extra)
        assert code == 1 and "wrong count of ['E']" in err and not out.exists()
    code, _, err = run(capsys, "export", str(plan), "--format", "rapid", "-o", str(out), "--force")
    assert code == 0 and "layout:" in err
    assert "NOMINAL FRAME" in out.read_text()


def test_export_refuses_read_only_and_writes_through_links(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ro = tmp_path / "signed_off.mod"
    ro.write_text("MODULE old\n")
    ro.chmod(0o444)
    args = ("export", str(STATOR), "--format", "rapid", "--no-check", "-o")
    code, _, err = run(capsys, *args, str(ro))
    assert code == 2 and "read-only file (mode 444), not overwritten" in err
    assert ro.read_text() == "MODULE old\n"
    real = tmp_path / "real.mod"
    real.write_text("old")
    link = tmp_path / "link.mod"
    link.symlink_to(real)
    code, _, err = run(capsys, *args, str(link))
    assert code == 0, err
    assert link.is_symlink() and real.read_text().startswith("MODULE ")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.mod", "real.mod", "signed_off.mod"]
