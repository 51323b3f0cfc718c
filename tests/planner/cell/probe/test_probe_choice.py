"""Tests of planner.cell.probe.probe_choice: the rule, and the fast path against the exact check.

The exact check is ``check_probes(staged=False)``: one whole Bullet clearance query per
candidate, in order. The default path (broad phase, Bullet only for the open parts, best-first
least-bad search) must give the same answers on every point: status, reason, branch, rotation,
joints, clearance pair and clearance.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest
import trimesh

from calib.frames import make_transform, matrix_from_rotvec
from planner.cell.cell import Cell
from planner.cell.probe.probe_rule import CLEARANCE_TIE_M, least_bad, select
from planner.cell.probe.reachability import sample_surface
from planner.cell.scene.clearance import Clearance
from tests.cells import add_box_on_table


def cl(slack: float, margin: float = 0.005) -> Clearance:
    return Clearance(slack >= 0, slack + margin, slack, ("a", "b") if slack < 0.01 else None)


def test_the_first_passing_candidate_in_order_is_chosen() -> None:
    slacks = {0: -0.01, 1: 0.002, 2: 0.008, 3: 0.01}
    order, near = np.array([0, 1, 2, 3]), np.zeros(4, bool)
    d = select(order, near, 0.005, lambda c: cl(slacks[c]))
    assert (d.candidate, d.chosen) == (2, True)
    near[2] = True  # near a joint limit: it cannot be chosen outright
    d = select(order, near, 0.005, lambda c: cl(slacks[c]))
    assert (d.candidate, d.chosen) == (3, True)


def test_the_least_bad_is_the_largest_slack_ties_to_the_earliest() -> None:
    tie = CLEARANCE_TIE_M
    seen = [(7, cl(-0.02)), (3, cl(-0.01)), (5, cl(-0.01 + 0.9 * tie)), (1, cl(-0.01 + 1.5 * tie))]
    d = least_bad(seen)
    assert d.candidate == 5 and not d.chosen  # within the tie of the largest, and earlier
    assert least_bad([(2, cl(0.001)), (4, cl(0.003))]).chosen  # no collision: marginal


@pytest.fixture(scope="module")
def cell() -> Iterator[Cell]:
    """A dense box on a table, a post beside it: probe poses near the table, the post, the
    part's edges and the robot's own links."""
    with Cell(use_acl_cache=False) as c:
        add_box_on_table(c, 0.02, (1.05, -0.2, 0.75))
        yield c


def same(a, b) -> bool:  # type: ignore[no-untyped-def]
    if (a.status, a.reason, a.branch, a.clearance_pair) != (
        b.status,
        b.reason,
        b.branch,
        b.clearance_pair,
    ):
        return False
    if a.q is None or b.q is None:
        return a.q is None and b.q is None
    return (
        np.array_equal(a.q, b.q)
        and a.rotation_rad == b.rotation_rad
        and abs(a.clearance_m - b.clearance_m) <= 1e-6
    )


@pytest.mark.slow
def test_the_default_path_answers_as_the_exact_check(cell: Cell) -> None:
    rng = np.random.default_rng(3)
    pts, nrm, _ = sample_surface(cell.work_object.mesh, 500, rng)
    # and points pushed along their normal: probe poses nearer than the sensing distance
    pts[250:] += nrm[250:] * rng.uniform(-0.012, 0.0, size=(250, 1))
    fast = cell.check_probes(pts, nrm)
    exact = cell.check_probes(pts, nrm, staged=False)
    bad = [i for i, (a, b) in enumerate(zip(fast, exact)) if not same(a, b)]
    assert bad == []
    statuses = {r.status for r in exact}
    reasons = " ".join(r.reason for r in exact)
    assert statuses == {"feasible", "marginal", "infeasible"}
    for word in ("hits table", "hits part", "at limit", "near its"):
        assert word in reasons  # the sample covers collisions, limits and marginal poses
    one_by_one = [cell.check_probes(pts[i : i + 1], nrm[i : i + 1])[0] for i in range(0, 500, 25)]
    assert all(same(a, b) for a, b in zip(one_by_one, exact[::25]))


def test_a_moved_part_is_checked_where_it_lies(cell: Cell) -> None:
    rng = np.random.default_rng(4)
    pts, nrm, _ = sample_surface(cell.work_object.mesh, 60, rng)
    T0 = cell.T_world_wobj
    try:
        shift = make_transform(matrix_from_rotvec([0, 0, 0.1]), [-0.05, 0.02, 0.01])
        cell.move_work_object(T0 @ shift)
        fast = cell.check_probes(pts, nrm)
        exact = cell.check_probes(pts, nrm, staged=False)
    finally:
        cell.move_work_object(T0)
    assert all(same(a, b) for a, b in zip(fast, exact))


@pytest.mark.slow
def test_self_collision_near_misses_answer_as_the_exact_check() -> None:
    """On the benchmark's box, the points whose answer is the forearm near the tool mount (the
    self part decides them) and a random share of the rest, to the last bit of the clearance's
    Bullet value where the exact check computes it the same way."""
    from bench.feasibility_cell import bench_cell

    with bench_cell(trimesh.creation.box([0.8, 0.6, 0.4]).subdivide_to_size(0.03)) as c:
        pts, nrm, _ = sample_surface(c.work_object.mesh, 3000, np.random.default_rng(0))
        fast = c.check_probes(pts, nrm)
        near = [i for i, r in enumerate(fast) if "tool_mount" in r.reason]
        idx = sorted(set(near) | set(range(0, 3000, 20)))
        exact = c.check_probes(pts[idx], nrm[idx], staged=False)
    assert len(near) >= 5
    assert all(same(fast[i], e) for i, e in zip(idx, exact))
    assert all(fast[i].clearance_m == e.clearance_m for i, e in zip(idx, exact) if i in near)


@pytest.mark.slow
def test_points_near_the_table_answer_as_the_exact_check() -> None:
    """600 points on the lowest 8 cm of the benchmark box's sides, half of them pushed up to
    12 mm into the part: the tool meets the table at every depth, so the least-bad search runs
    on penetration bounds (:mod:`planner.cell.broad.slack_bounds`) for most of them."""
    from bench.feasibility_cell import bench_cell

    rng = np.random.default_rng(8)
    with bench_cell(trimesh.creation.box([0.8, 0.6, 0.4]).subdivide_to_size(0.03)) as c:
        pts, nrm, _ = sample_surface(c.work_object.mesh, 6_000, rng)
        low = np.flatnonzero((pts[:, 2] < -0.12) & (np.abs(nrm[:, 2]) < 0.5))[:600]
        pts, nrm = pts[low], nrm[low]
        pts[::2] += nrm[::2] * rng.uniform(-0.012, 0.0, size=(len(pts[::2]), 1))
        fast = c.check_probes(pts, nrm)
        exact = c.check_probes(pts, nrm, staged=False)
    assert len(pts) == 600
    assert [i for i, (a, b) in enumerate(zip(fast, exact)) if not same(a, b)] == []
    hits_table = sum("hits table" in r.reason for r in exact)
    assert hits_table >= 40, hits_table


def test_points_that_wait_for_more_rows_answer_as_one_by_one(
    cell: Cell, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With a first block of one candidate, most searched points stop for more broad-phase
    rows and go on after one batched call, each with its own cached part results: the same
    answers as each point checked alone (where nothing waits)."""
    import planner.cell.probe.probe_choice as probe_choice

    rng = np.random.default_rng(5)
    pts, nrm, _ = sample_surface(cell.work_object.mesh, 120, rng)
    pts[60:] += nrm[60:] * rng.uniform(-0.012, 0.0, size=(60, 1))
    monkeypatch.setattr(probe_choice, "FIRST_BLOCK", 1)
    batch = cell.check_probes(pts, nrm)
    alone = [cell.check_probes(pts[i : i + 1], nrm[i : i + 1])[0] for i in range(120)]
    assert all(same(a, b) for a, b in zip(batch, alone))
