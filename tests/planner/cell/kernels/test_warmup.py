"""The kernels compiled ahead of use (:mod:`planner.cell.kernels.warmup`).

Each case runs in a fresh interpreter on a copy of this process's kernel cache (so nothing is
compiled unless a signature is wrong, and the user's cache is not touched).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from planner.cell.kernels.kernel_cache import configure, marker_path, source_key, start_background

ROOT = Path(__file__).resolve().parents[4]

_CHECK = """
import numpy as np
from numba.core import event
from planner.cell.kernels.warmup import compile_kernels
compile_kernels()
compiled = []
class Count(event.Listener):
    def on_start(self, ev): compiled.append(ev.data["dispatcher"].py_func.__name__)
    def on_end(self, ev): pass
event.register("numba:compile", Count())
from planner.cell.cell import Cell
from planner.cell.probe.reachability import sample_surface
from tests.cells import add_box_on_table
with Cell(use_acl_cache=False) as c:
    add_box_on_table(c, 0.02, (1.05, -0.2, 0.75))
    pts, nrm, _ = sample_surface(c.work_object.mesh, 200, np.random.default_rng(1))
    pts[100:] -= nrm[100:] * 0.01
    c.check_probes(pts, nrm)
print("compiled:", sorted(set(compiled)))
"""


def _cache(tmp_path: Path) -> Path:
    """Where a process with ``WOBJCAL_CACHE_DIR=tmp_path/cache`` keeps its kernels."""
    return tmp_path / "cache" / "numba" / source_key()


def _env(tmp_path: Path, **extra: str) -> dict[str, str]:
    warm = configure()
    if warm is None or not warm.is_dir():
        pytest.skip("no writable kernel cache to copy")
    shutil.copytree(warm, _cache(tmp_path), ignore=shutil.ignore_patterns("warm-*"))
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(WOBJCAL_CACHE_DIR=str(tmp_path / "cache"), **extra)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    return env


@pytest.mark.slow
def test_a_check_after_the_warm_up_compiles_nothing(tmp_path: Path) -> None:
    """The warm-up's signatures are the ones a check calls with: after it, a check (a fresh
    distance field, parts and pairs, slack bounds of points pushed into the part) finds every
    kernel in the cache. A wrong signature would make it compile (and the marker lie)."""
    env = _env(tmp_path, WOBJCAL_BACKGROUND_COMPILE="0")
    out = subprocess.run(
        [sys.executable, "-c", _CHECK], capture_output=True, text=True, env=env, check=True
    )
    assert out.stdout.strip().splitlines()[-1] == "compiled: []"


@pytest.mark.slow
def test_the_warm_up_command_and_the_background_helper_write_the_marker(tmp_path: Path) -> None:
    env = _env(tmp_path, WOBJCAL_BACKGROUND_COMPILE="0")
    cache = _cache(tmp_path)
    out = subprocess.run(
        [sys.executable, "-m", "planner.cell.kernels.warmup"],
        capture_output=True,
        text=True,
        env=env,
        check=True,
    )
    assert "kernels ready" in out.stdout and marker_path(cache).exists()
    marker_path(cache).unlink()
    # importing a kernel module with an unwarmed cache starts the helper, which writes it
    env["WOBJCAL_BACKGROUND_COMPILE"] = "1"
    code = (
        "import planner.cell.kernels.gjk_kernels, planner.cell.kernels.kernel_cache as k; "
        "print(bool(k._helper))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True
    )
    assert out.stdout.strip() == "True"
    deadline = time.monotonic() + 120
    while not marker_path(cache).exists() and time.monotonic() < deadline:
        time.sleep(0.2)
    assert marker_path(cache).exists()


def test_no_helper_for_a_warmed_cache_none_or_when_turned_off(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("WOBJCAL_BACKGROUND_COMPILE", "1")
    assert not start_background(None)  # numba's own cache directory
    marker_path(tmp_path).write_text("")
    assert not start_background(tmp_path)  # warmed already: no process started
    monkeypatch.setenv("WOBJCAL_BACKGROUND_COMPILE", "0")
    assert not start_background(tmp_path / "other")
