"""Kernels with one fixed signature compiled on first use
(:mod:`planner.cell.kernels.lazy_kernel`)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numba as nb
import numpy as np
import pytest

from planner.cell.kernels.lazy_kernel import lazy_njit

ROOT = Path(__file__).resolve().parents[4]


@lazy_njit("void(float64[:, ::1], int64, float64)")
def _put(W: np.ndarray, i: int, x: float) -> None:
    W[i, 0] = x


@nb.njit  # not cached: compiled (so typed against _put) in every run
def _put_constants(W: np.ndarray) -> None:
    _put(W, 0, 1.0)  # literal 0: an untyped kernel would compile a copy for it
    _put(W, 1, 2)  # literal 1 and an int for the float
    _put(W, W.shape[0] - 1, 3.0)


@lazy_njit("float64(float64[::1])")
def _total(a: np.ndarray) -> float:
    return a.sum()


def test_one_version_for_every_caller_and_constants_convert() -> None:
    W = np.zeros((3, 3))
    _put_constants(W)
    assert W[:, 0].tolist() == [1.0, 2.0, 3.0]
    assert len(_put.signatures) == 1  # not one per literal
    _put(W, 2, 5)  # from Python: the same version
    assert W[2, 0] == 5.0 and len(_put.signatures) == 1


def test_a_call_whose_types_do_not_convert_is_an_error_not_a_new_version() -> None:
    with pytest.raises(TypeError):
        _total(np.ones((2, 2)))  # first call, wrong rank: not the 1-D version on its memory
    assert _total(np.ones(3)) == 3.0


@lazy_njit("float64(float64[::1], int64)")
def _first(a: np.ndarray, i: int) -> float:
    return a[i]


def test_a_first_call_from_python_runs_the_fixed_version() -> None:
    assert _first(np.array([1.0, 2.0]), 1) == 2.0  # the call that compiles returns the answer
    assert len(_first.signatures) == 1
    with pytest.raises(TypeError):
        _total(np.ones(3, dtype=np.float32))
    assert len(_total.signatures) == 1


def test_importing_the_gjk_and_bound_kernels_compiles_nothing(tmp_path: Path) -> None:
    """A fresh interpreter with an empty kernel cache: the import is instant and no kernel has
    a compiled version until one is used (the background helper then compiles without
    racing the importer for the same kernels)."""
    code = (
        "import time; t = time.perf_counter()\n"
        "from planner.cell.kernels import bound_kernels as B, gjk_kernels as G\n"
        "dt = time.perf_counter() - t\n"
        "compiled = [n for m in (B, G) for n, f in vars(m).items()\n"
        "            if hasattr(f, 'signatures') and f.signatures]\n"
        "print(compiled)\n"
    )
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), WOBJCAL_BACKGROUND_COMPILE="0")
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True
    )
    assert out.stdout.strip() == "[]"
    assert not any(tmp_path.rglob("*.nbi"))  # nothing compiled, so nothing cached
