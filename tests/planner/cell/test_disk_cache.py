"""The per-user disk cache stays within its bound (:mod:`planner.cell.disk_cache`)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from planner.cell.disk_cache import DEFAULT_MAX_MB, cache_path, load_arrays, max_bytes, save_arrays

KIND = "fields_test"
MB = np.zeros(125_000)  # 1 MB of float64 (about 1.0 MB on disk, uncompressed npz)


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("WOBJCAL_CACHE_DIR", str(tmp_path))
    monkeypatch.setenv("WOBJCAL_CACHE_MAX_MB", "2.5")
    return tmp_path


def _age(key: str, seconds_ago: float) -> None:
    t = cache_path(KIND, key).stat().st_mtime - seconds_ago
    os.utime(cache_path(KIND, key), (t, t))


def test_the_least_recently_used_files_go_first_and_a_load_counts_as_use(cache: Path) -> None:
    for i, key in enumerate("abc"):
        save_arrays(KIND, key, 1, {"x": MB + i})
        _age(key, 100 - 10 * i)  # a is the oldest
    assert not cache_path(KIND, "a").exists()  # 3 MB > 2.5 MB: the oldest went
    assert load_arrays(KIND, "b", 1) is not None  # b is now the most recently used
    save_arrays(KIND, "d", 1, {"x": MB})
    left = sorted(p.stem for p in (cache / KIND).glob("*.npz"))
    assert left == ["b", "d"]  # c was the least recently used
    assert np.array_equal(load_arrays(KIND, "b", 1)["x"], MB + 1)  # type: ignore[index]


def test_the_file_just_written_stays_even_when_alone_over_the_bound(
    cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("WOBJCAL_CACHE_MAX_MB", "0.5")
    save_arrays(KIND, "big", 1, {"x": MB})
    assert cache_path(KIND, "big").exists()
    save_arrays(KIND, "next", 1, {"x": MB})
    assert [p.stem for p in (cache / KIND).glob("*.npz")] == ["next"]


def test_a_bad_bound_is_named_and_the_default_used(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    for bad in ("lots", "-3", "nan"):
        monkeypatch.setenv("WOBJCAL_CACHE_MAX_MB", bad)
        assert max_bytes() == DEFAULT_MAX_MB * 1e6
        assert f"WOBJCAL_CACHE_MAX_MB={bad!r}" in caplog.text
    monkeypatch.setenv("WOBJCAL_CACHE_MAX_MB", "12")
    assert max_bytes() == 12e6
