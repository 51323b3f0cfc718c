"""``wobjcal ui`` stops on SIGTERM with exit 143 and on Ctrl-C (SIGINT) with 130, as
``docs/cli.md`` documents (it used to exit 0 either way)."""

from __future__ import annotations

import os
import queue
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


#: Run ``sys.argv[1:]`` with SIGINT's default action (``exec`` keeps it; Python then makes it
#: KeyboardInterrupt).
_DEFAULT_SIGINT = (
    "import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); "
    "os.execv(sys.argv[1], sys.argv[1:])"
)


@pytest.mark.slow
@pytest.mark.parametrize(("sig", "code"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_ui_exit_code_after_a_signal(sig: signal.Signals, code: int, tmp_path: Path) -> None:
    from webui.testing import box_plan

    plan = box_plan(tmp_path / "plan")  # a small cell: the server is up in seconds
    ui = [sys.executable, "-m", "planner", "ui", str(plan), "--port", "0", "--fresh"]
    proc = subprocess.Popen(
        # started as from a terminal: a suite run as a background job ignores SIGINT, and a
        # process inherits that (Python then leaves Ctrl-C ignored, as it should); the default
        # is put back before the UI's interpreter starts
        [sys.executable, "-c", _DEFAULT_SIGINT, *ui],
        cwd=REPO,
        env={**os.environ, "PYTHONFAULTHANDLER": "1"},  # SIGABRT dumps every thread's stack
        stderr=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        text=True,
    )
    lines: queue.Queue[str] = queue.Queue()

    def read() -> None:  # the pipe drained on its own thread: readline never blocks the test
        assert proc.stderr is not None
        for text in proc.stderr:
            lines.put(text)

    threading.Thread(target=read, daemon=True).start()
    try:
        deadline = time.monotonic() + 120.0
        seen = ""
        while "wobjcal UI on http://127.0.0.1:" not in seen:
            left = deadline - time.monotonic()
            assert left > 0 and proc.poll() is None, f"no server: {seen!r}"
            try:
                seen += lines.get(timeout=min(left, 1.0))
            except queue.Empty:
                continue
        proc.send_signal(sig)
        try:
            got = proc.wait(timeout=60)
        except subprocess.TimeoutExpired:  # hung: say where every thread of it is
            masks = _signal_masks(proc.pid)
            proc.send_signal(signal.SIGABRT)
            proc.wait(timeout=30)
            time.sleep(0.5)  # the reader thread drains the dump
            dump = "".join(lines.queue)
            raise AssertionError(
                f"no exit 60 s after {sig.name}; signal masks {masks}; its threads:\n{dump}"
            ) from None
        assert got == code, "".join(lines.queue)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def _signal_masks(pid: int) -> dict[str, str]:
    """The ignored, caught and blocked signal masks (hex, bit ``n - 1`` for signal ``n``) of
    process ``pid`` and of each of its threads, and this process's handler of SIGINT."""
    out = {"test's SIGINT handler": repr(signal.getsignal(signal.SIGINT))}
    try:
        for task in sorted(Path(f"/proc/{pid}/task").iterdir()):
            fields = dict(
                line.split(":\t", 1)
                for line in (task / "status").read_text().splitlines()
                if line.startswith(("SigIgn", "SigCgt", "SigBlk", "Name"))
            )
            out[task.name] = " ".join(f"{k}={v}" for k, v in sorted(fields.items()))
    except OSError as exc:
        out["error"] = str(exc)
    return out
