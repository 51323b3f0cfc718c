"""Where the compiled kernels are cached (:mod:`planner.cell.kernels.kernel_cache`).

numba picks the cache directory when a function is decorated, once per process, so every case
runs in a fresh interpreter.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from planner.cell.kernels.kernel_cache import SOURCES, source_key

ROOT = Path(__file__).resolve().parents[4]

_PROBE = (
    "import numba; from planner.cell.kernels.kernel_cache import configure, kernel_cache_dir; "
    "print(configure()); print(kernel_cache_dir()); print(repr(numba.config.CACHE_DIR))"
)


def _run(env_extra: dict[str, str]) -> list[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR",)}
    env.update(env_extra)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    out = subprocess.run(
        [sys.executable, "-c", _PROBE], capture_output=True, text=True, env=env, check=True
    )
    return out.stdout.strip().splitlines()


@pytest.mark.slow
def test_kernels_cached_under_wobjcal_cache_root_by_source_key(tmp_path: Path) -> None:
    stale = tmp_path / "numba" / ("0" * 16)  # another version's kernels
    stale.mkdir(parents=True)
    (stale / "x.nbi").write_text("old")
    keep = tmp_path / "numba" / "notes"  # not a version's directory
    keep.mkdir()
    lines = _run({"WOBJCAL_CACHE_DIR": str(tmp_path)})
    assert lines[0] == lines[1] == str(tmp_path / "numba" / source_key())
    assert (tmp_path / "numba" / source_key()).is_dir()
    assert not stale.exists() and keep.is_dir()


def test_the_key_follows_every_kernel_source(tmp_path: Path) -> None:
    """A cached caller holds its callees' code, and numba checks only the caller's own file:
    a change to any kernel module must change the directory (a fresh compile)."""
    here = ROOT / "planner" / "cell" / "kernels"
    for name in SOURCES:
        shutil.copy(here / f"{name}.py", tmp_path / f"{name}.py")
    assert source_key(tmp_path) == source_key()
    for name in ("gjk_kernels", "lazy_kernel"):
        path = tmp_path / f"{name}.py"
        text = path.read_text()
        path.write_text(text + "\n# changed\n")
        assert source_key(tmp_path) != source_key()
        path.write_text(text)


def test_numba_cache_dir_wins(tmp_path: Path) -> None:
    mine = tmp_path / "mine"
    lines = _run({"WOBJCAL_CACHE_DIR": str(tmp_path / "w"), "NUMBA_CACHE_DIR": str(mine)})
    assert lines[0] == str(mine)
    assert not (tmp_path / "w" / "numba").exists()


def test_unwritable_root_leaves_numba_defaults(tmp_path: Path) -> None:
    blocker = tmp_path / "a_file"
    blocker.write_text("not a directory")
    lines = _run({"WOBJCAL_CACHE_DIR": str(blocker)})
    assert lines == ["None", "None", "''"]


@pytest.mark.slow
def test_kernels_load_from_the_cache_in_a_new_process(tmp_path: Path) -> None:
    """A kernel compiled by one process is loaded, not recompiled, by the next."""
    code = (
        "import numpy as np; from planner.cell.kernels.field_kernels import "
        "point_triangle_distance as f; "
        "z = np.zeros(3); e = np.eye(3); "
        "print(round(f(np.ones(3), e[0], e[1], e[2]), 12)); print(len(f.stats.cache_hits))"
    )
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["WOBJCAL_CACHE_DIR"] = str(tmp_path)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    runs = [
        subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                       check=True).stdout.split()
        for _ in range(2)
    ]  # fmt: skip
    # distance from (1, 1, 1) to the triangle through the unit points: sqrt(3) - 1/sqrt(3)
    assert runs[0][0] == runs[1][0] == str(round(3**0.5 - 3**-0.5, 12))
    assert runs[0][1] == "0" and runs[1][1] == "1"
    assert list((tmp_path / "numba").rglob("*.nbi"))
