"""``wobjcal ui`` stops on SIGTERM with exit 143 and on Ctrl-C (SIGINT) with 130, as
``docs/cli.md`` documents (it used to exit 0 either way)."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize(("sig", "code"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_ui_exit_code_after_a_signal(sig: signal.Signals, code: int, tmp_path: Path) -> None:
    from webui.testing import box_plan

    plan = box_plan(tmp_path / "plan")  # a small cell: the server is up in seconds
    proc = subprocess.Popen(
        [sys.executable, "-m", "planner", "ui", str(plan), "--port", "0", "--fresh"],
        cwd=REPO,
        stderr=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        text=True,
    )
    try:
        assert proc.stderr is not None
        deadline = time.monotonic() + 120.0
        line = ""
        while time.monotonic() < deadline:
            line = proc.stderr.readline()
            if "wobjcal UI on http://127.0.0.1:" in line or not line:
                break
        assert "wobjcal UI on http://127.0.0.1:" in line, line
        proc.send_signal(sig)
        assert proc.wait(timeout=60) == code
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
