"""Tests of calib.atomic_io: atomic replacement, no leftovers, errors leave the target intact."""

from __future__ import annotations

import stat
from pathlib import Path

import pytest

from calib import atomic_io
from calib.atomic_io import write_bytes_atomic, write_text_atomic


def test_write_creates_and_replaces(tmp_path: Path) -> None:
    target = tmp_path / "plan.json"
    write_text_atomic(target, "first\n")
    assert target.read_text() == "first\n"
    write_text_atomic(target, "second\n")
    assert target.read_text() == "second\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plan.json"]


def test_keeps_mode_of_replaced_file(tmp_path: Path) -> None:
    target = tmp_path / "prog.mod"
    target.write_text("old")
    target.chmod(0o640)
    write_bytes_atomic(target, b"new")
    assert stat.S_IMODE(target.stat().st_mode) == 0o640
    assert target.read_bytes() == b"new"


def test_failure_leaves_target_and_no_temp_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    target = tmp_path / "plan.json"
    target.write_text("intact")

    def broken_replace(self: Path, dst: Path) -> None:
        raise OSError("disk full")

    monkeypatch.setattr(atomic_io.Path, "replace", broken_replace)
    with pytest.raises(OSError, match="disk full"):
        write_text_atomic(target, "never seen")
    assert target.read_text() == "intact"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plan.json"]


def test_missing_directory_raises_oserror_naming_target(tmp_path: Path) -> None:
    target = tmp_path / "nope" / "plan.json"
    with pytest.raises(FileNotFoundError) as info:
        write_text_atomic(target, "x")
    assert info.value.filename == str(target)
    assert "cannot write into" in str(info.value.strerror)
