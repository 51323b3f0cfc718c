"""Autosave and server start (issue 10, item 6): a killed session's edits come back, one
autosave per plan and bound port under a lock, the real URL printed, the port range-checked."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from calib.errors import InputError
from planner.cell.disk_cache import cache_root
from planner.cli.main import main
from webui import autosave
from webui.server import run
from webui.testing import box_plan, free_port

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture
def autosave_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "autosave"
    monkeypatch.setattr(autosave, "AUTOSAVE_DIR", folder)
    return folder


def _edit_then_kill(plan: Path, port: int, home: Path) -> None:
    """Start the UI in another process, delete point P1 there, and kill -9 it."""
    child = textwrap.dedent(
        f"""
        import time
        from webui import plan_doc
        from webui.server import run
        app = run({str(plan)!r}, port={port}, block=False)
        app.state.apply(plan_doc.delete_point(app.state.doc, "P1"), "delete P1")
        print("edited", app.state.autosave_path, flush=True)
        time.sleep(120)
        """
    )
    # another home for the autosave, but this machine's caches: with a cold kernel cache the
    # child compiles every kernel first, which on a loaded machine outlasts the cell's 120 s
    env = {
        **os.environ,
        "HOME": str(home),
        "PYTHONPATH": str(REPO),
        "WOBJCAL_CACHE_DIR": str(cache_root()),
    }
    proc = subprocess.Popen([sys.executable, "-c", child], stdout=subprocess.PIPE, env=env)
    try:
        assert proc.stdout is not None
        lines = []
        for raw in proc.stdout:  # viser prints a banner first
            lines.append(raw.decode(errors="replace"))
            if lines[-1].startswith("edited "):
                break
        assert lines and lines[-1].startswith("edited "), "".join(lines)
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=60)
    finally:
        proc.kill()


@pytest.mark.slow
def test_the_edits_of_a_killed_session_are_restored_and_said(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Before: after kill -9 the same command loaded the original plan without a word, and the
    first edit overwrote the autosave."""
    home = tmp_path / "home"
    monkeypatch.setattr(autosave, "AUTOSAVE_DIR", home / ".cache" / "wobjcal" / "autosave")
    plan = box_plan(tmp_path / "plan")
    port = free_port()
    _edit_then_kill(plan, port, home)
    app = run(plan, port=port, block=False)
    try:
        assert "P1" not in app.state.doc.ids  # the edit is back
        assert app.autosave_note.startswith("restored the edits of the last session from")
        assert app.state.autosave_path == autosave.default_autosave_path(plan, port)
    finally:
        app.stop()
    fresh = run(plan, port=port, block=False, fresh=True)
    try:
        assert "P1" in fresh.state.doc.ids
        assert "kept as" in fresh.autosave_note
        kept = list(autosave.AUTOSAVE_DIR.glob("*.bak"))
        assert len(kept) == 1 and b'"P1"' not in kept[0].read_bytes()
    finally:
        fresh.stop()


def test_a_busy_port_is_said_and_each_server_has_its_own_locked_autosave(
    tmp_path: Path, autosave_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Before: viser silently bound the next port, the CLI printed the requested URL and both
    servers wrote one autosave file."""
    plan = box_plan(tmp_path)
    port = free_port()
    first = run(plan, port=port, block=False)
    second = run(plan, port=port, block=False)
    try:
        assert first.server.get_port() == port and second.server.get_port() != port
        assert first.state.autosave_path != second.state.autosave_path
        assert str(second.state.autosave_path).endswith(f"-{second.server.get_port()}.json")
        assert autosave.in_use(first.state.autosave_path)  # type: ignore[arg-type]
        with pytest.raises(InputError, match="in use by another wobjcal UI server"):
            run(plan, port=free_port(), block=False, autosave_path=first.state.autosave_path)
    finally:
        second.stop()
        first.stop()
    assert not autosave.in_use(first.state.autosave_path)  # type: ignore[arg-type]


def test_the_cli_prints_the_port_actually_bound(
    tmp_path: Path, autosave_dir: Path, monkeypatch: pytest.MonkeyPatch, capsys
) -> None:  # type: ignore[no-untyped-def]
    import webui.server

    monkeypatch.setattr(webui.server, "serve", lambda app, announce: (announce(), app.stop(), 0)[2])
    plan = box_plan(tmp_path)
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        assert main(["ui", str(plan), "--port", str(port)]) == 0
    err = capsys.readouterr().err
    assert f"port {port} is busy: serving on " in err
    bound = int(err.split("serving on ")[1].split()[0])
    assert f"wobjcal UI on http://127.0.0.1:{bound} " in err
    assert f"autosaves to {autosave.default_autosave_path(plan, bound)}" in err


def test_the_port_is_range_checked(capsys: pytest.CaptureFixture[str]) -> None:
    """Before: --port 99999 printed a traceback and hung."""
    assert main(["ui", "--port", "99999"]) == 2
    assert "must be 0-65535" in capsys.readouterr().err
    with pytest.raises(InputError, match="port: must be a whole number 0-65535"):
        run(None, port=99999, block=False)
