"""``wobjcal export`` refuses a plan with an infeasible point unless told to write it anyway."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.test_cli import STATOR, _moved_copy, run


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


def test_export_of_feasible_plan_checks_and_writes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "ah.mod"
    code, _, err = run(capsys, "export", str(STATOR), "--format", "rapid", "-o", str(out))
    assert code == 0, err
    text = out.read_text()
    assert "ADAPTIVE" in text and "confdata unknown" not in text
