"""Tests of planner.cell.scene.acl: the sampled allowed-collision list and its cache."""

from __future__ import annotations

import numpy as np
import pytest

import planner.cell.scene.acl as acl_module
from planner.cell.cell import Cell
from planner.cell.scene.acl import AllowedCollisions, pair, sample_configurations


def test_builtin_acl_allows_adjacent_links_and_the_tool_mount(cell: Cell) -> None:
    acl = cell.checker.acl
    for a, b in [("base_link", "link_1"), ("link_4", "link_5"), ("link_6", "tool_mount")]:
        assert pair(a, b) in acl.allowed
    # the forearm can hit the tool: that pair is checked, never allowed
    assert pair("link_3", "feeder_body") not in acl.allowed
    assert acl.n_samples == 1000


@pytest.mark.slow
def test_ur5_acl_keeps_real_self_collisions_checked(ur5: Cell) -> None:
    """Base vs upper arm touch in ~37 % of random samples: a real collision, not an artefact."""
    acl = ur5.checker.acl
    f = acl.near_fraction[pair("base_link_inertia", "upper_arm_link")]
    assert 0.25 < f < 0.55
    assert pair("base_link_inertia", "upper_arm_link") not in acl.allowed
    assert pair("forearm_link", "wrist_2_link") not in acl.allowed
    # the offset wrist links touch in every pose: allowed, or every pose would collide
    assert acl.near_fraction[pair("wrist_1_link", "wrist_2_link")] == 1.0
    assert pair("wrist_1_link", "wrist_2_link") in acl.allowed


def test_acl_cache_round_trip(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv("WOBJCAL_CACHE_DIR", str(tmp_path))
    acl_module._MEMORY_CACHE.clear()
    with Cell(acl_samples=150) as a:
        acl = a.checker.acl
    files = list((tmp_path / "acl").glob("*.json"))
    assert len(files) == 1 and files[0].stem == acl.key
    assert AllowedCollisions.from_json(files[0].read_text()) == acl
    acl_module._MEMORY_CACHE.clear()  # force a read from disk
    mtime = files[0].stat().st_mtime_ns
    with Cell(acl_samples=150) as b:
        assert b.checker.acl == acl
    assert files[0].stat().st_mtime_ns == mtime
    with Cell(acl_samples=160) as c:  # other settings: another key
        assert c.checker.acl.key != acl.key
    acl_module._MEMORY_CACHE.clear()


def test_samples_stay_within_limits(rng) -> None:
    lo, hi = np.array([-1.0, 0.0, -np.inf]), np.array([1.0, 0.5, np.inf])
    q = sample_configurations(lo, hi, 5000, rng)
    assert q.shape == (5000, 3)
    assert np.all(q >= [-1.0, 0.0, -np.pi]) and np.all(q <= [1.0, 0.5, np.pi])
    # uniform: the mean of each column sits mid-range
    np.testing.assert_allclose(q.mean(axis=0), [0.0, 0.25, 0.0], atol=0.06)
