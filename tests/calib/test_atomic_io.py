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


# ---- like cp: read-only files, symbolic links; nothing left on kill (issue 10, item 5) ----------
def test_read_only_target_is_refused_even_for_root(tmp_path: Path) -> None:
    target = tmp_path / "prog.mod"
    target.write_text("signed off")
    target.chmod(0o444)
    with pytest.raises(PermissionError, match=r"read-only file \(mode 444\)") as info:
        write_text_atomic(target, "replaced")
    assert info.value.filename == str(target)
    assert target.read_text() == "signed off"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["prog.mod"]


def test_symlink_is_followed_like_cp(tmp_path: Path) -> None:
    real = tmp_path / "real.mod"
    real.write_text("old")
    link = tmp_path / "link.mod"
    link.symlink_to(real)
    assert write_text_atomic(link, "new") == real
    assert link.is_symlink() and real.read_text() == "new"
    dangling = tmp_path / "dangling.mod"
    dangling.symlink_to(tmp_path / "nowhere" / "x.mod")
    with pytest.raises(FileNotFoundError, match="dangling symbolic link"):
        write_text_atomic(dangling, "x")
    with pytest.raises(IsADirectoryError):
        write_text_atomic(tmp_path, "x")


def test_a_write_killed_midway_leaves_no_file(tmp_path: Path) -> None:
    """SIGKILL while the data are being written: the old file stays and no temporary is left."""
    import signal
    import subprocess
    import sys
    import textwrap

    target = tmp_path / "plan.json"
    target.write_text("old")
    child = textwrap.dedent(
        f"""
        import os, sys, time
        from calib import atomic_io
        def slow_fsync(fd):
            print("writing", flush=True)
            time.sleep(60)
        atomic_io.os.fsync = slow_fsync
        atomic_io.write_text_atomic({str(target)!r}, "new" * 1000)
        """
    )
    env = {**__import__("os").environ, "PYTHONPATH": str(Path(atomic_io.__file__).parents[1])}
    proc = subprocess.Popen([sys.executable, "-c", child], stdout=subprocess.PIPE, env=env)
    try:
        assert proc.stdout is not None and proc.stdout.readline() == b"writing\n"
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=60)
    finally:
        proc.kill()
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plan.json"]


def test_named_temporaries_of_dead_processes_are_removed(tmp_path: Path) -> None:
    """Where O_TMPFILE is missing, a killed writer's named temporary goes at the next write."""
    import subprocess
    import sys

    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True).stdout.strip()  # fmt: skip
    stale = tmp_path / f".plan.json.wobjcal-{dead}-0123abcd.tmp"
    stale.write_text("half")
    other = tmp_path / ".notes.tmp"  # not ours: kept
    other.write_text("x")
    write_text_atomic(tmp_path / "plan.json", "new")
    assert sorted(p.name for p in tmp_path.iterdir()) == [".notes.tmp", "plan.json"]
