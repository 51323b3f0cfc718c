"""The broad phase against Bullet, part by part and pair by pair, on thousands of configurations.

A part called clear (state 1) must report nothing in Bullet's query; a part called below the
margin (state -1) must have a Bullet slack below the margin. The configurations are random
joint values and the IK solutions of probe poses all over a dense box (the tool at the sensing
distance from the surface: near contact by construction), in a cell with a table, a cylinder
and a mesh fixture.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest
import trimesh

from calib.frames import make_transform
from planner.cell.broad.broad_phase import broad_phase_of
from planner.cell.cell import Cell
from planner.cell.probe.feasibility import tcp_frames
from planner.cell.probe.reachability import sample_surface
from planner.cell.scene.collision import DEFAULT_MARGIN_M
from planner.cell.scene.pybullet_client import pb
from tests.cells import add_box_on_table

MARGIN = DEFAULT_MARGIN_M


@pytest.fixture(scope="module")
def cell() -> Iterator[Cell]:
    with Cell(use_acl_cache=False) as c:
        add_box_on_table(c, 0.03, (1.0, -0.45, 0.55))
        ball = trimesh.creation.icosphere(subdivisions=2, radius=0.08)
        c.add_fixture(
            "ball", mesh=ball, units="m", T_world_fixture=make_transform(p=[1.0, 0.45, 0.75])
        )
        yield c


def configurations(cell: Cell, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """``(q (M, n), T_base_flange (M, 4, 4))``: random joint values, and IK solutions of
    probe poses on the part, the sensor TCP from 12 mm inside to 2 mm outside the surface
    (the sensor from 4 mm into the part to 10 mm off it)."""
    lo, hi = cell.chain.lower, cell.chain.upper
    q_rand = rng.uniform(lo, hi, size=(700, lo.size))
    mesh = cell.work_object.mesh
    pts, nrm, _ = sample_surface(mesh, 250, rng)
    pts = pts + nrm * rng.uniform(-0.012, 0.002, size=(len(pts), 1))
    T = cell.T_base_wobj @ tcp_frames(pts, nrm, np.radians(np.arange(0, 360, 30)))
    T_bf = (T @ np.linalg.inv(cell.T_flange_tcp("sensor"))).reshape(-1, 4, 4)
    sol = cell.solver.solve(T_bf)
    q_probe = sol.q[sol.valid]
    pick = rng.choice(len(q_probe), size=min(1300, len(q_probe)), replace=False)
    q = np.concatenate([q_rand, q_probe[pick]])
    return q, cell.chain.fk(q)


@pytest.mark.slow
def test_clear_and_below_margin_parts_agree_with_bullet(cell: Cell) -> None:
    rng = np.random.default_rng(5)
    q, T_bf = configurations(cell, rng)
    broad = broad_phase_of(cell)
    plan = cell.checker.plan(MARGIN, cell.self_margin_m, None, True, False)
    env = broad.environment(cell)
    parts = broad.part_map(cell, plan, env)
    states, pair_states, _ = broad.states(parts, env, broad.link_poses(cell, q, T_bf))
    env_parts = [plan.parts[int(i)] for i in parts.part_index]
    bodies, links, pa, pb_ = cell.checker._self_pair_table()
    look = plan.parts[-1].dist_m
    reported = decided = total = 0
    near = set()  # configurations where Bullet reports a part or a pair
    with cell.saved_state():
        for m in range(len(q)):
            cell.set_joint_positions(q[m])
            for k, part in enumerate(env_parts):
                res = cell.checker.evaluate(part)
                total += 1
                reported += res is not None
                if res is not None:
                    near.add(m)
                decided += states[m, k] != 0
                if states[m, k] == 1:
                    assert res is None, (m, part, res)
                elif states[m, k] == -1:
                    assert res is not None and res.slack_m < MARGIN, (m, part, res)
            for s in range(pa.size):
                a, b = int(pa[s]), int(pb_[s])
                pts = pb.getClosestPoints(
                    bodies[a], bodies[b], look, linkIndexA=links[a], linkIndexB=links[b],
                    physicsClientId=cell.client,
                )  # fmt: skip
                d = min((p[8] for p in pts), default=np.inf)
                if pts:
                    near.add(m)
                if pair_states[m, s] == 1:
                    assert not pts, (m, s, d)
                elif pair_states[m, s] == -1:
                    assert d - cell.self_margin_m < MARGIN, (m, s, d)
    assert len(q) >= 1800
    assert len(near) >= 500  # near contact is well represented
    assert decided > 0.95 * total  # and the broad phase decides almost every part


def test_a_moved_part_moves_its_field(cell: Cell) -> None:
    """The environment is read at every query: after moving the work object the states follow
    it (a part call clear before would now be reported by Bullet, and is not called clear)."""
    rng = np.random.default_rng(6)
    q, T_bf = configurations(cell, rng)
    q, T_bf = q[700:900], T_bf[700:900]  # near the part's surface
    broad = broad_phase_of(cell)
    plan = cell.checker.plan(MARGIN, cell.self_margin_m, None, True, False)
    T0 = cell.T_world_wobj
    try:
        cell.move_work_object(T0 @ make_transform(p=[0.0, 0.0, 0.03]))
        env = broad.environment(cell)
        parts = broad.part_map(cell, plan, env)
        states, _, _ = broad.states(parts, env, broad.link_poses(cell, q, T_bf))
        env_parts = [plan.parts[int(i)] for i in parts.part_index]
        with cell.saved_state():
            for m in range(len(q)):
                cell.set_joint_positions(q[m])
                for k, part in enumerate(env_parts):
                    if states[m, k] == 1:
                        assert cell.checker.evaluate(part) is None
    finally:
        cell.move_work_object(T0)
