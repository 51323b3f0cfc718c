"""Tests of planner.cell.probe.probe_clearance: the query part by part against the whole query."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest
import trimesh

from calib.frames import make_transform
from planner.cell.cell import Cell
from planner.cell.probe.probe_clearance import ProbeClearance
from planner.cell.scene.clearance import Clearance
from planner.cell.scene.collision import DEFAULT_MARGIN_M
from planner.cell.scene.pybullet_client import pb

MARGIN = DEFAULT_MARGIN_M


@pytest.fixture(scope="module")
def cell() -> Iterator[Cell]:
    """A box the arm reaches into from many poses, and a plate over it."""
    with Cell(use_acl_cache=False) as c:
        c.set_work_object(
            trimesh.creation.box([0.5, 0.8, 0.6]), "m", make_transform(p=[1.1, 0, 0.5])
        )
        c.add_fixture(
            "plate", size_m=(0.8, 0.8, 0.02), T_world_fixture=make_transform(p=[1.1, 0, 1.3])
        )
        yield c


def configurations(cell: Cell, n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    lo, hi = cell.chain.lower, cell.chain.upper
    return rng.uniform(np.maximum(lo, -2.0), np.minimum(hi, 2.0), size=(n, lo.size))


def whole(cell: Cell, q: np.ndarray) -> Clearance:
    """The naive query: robot and tool each as one body against each environment body (as
    before the query was split into parts), the self part as in the checker."""
    ch = cell.checker
    plan = ch.plan(MARGIN, cell.self_margin_m)
    look = plan.look_m
    best = Clearance(True, look, look - MARGIN, None)
    with cell.saved_state():
        cell.set_joint_positions(q)
        for env, env_name in ch.environment.items():
            for body in (cell.robot.body_id, cell.tool_body.body_id):
                for pt in pb.getClosestPoints(body, env, look, physicsClientId=cell.client):
                    link = pt[3]
                    if body == cell.robot.body_id and link in ch.static_links:
                        continue
                    sensor = body != cell.robot.body_id and link in ch.sensor_links
                    need = 0.0 if sensor and env == ch.wobj_body else MARGIN
                    if sensor and env == ch.wobj_body and pt[8] > MARGIN:
                        continue  # the sensor looks only margin_m far at the work object
                    if pt[8] - need < best.slack_m:
                        pair = (ch.names(body, link), env_name)
                        best = Clearance(pt[8] >= need, pt[8], pt[8] - need, pair)
        own = ch.evaluate(plan.parts[-1])
        if own is not None and own.slack_m < best.slack_m:
            best = own
    if best.pair is not None and best.slack_m >= 0:
        best = Clearance(True, best.clearance_m, best.slack_m, best.pair)
    return best


def assert_same(a: Clearance, b: Clearance) -> None:
    assert (a.ok, a.pair) == (b.ok, b.pair)
    # the staged query puts the tool at the planned flange pose, PyBullet's FK within ~1e-7 m
    assert a.clearance_m == pytest.approx(b.clearance_m, abs=1e-6)
    assert a.slack_m == pytest.approx(b.slack_m, abs=1e-6)


def all_parts(cell: Cell, stages: ProbeClearance, rotation: int, q: np.ndarray) -> Clearance:
    """Every part of the query evaluated by ``stages`` and merged."""
    results = {p.index: stages.evaluate(rotation, q, p) for p in stages.plan.parts}
    return stages.merge(results)


def test_the_parts_merged_are_the_whole_query(cell: Cell) -> None:
    qs = configurations(cell, 40, seed=1)
    stages = ProbeClearance(cell, MARGIN)
    stages.start_point(cell.chain.fk(qs))
    with cell.saved_state():
        got = [all_parts(cell, stages, r, q) for r, q in enumerate(qs)]
    expected = [whole(cell, q) for q in qs]
    assert sum(not e.ok for e in expected) >= 5  # the sample holds real collisions
    assert {e.pair[1] for e in expected if e.pair and not e.ok} >= {"plate", "work object"}
    for g, e, q in zip(got, expected, qs):
        assert_same(g, e)
        assert_same(whole_query(cell, q), e)  # the query made of parts, too


def whole_query(cell: Cell, q: np.ndarray) -> Clearance:
    with cell.saved_state():
        cell.set_joint_positions(q)
        return cell.clearance(MARGIN, sensor_wobj_allowed=True)


def test_a_subset_of_self_pairs_reports_the_nearest_of_them(cell: Cell) -> None:
    """The self part over a mask of pairs: all pairs give the whole self part, none give
    nothing, and the limiting pair alone gives the whole part's answer."""
    rng = np.random.default_rng(2)
    lo, hi = cell.chain.lower, cell.chain.upper
    part = cell.checker.plan(MARGIN, cell.self_margin_m).parts[-1]
    bodies, links, pa, pb_ = cell.checker._self_pair_table()
    names = [
        {cell.checker.names(bodies[a], links[a]), cell.checker.names(bodies[b], links[b])}
        for a, b in zip(pa.tolist(), pb_.tolist())
    ]
    near_seen = 0
    with cell.saved_state():
        for q in rng.uniform(lo, hi, size=(400, lo.size)):
            cell.set_joint_positions(q)
            full = cell.checker.evaluate(part)
            assert cell.checker.evaluate(part, np.ones(pa.size, bool)) == full
            assert cell.checker.evaluate(part, np.zeros(pa.size, bool)) is None
            if full is not None:
                near_seen += 1
                mask = np.array([n == set(full.pair) for n in names])
                assert cell.checker.evaluate(part, mask) == full
    assert near_seen >= 10


def test_certificates_never_claim_a_deeper_collision_than_the_full_part(cell: Cell) -> None:
    qs = configurations(cell, 30, seed=3)
    plan = cell.checker.plan(MARGIN, cell.self_margin_m)
    certified = 0
    with cell.saved_state():
        for q in qs:
            cell.set_joint_positions(q)
            for part in plan.parts:
                full = cell.checker.evaluate(part)
                slack = np.inf if full is None else full.slack_m
                # just above the full result: a certificate must not go below it
                assert not cell.checker.certify_below(part, slack - 1e-4)
                assert cell.checker.evaluate_capped(part, slack - 1e-4) is None
                if full is not None and part.kind != "self" and slack < -0.01:
                    hit = cell.checker.certify_below(part, slack + 1e-4)
                    assert hit == (part.env_name == "work object")  # only the concave mesh
                    certified += hit
                    if hit:  # the capped query's deepest point is the full query's, bit for bit
                        assert cell.checker.evaluate_capped(part, slack + 1e-4) == full
                        assert cell.checker.evaluate_capped(part, slack) == full
    assert certified >= 3  # and deep collisions with the work object do get certified


def test_the_tool_is_checked_once_per_rotation(cell: Cell, monkeypatch) -> None:
    """Two IK branches of the same flange pose share the tool parts' results, and a 2 pi
    variant of the last joint shares every robot link before it."""
    T = cell.chain.fk(np.array([[0.2, 0.3, 0.1, 0.4, 0.8, 0.3]]))
    sol = cell.solver.solve(T)
    qs = sol.q[0][sol.valid[0]]
    q_a = qs[0]
    q_b = qs[np.argmax(np.abs(qs[:, :4] - q_a[:4]).max(axis=1))]  # another branch
    assert np.abs(q_b[:4] - q_a[:4]).max() > 0.1
    kinds: list[str] = []
    evaluate = cell.checker.evaluate
    monkeypatch.setattr(
        cell.checker, "evaluate", lambda p, pairs=None: kinds.append(p.kind) or evaluate(p, pairs)
    )
    stages = ProbeClearance(cell, MARGIN)
    stages.start_point(T)
    with cell.saved_state():
        all_parts(cell, stages, 0, q_a)
        first = list(kinds)
        all_parts(cell, stages, 0, q_b)
        second = kinds[len(first) :]
        q_c = q_a.copy()
        q_c[5] += 2 * np.pi if q_c[5] < 0 else -2 * np.pi
        all_parts(cell, stages, 0, q_c)
        third = kinds[len(first) + len(second) :]
    assert first.count("tool") == 2 * len(cell.checker._tool_links())  # work object, plate
    assert "tool" not in second and "robot" in second and "self" in second
    assert third == ["self"]  # every robot link and the tool as before
