"""A validation's worker processes stop with it (issue 10, item 7): SIGTERM to ``wobjcal
validate`` left its workers running at 100 % CPU; SIGKILL of the parent must not either."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"


def _children(pid: int) -> set[int]:
    out: set[int] = set()
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            out |= {int(c) for c in (task / "children").read_text().split()}
        except OSError:
            continue
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0]
    except OSError:
        return False
    return state != "Z"


def _start_validation() -> tuple[subprocess.Popen[bytes], set[int]]:
    cmd = [sys.executable, "-m", "planner", "validate", str(STATOR), "--trials", "12000",
           "--reach-trials", "0", "--no-check", "--workers", "2"]  # fmt: skip
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    workers: set[int] = set()
    while time.monotonic() < deadline and len(workers) < 2:
        time.sleep(0.2)
        # the workers are the fork server's children (planner.sim.pool)
        workers = {w for c in _children(proc.pid) for w in _children(c)}
        assert proc.poll() is None, proc.stderr.read() if proc.stderr else ""
    assert len(workers) >= 2, "the validation never started its workers"
    return proc, workers | _children(proc.pid)


def _gone(pids: set[int], timeout_s: float = 120.0) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if not any(_alive(p) for p in pids):
            return True
        time.sleep(0.2)
    return False


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="needs Linux /proc")
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL])
def test_workers_stop_with_the_validation(sig: signal.Signals) -> None:
    proc, workers = _start_validation()
    try:
        proc.send_signal(sig)
        code = proc.wait(timeout=120)
        assert _gone(workers), f"workers {workers} still running after {sig.name}"
        if sig == signal.SIGTERM:
            assert code == 143
            assert proc.stderr is not None and b"wobjcal validate: terminated" in proc.stderr.read()
    finally:
        proc.kill()
        for p in workers:
            if _alive(p):
                os.kill(p, signal.SIGKILL)
