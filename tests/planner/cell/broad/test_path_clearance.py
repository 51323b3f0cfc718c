"""planner.cell.broad.path_clearance: the verdict and the clearances of a sampled path, broad phase
first, against the plain loop of whole clearance queries (the same failing sample, the same
reason, the same clearance at every sample)."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace

import numpy as np
import pytest
import trimesh

from calib.frames import make_transform
from calib.probing import ProbePoint, SearchCommand, SearchSpec
from planner.cell.broad.path_clearance import first_failure, path_clearances
from planner.cell.cell import Cell

BOX = 0.4
X0 = 1.6
T_WORLD_WOBJ = make_transform(p=[X0, 0.0, 0.4])  # top face at world z = 0.6
TOP = ProbePoint("A", (0.0, 0.0, BOX / 2), (0.0, 0.0, 1.0), SearchSpec("approach", 0.05, 0.03))
FRONT = ProbePoint(
    "F",
    (-BOX / 2, 0.0, BOX / 2 - 0.03),
    (-1.0, 0.0, 0.0),
    SearchSpec("edge", 0.05, 0.02, edge_direction=(0.0, 0.0, 1.0)),
    edge_normal=(0.0, 0.0, 1.0),
)


@pytest.fixture(scope="module")
def cell() -> Iterator[Cell]:
    with Cell(use_acl_cache=False) as c:
        c.set_work_object(trimesh.creation.box([BOX] * 3), "m", T_WORLD_WOBJ, name="box")
        c.add_fixture(
            "clamp",
            size_m=(0.05, 0.05, 0.02),
            T_world_fixture=make_transform(p=[X0 + 0.1, 0.1, 0.61]),
        )
        yield c


def _loop(
    cell: Cell, q_path: np.ndarray, skip: np.ndarray, margin: float
) -> tuple[int, str | None]:
    for j, q in enumerate(q_path):
        cell.set_joint_positions(q)
        cl = cell.clearance(margin, sensor_wobj_allowed=True, skip_wobj=bool(skip[j]))
        if not cl.ok:
            return j, cl.describe()
    return len(q_path), None


def test_configurations_near_the_part_fail_where_the_loop_fails(cell: Cell) -> None:
    """The joint values of a search over the box, jittered by a few degrees to a fraction of
    a radian (the tool into the box and the clamp, near misses, clear poses), in blocks of 8:
    the first failing sample and its reason are the loop's."""
    rng = np.random.default_rng(3)
    base = cell.check_search(SearchCommand.from_point(TOP, cell.T_base_wobj)).q_path
    seen_fail = seen_pass = 0
    with cell.saved_state():
        for n in range(48):
            q = base[rng.integers(len(base), size=8)]
            q = q + rng.normal(0.0, 0.02 + 0.3 * (n % 4) / 3, size=q.shape)
            q = np.clip(q, cell.chain.lower, cell.chain.upper)
            skip = rng.random(8) < 0.3
            j, cl = first_failure(cell, q, cell.chain.fk(q), skip, 0.005)
            want_j, want = _loop(cell, q, skip, 0.005)
            assert (j, None if cl is None else cl.describe()) == (want_j, want)
            seen_fail += want is not None
            seen_pass += want is None
    assert seen_fail >= 10 and seen_pass >= 5  # both kinds of answer were compared


def test_every_sample_has_the_clearance_of_the_whole_query(cell: Cell) -> None:
    """The same jittered blocks: each sample's clearance, limiting pair and verdict are the
    whole query's, bit for bit, up to and including the first that fails (none after it)."""
    rng = np.random.default_rng(4)
    base = cell.check_search(SearchCommand.from_point(TOP, cell.T_base_wobj)).q_path
    seen_fail = seen_near = 0
    with cell.saved_state():
        for n in range(49):
            if n == 48:  # the search itself: it passes, near the part all along
                q, skip = base, np.zeros(len(base), dtype=bool)
            else:
                q = base[rng.integers(len(base), size=8)]
                q = q + rng.normal(0.0, 0.02 + 0.3 * (n % 4) / 3, size=q.shape)
                q = np.clip(q, cell.chain.lower, cell.chain.upper)
                skip = rng.random(8) < 0.3
            got = path_clearances(cell, q, cell.chain.fk(q), skip, 0.005)
            want = []
            for j in range(len(q)):
                cell.set_joint_positions(q[j])
                want.append(
                    cell.clearance(0.005, sensor_wobj_allowed=True, skip_wobj=bool(skip[j]))
                )
                if not want[-1].ok:
                    break
            assert got == want
            seen_fail += not want[-1].ok
            seen_near += sum(w.pair is not None and w.ok for w in want)
    assert seen_fail >= 10 and seen_near >= 5  # failures and passing near misses compared


def test_searches_give_the_same_verdict_with_and_without_the_clearances(cell: Cell) -> None:
    """Approaches and edge searches over the box, some into the clamp: the verdict-only check
    (``exact_clearance=False``) gives the exact check's answer, sample for sample."""
    rng = np.random.default_rng(5)
    T = cell.T_base_wobj
    n_failed = 0
    for _ in range(24):
        shift = np.array([rng.uniform(-0.15, 0.15), rng.uniform(-0.15, 0.15), 0.0])
        top = replace(TOP, position_m=tuple(np.add(TOP.position_m, shift)))
        front = replace(FRONT, position_m=tuple(np.add(FRONT.position_m, [0.0, shift[1], 0.0])))
        for point in (top, front):
            cmd = SearchCommand.from_point(point, T)
            exact = cell.check_search(cmd)
            fast = cell.check_search(cmd, exact_clearance=False)
            assert (fast.feasible, fast.reason, fast.branch) == (
                exact.feasible,
                exact.reason,
                exact.branch,
            )
            assert np.array_equal(fast.fail_at_m, exact.fail_at_m, equal_nan=True)
            assert np.array_equal(fast.q_path, exact.q_path)
            assert np.isnan(fast.min_clearance_m)
            n_failed += not exact.feasible
    assert n_failed >= 3  # the clamp stops some
