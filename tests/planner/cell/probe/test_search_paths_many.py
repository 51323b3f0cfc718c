"""Tests of planner.cell.probe.search_paths_many: many searches checked at once give, search by
search, what check_search gives with the same pose: clear ones, one into a clamp, one with an
unreachable start, one leaving the workspace, a branch the start lacks and one of any branch."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import replace

import numpy as np
import pytest
import trimesh

from calib.frames import make_transform
from calib.probing import ProbePoint, SearchCommand, SearchSpec
from planner.cell.cell import Cell
from planner.cell.probe import PathFeasibility, search_paths_many

BOX = 0.4
X0 = 1.6
T_WORLD_WOBJ = make_transform(p=[X0, 0.0, 0.4])  # top face at world z = 0.6
STEP_M = 0.002  # the vetting's step


@pytest.fixture(scope="module")
def cell() -> Iterator[Cell]:
    with Cell(use_acl_cache=False) as c:
        c.set_work_object(trimesh.creation.box([BOX] * 3), "m", T_WORLD_WOBJ, name="box")
        # a 20 mm clamp on the top face, under the approaches at wobj x = 0.1
        c.add_fixture(
            "clamp",
            size_m=(0.05, 0.05, 0.02),
            T_world_fixture=make_transform(p=[X0 + 0.1, 0.0, 0.61]),
        )
        yield c


def _commands(cell: Cell) -> list[SearchCommand]:
    T = cell.T_base_wobj
    out = []
    for x in (-0.15, -0.05, 0.05, 0.1, 0.15):
        for y in (-0.1, 0.0, 0.12):
            p = ProbePoint(
                f"t{x:+.2f}{y:+.2f}", (x, y, BOX / 2), (0.0, 0.0, 1.0), SearchSpec("approach")
            )
            out.append(SearchCommand.from_point(p, T))
    edge = ProbePoint(
        "F",
        (-BOX / 2, 0.0, BOX / 2),
        (-1.0, 0.0, 0.0),
        SearchSpec("edge", 0.05, 0.02, edge_direction=(0.0, 0.0, 1.0)),
        edge_normal=(0.0, 0.0, 1.0),
    )
    out.append(SearchCommand.from_point(edge, T))
    shift = np.array([5.0, 0.0, 0.0])  # its start is out of reach
    out.append(replace(out[0], start_m=out[0].start_m + shift, nominal_m=out[0].nominal_m + shift))
    away = replace(out[1], kind="edge", direction=np.array([1.0, 0.0, 0.0]), length_m=0.4)
    out.append(away)  # leaves the workspace midway
    return out


def _poses(cell: Cell, cmds: list[SearchCommand]) -> tuple[list, list, list]:
    """Each search's pose as check chose one: the free check's start, rotated 10 deg."""
    xs, qs, branches = [], [], []
    for c in cmds:
        free = cell.check_search(c, step_m=STEP_M, max_starts=1, exact_clearance=False)
        T0 = np.eye(3)
        if free.q_path.shape[0]:
            T0 = (cell.chain.fk(free.q_path[:1]) @ cell.T_flange_tcp("sensor"))[0, :3, :3]
            q = free.q_path[0]
        else:
            q = cell.home_q
        turn = math.radians(10.0)
        x = math.cos(turn) * T0[:, 0] + math.sin(turn) * T0[:, 1]
        xs.append(x)
        qs.append(q)
        branches.append(free.branch if free.branch >= 0 else 0)
    return xs, qs, branches


def _same(a: PathFeasibility, b: PathFeasibility) -> None:
    assert a.feasible == b.feasible
    assert a.cause == b.cause and a.reason == b.reason
    assert (math.isnan(a.fail_at_m) and math.isnan(b.fail_at_m)) or a.fail_at_m == b.fail_at_m
    assert np.array_equal(a.s_m, b.s_m)
    assert np.array_equal(a.q_path, b.q_path)
    assert np.array_equal([a.rotation_rad], [b.rotation_rad], equal_nan=True)
    assert a.branch == b.branch
    assert math.isnan(a.min_clearance_m) and math.isnan(b.min_clearance_m)


def test_many_searches_at_once_are_each_search_checked_alone(
    cell: Cell, monkeypatch: pytest.MonkeyPatch
) -> None:
    cmds = _commands(cell)
    xs, qs, branches = _poses(cell, cmds)
    branches[2] = 99  # a branch no start has: check_search words why
    branches[4] = -1  # any branch: checked alone
    q_before = cell.joint_positions.copy()
    alone: list[str] = []
    one_by_one = search_paths_many.check_search

    def counted(cell: Cell, command: SearchCommand, **kw: object) -> PathFeasibility:
        alone.append(command.point_id)
        return one_by_one(cell, command, **kw)  # type: ignore[arg-type]

    monkeypatch.setattr(search_paths_many, "check_search", counted)
    got = cell.check_searches(cmds, xs, qs, branches, step_m=STEP_M)
    monkeypatch.undo()
    # only the three that need it are checked alone: any branch, branch 99, no start
    assert sorted(alone) == sorted([cmds[2].point_id, cmds[4].point_id, cmds[-2].point_id])
    assert np.array_equal(cell.joint_positions, q_before)  # the joints are put back
    expected = [
        cell.check_search(
            c,
            step_m=STEP_M,
            q_ref=q,
            sensor_x=x,
            branch=b,
            max_starts=1,
            exact_clearance=False,
        )
        for c, x, q, b in zip(cmds, xs, qs, branches, strict=True)
    ]
    assert len(got) == len(expected)
    for a, b in zip(got, expected, strict=True):
        _same(a, b)
    # the cases the test is for: clear paths, the clamp, the start, the workspace, the branch
    reasons = [r.reason for r in expected]
    assert sum(r.feasible for r in expected) >= 8
    assert any("clamp" in r for r in reasons)
    assert any(r.startswith("at 0.0 mm: out of reach") for r in reasons)
    assert any("no solution on IK branch 99" in r for r in reasons)
    assert not expected[-1].feasible and expected[-1].fail_at_m > 0.05


def test_no_searches_and_bad_commands(cell: Cell) -> None:
    assert cell.check_searches([], [], [], []) == []
    cmd = _commands(cell)[0]
    with pytest.raises(ValueError):
        cell.check_searches([cmd], [np.ones(3)], [], [0])  # the lists must match
