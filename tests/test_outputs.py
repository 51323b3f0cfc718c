"""Never report a failed write as done (issue 27, items 1 and 3).

Outputs: a device, FIFO or ``/dev/stdout`` given as the output is written in place, never
replaced by a regular file; a write, flush, sync or close that fails (a full disk: ``ENOSPC``)
is exit 2 naming the file (or standard output) and the reason. Caches: an unwritable or full
cache slows a command, it never fails it. Full and null devices are private nodes made with
``mknod`` in the test's folder (``/dev/full`` is 1,7 and ``/dev/null`` 1,3), never the system's.
"""

from __future__ import annotations

import errno
import importlib.util
import json
import logging
import os
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from calib import atomic_io
from calib.atomic_io import write_bytes_atomic, write_text_atomic
from planner.cli.main import main

REPO = Path(__file__).resolve().parent.parent
PLAN = REPO / "assets" / "plans" / "plate_holes_321.json"
MEASURED = REPO / "tests" / "data" / "results" / "wobjcal_measured.json"
FULL, NULL = 7, 3  # minor numbers of /dev/full and /dev/null (major 1)
NO_SPACE = os.strerror(errno.ENOSPC)  # "No space left on device"


def device(path: Path, minor: int) -> Path:
    """A private character device node ``1, minor`` at ``path`` (skip where not allowed)."""
    try:
        os.mknod(path, stat.S_IFCHR | 0o600, os.makedev(1, minor))
        os.close(os.open(path, os.O_WRONLY))  # a folder mounted nodev refuses to open it
    except PermissionError as exc:
        pytest.skip(f"cannot make or open a device node here: {exc}")
    return path


def is_device(path: Path) -> bool:
    return stat.S_ISCHR(path.lstat().st_mode)


def wobjcal(*argv: str, stdout: object, cwd: Path) -> subprocess.CompletedProcess[str]:
    """``python -m planner ARGV`` in a fresh interpreter, stdout given (a file object)."""
    path = os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])
    env = dict(os.environ, PYTHONPATH=path)
    return subprocess.run(
        [sys.executable, "-m", "planner", *argv],
        stdout=stdout,  # type: ignore[arg-type]
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        cwd=cwd,
        timeout=300,
        check=False,
    )


def export_json(out: str) -> list[str]:
    return ["export", str(PLAN), "--format", "json", "--no-check", "-o", out]


# ---- devices, FIFOs and symbolic links to them are written in place --------------------------
@pytest.mark.reference
def test_export_to_a_full_device_exits_2_and_the_node_stays(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Before: the node became a regular JSON file, exit 0."""
    full = device(tmp_path / "full", FULL)
    link = tmp_path / "link.json"
    link.symlink_to(full)
    for target in (full, link):
        code = main(export_json(str(target)))
        err = capsys.readouterr().err
        assert code == 2, err
        assert f"wobjcal export: error: {target}: {NO_SPACE}" in err and "wrote" not in err
    assert is_device(full) and link.is_symlink()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["full", "link.json"]


@pytest.mark.reference
def test_export_to_a_null_device_succeeds_and_the_node_stays(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Before: ``/dev/null`` given as the output became a regular file."""
    null = device(tmp_path / "null", NULL)
    assert main(export_json(str(null))) == 0
    assert f"wrote {null}" in capsys.readouterr().err
    assert is_device(null)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["null"]


def test_every_file_output_writes_a_device_or_fifo_in_place(tmp_path: Path) -> None:
    """``validate --json``, ``suggest -o``, plots, autosave and caches all write through
    :func:`calib.atomic_io.write_bytes_atomic`: a device or FIFO is written, not replaced."""
    full = device(tmp_path / "full", FULL)
    with pytest.raises(OSError) as info:
        write_text_atomic(full, "{}\n")
    assert info.value.errno == errno.ENOSPC and info.value.filename == str(full)
    assert is_device(full)
    null = device(tmp_path / "null", NULL)
    assert write_bytes_atomic(null, b"x" * 100_000) == null and is_device(null)
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    reader = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK)  # a reader waits on the other end
    try:
        write_text_atomic(fifo, "through the pipe\n")
        assert os.read(reader, 100) == b"through the pipe\n"
    finally:
        os.close(reader)
    assert stat.S_ISFIFO(fifo.lstat().st_mode)


@pytest.mark.reference
@pytest.mark.slow
def test_dev_stdout_redirected_to_a_file_gets_the_output(tmp_path: Path) -> None:
    """``export -o /dev/stdout >> out.txt``. Before: out.txt stayed empty (or was replaced)
    and the plan went to wherever stderr pointed."""
    out = tmp_path / "out.txt"
    out.write_text("first line\n")
    with out.open("a") as handle:  # `>>`: written at the end, the first line kept
        proc = wobjcal(*export_json("/dev/stdout"), stdout=handle, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.strip() == "wrote /dev/stdout"
    head, _, rest = out.read_text().partition("\n")
    assert head == "first line" and json.loads(rest)["schema"] == "wobjcal.plan/1"


# ---- a failed write names the file and is exit 2 ------------------------------------------------
@pytest.mark.reference
def test_a_full_disk_under_a_regular_file_names_the_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The temporary file's data land on a full device: ``ENOSPC`` on a regular output.
    Before: "error: [Errno 28] No space left on device", without the file."""
    full = device(tmp_path / "full", FULL)
    monkeypatch.setattr(
        atomic_io, "_open_temporary", lambda *_: (os.open(full, os.O_WRONLY), False)
    )
    target = tmp_path / "plan.json"
    assert main(export_json(str(target))) == 2
    err = capsys.readouterr().err
    assert f"wobjcal export: error: {target}: {NO_SPACE}" in err and "wrote" not in err
    assert not target.exists()


def test_a_failed_sync_names_the_file_and_leaves_the_old_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Before: the ``fsync`` error escaped without a file name."""
    target = tmp_path / "plan.json"
    target.write_text("old")

    def failing_fsync(fd: int) -> None:
        raise OSError(errno.EIO, os.strerror(errno.EIO))

    monkeypatch.setattr(atomic_io.os, "fsync", failing_fsync)
    with pytest.raises(OSError) as info:
        write_text_atomic(target, "new")
    assert info.value.errno == errno.EIO and info.value.filename == str(target)
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plan.json"]


@pytest.mark.slow
def test_schema_into_a_full_device_exits_2_naming_standard_output(tmp_path: Path) -> None:
    """Standard output itself is the full device (file descriptor 1 of a fresh process).
    Before: "error: [Errno 28] No space left on device", not saying it was the output."""
    full = device(tmp_path / "full", FULL)
    with full.open("w") as handle:
        proc = wobjcal("schema", stdout=handle, cwd=tmp_path)
    assert proc.returncode == 2
    assert proc.stderr == (
        f"wobjcal schema: error: cannot write to standard output: [Errno 28] {NO_SPACE}\n"
    )


@pytest.mark.parametrize(
    "argv",
    [
        ["calibrate", "--json", str(PLAN), str(MEASURED)],
        pytest.param(["check", "--json", str(PLAN)], marks=pytest.mark.slow),
    ],
    ids=["calibrate", "check"],
)
@pytest.mark.reference
def test_json_into_a_full_stdout_exits_2(
    argv: list[str],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """``check --json`` and ``calibrate --json`` into a full device. Before: exit 0, the
    output lost (the error surfaced only at the final flush, which was ignored)."""
    full = device(tmp_path / "full", FULL)
    with full.open("w") as handle:
        monkeypatch.setattr(sys, "stdout", handle)
        code = main(argv)
        monkeypatch.undo()
        err = capsys.readouterr().err
        assert code == 2, err
        assert f"error: cannot write to standard output: [Errno 28] {NO_SPACE}" in err


def test_autosave_into_a_full_device_is_reported_and_the_node_stays(tmp_path: Path) -> None:
    """Before: the node was replaced by a regular file and the autosave said done."""
    from webui.state import SessionState

    full = device(tmp_path / "full", FULL)
    s: SessionState[int] = SessionState(0, serialize=lambda d: b"%d" % d, autosave_path=full)
    s.apply(1, "edit")
    assert s.doc == 1 and not s.autosave()
    assert str(full) in s.last_autosave_error and NO_SPACE in s.last_autosave_error
    assert is_device(full)


# ---- caches are optional -----------------------------------------------------------------------
def test_an_unwritable_disk_cache_warns_once_per_kind(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """A root under a regular file (root ignores permissions, not this): every save fails,
    one warning says so. Before: one warning per file."""
    from planner.cell import disk_cache

    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("WOBJCAL_CACHE_DIR", str(blocker / "cache"))
    with caplog.at_level(logging.WARNING):
        for key in ("a", "b", "c"):
            disk_cache.save_arrays("fields", key, 1, {"x": np.zeros(3)})
            assert disk_cache.load_arrays("fields", key, 1) is None
    lines = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert len(lines) == 1 and "cannot write cache file" in lines[0], lines
    assert "going on without the fields cache" in lines[0]


_KERNEL = """
import numba


@numba.njit(cache=True)
def plus_one(x):
    return x + 1


@numba.njit(cache=True)
def twice(x):
    return 2 * x
"""


def test_a_full_kernel_cache_compiles_in_memory_with_one_warning(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """numba cannot save (a full disk) or load (an I/O error) a cached kernel: it runs all the
    same, one warning. Before: the OSError failed the command (``check`` exit 2)."""
    from numba.core import caching

    from planner.cell.kernels.kernel_cache import guard_cache_io

    guard_cache_io()
    monkeypatch.setenv("WOBJCAL_CACHE_DIR", str(tmp_path / "cache"))  # a fresh "once"

    def no_space(*_args: object) -> None:
        raise OSError(errno.ENOSPC, NO_SPACE)

    monkeypatch.setattr(caching.IndexDataCacheFile, "save", no_space)
    monkeypatch.setattr(caching.IndexDataCacheFile, "load", no_space)
    source = tmp_path / "wobjcal_kernel_probe.py"
    source.write_text(_KERNEL)
    spec = importlib.util.spec_from_file_location("wobjcal_kernel_probe", source)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    with caplog.at_level(logging.WARNING):
        assert module.plus_one(1) == 2 and module.twice(3) == 6
    lines = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert len(lines) == 1 and "cannot use the kernel cache" in lines[0], lines
    assert NO_SPACE in lines[0]
