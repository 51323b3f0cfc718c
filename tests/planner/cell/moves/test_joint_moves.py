"""planner.cell.moves.joint_moves: a joint move's first colliding pose and its reason are those of
the plain loop of whole clearance queries (the broad phase clears most of each pose's parts)."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest
import trimesh

from calib.frames import make_transform
from calib.probing import ProbePoint, SearchCommand, SearchSpec
from planner.cell.cell import Cell
from planner.cell.moves.joint_moves import check_joint_move, move_steps
from planner.reasons import Reason

BOX = 0.4
X0 = 1.6


@pytest.fixture(scope="module")
def cell() -> Iterator[Cell]:
    """The built-in robot and tool, a 400 mm box in front of it and a clamp on the box."""
    with Cell(use_acl_cache=False) as c:
        c.set_work_object(
            trimesh.creation.box([BOX] * 3), "m", make_transform(p=[X0, 0.0, 0.4]), name="box"
        )
        c.add_fixture(
            "clamp",
            size_m=(0.05, 0.05, 0.02),
            T_world_fixture=make_transform(p=[X0 + 0.1, 0.1, 0.61]),
        )
        yield c


def _loop(cell: Cell, q_from: np.ndarray, q_to: np.ndarray) -> Reason | None:
    """What the move check said before the broad phase: each pose's whole query in turn."""
    steps = move_steps(q_from, q_to)
    qs = q_from + np.linspace(0.0, 1.0, steps)[:, None] * (q_to - q_from)
    with cell.saved_state():
        for k, q in enumerate(qs):
            cell.set_joint_positions(q)
            c = cell.clearance()
            if not c.ok:
                return c.reason(f"at {100 * k // (steps - 1)} %: ", kind="move")
    return None


def test_moves_through_the_box_and_past_it_fail_where_the_loop_fails(cell: Cell) -> None:
    """Seeded moves between poses around the box (some through it, some past the clamp, some
    clear; self-collisions of wide swings too): the same first failing pose and words, and the
    TCP path the Teach tab draws."""
    rng = np.random.default_rng(8)
    lo, hi = cell.chain.lower, cell.chain.upper
    home = cell.home_q
    top = ProbePoint("A", (0.0, 0.0, BOX / 2), (0.0, 0.0, 1.0), SearchSpec("approach", 0.05, 0.03))
    on_box = cell.check_search(SearchCommand.from_point(top, cell.T_base_wobj)).q_path[-1]
    failed = passed = 0
    for n in range(40):
        spread = 0.2 + 1.2 * (n % 4) / 3
        a = np.clip(home + rng.normal(0.0, spread, home.size), lo, hi)
        near = on_box if n % 2 else home  # half of them end at the box's top, jittered
        b = np.clip(near + rng.normal(0.0, 0.3 * spread, home.size), lo, hi)
        got = check_joint_move(cell, a, b, "sensor")
        assert got.cause == _loop(cell, a, b)  # words, kind and clearance pair
        steps = move_steps(a, b)
        qs = a + np.linspace(0.0, 1.0, steps)[:, None] * (b - a)
        T = cell.T_world_base @ np.asarray(cell.chain.fk(qs)) @ cell.T_flange_tcp("sensor")
        assert np.array_equal(got.tcp_path_world, T[:, :3, 3])
        failed += bool(got.problem)
        passed += not got.problem
    assert failed >= 8 and passed >= 8  # both kinds of answer were compared
