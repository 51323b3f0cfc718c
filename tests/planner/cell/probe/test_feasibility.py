"""Tests of planner.cell.probe.feasibility against known geometry: boxes, a blocking plate, a
slot."""

from __future__ import annotations

import re
from collections.abc import Iterator

import numpy as np
import pybullet_data
import pytest
import trimesh

from calib.errors import DegenerateGeometryError, NonFiniteError, ShapeError
from calib.frames import make_transform, matrix_from_rotvec
from planner.cell.cell import Cell
from planner.cell.probe.feasibility import tcp_frames
from planner.cell.scene.pybullet_client import pb
from planner.errors import UnknownFrameError

BOX = 0.4  # edge of the work-object cube, m
T_WORLD_WOBJ = make_transform(p=[1.4, 0.0, 0.4])  # top face at z = 0.6, 1.2 m in front
TOP = np.array([[0.0, 0.0, BOX / 2]])
UP = np.array([[0.0, 0.0, 1.0]])


@pytest.fixture(scope="module")
def cell() -> Iterator[Cell]:
    with Cell(use_acl_cache=False) as c:
        c.set_work_object(trimesh.creation.box([BOX] * 3), "m", T_WORLD_WOBJ, name="box")
        yield c


def test_probe_on_top_of_a_reachable_box_is_feasible(cell: Cell) -> None:
    (res,) = cell.check_probes(TOP, UP)
    assert res.feasible and res.status == "feasible" and res.reason == ""
    assert 0 <= res.branch < 8
    # the chosen joints put the sensor TCP on the point, its axis into the surface
    T_base_sensor = cell.chain.fk(res.q)[0] @ cell.T_flange_tcp("sensor")
    np.testing.assert_allclose(T_base_sensor[:3, 3], [1.4, 0.0, 0.6], atol=1e-6)
    np.testing.assert_allclose(T_base_sensor[:3, 2], [0.0, 0.0, -1.0], atol=1e-6)
    np.testing.assert_allclose(res.T_base_flange, cell.chain.fk(res.q)[0], atol=1e-6)
    # nothing within 2 x 5 mm margin + 5 mm (the sensor, which needs no margin, looks 5 mm)
    assert res.clearance_m == pytest.approx(0.015, abs=1e-6)
    assert res.joint_margin_rad > np.radians(5)


def test_the_same_point_under_a_plate_is_infeasible_naming_the_plate(cell: Cell) -> None:
    T_plate = make_transform(p=[1.4, 0.0, 0.6 + 0.10])  # 100 mm above the top face
    cell.add_fixture("plate", size_m=(0.6, 0.6, 0.01), T_world_fixture=T_plate)
    try:
        (res,) = cell.check_probes(TOP, UP)
    finally:
        cell.remove_fixture("plate")
    assert not res.feasible and res.status == "infeasible"
    assert "hits plate" in res.reason and "clearance" in res.reason
    assert res.clearance_m < 0.005


def test_a_point_5_m_away_is_out_of_reach(cell: Cell) -> None:
    (res,) = cell.check_probes([[5.0, 0.0, 0.0]], [[1.0, 0.0, 0.0]])
    assert not res.feasible
    m = re.fullmatch(
        r"out of reach \((\d+\.\d\d) m from the shoulder, reach (\d\.\d\d) m\)", res.reason
    )
    assert m is not None, res.reason
    # the TCP is at world (6.4, 0, 0.4), the flange ~0.35 m further out; shoulder at x = 0.2
    assert float(m.group(1)) == pytest.approx(6.55, abs=0.1)
    assert float(m.group(2)) == pytest.approx(cell.reach_model.reach_m, abs=0.005)
    assert res.q is None and np.isnan(res.rotation_rad)


def test_joint_limit_is_named(cell: Cell) -> None:
    """Probing the box's bottom face from below: within the arm's length, but not its limits."""
    point, normal = np.array([[0.0, 0.0, -BOX / 2]]), np.array([[0.0, 0.0, -1.0]])
    (res,) = cell.check_probes(point, normal)
    assert not res.feasible
    assert re.fullmatch(r"joint [1-6] at limit \(joint_[1-6]\)", res.reason), res.reason
    # independent check: the analytic IK reaches the poses if limits are ignored
    T = cell.T_base_wobj @ tcp_frames(point, normal, np.radians(np.arange(0, 360, 15)))[0]
    T_flange = T @ np.linalg.inv(cell.T_flange_tcp("sensor"))
    assert not cell.solver.solve(T_flange).valid.any()
    assert cell.solver.opw.ik_branches(T_flange)[1].any()


def test_small_clearance_is_marginal(cell: Cell) -> None:
    """A short post beside the sensor: 7 mm from the sensor body whatever the rotation."""
    T_post = make_transform(p=[1.4 + 0.009 + 0.007 + 0.010, 0.0, 0.6 + 0.0075])
    cell.add_fixture("post", radius_m=0.010, height_m=0.015, T_world_fixture=T_post)
    try:
        (res,) = cell.check_probes(TOP, UP, margin_m=0.005)
    finally:
        cell.remove_fixture("post")
    assert res.feasible and res.status == "marginal"
    assert "sensor_body is near post" in res.reason
    assert res.clearance_m == pytest.approx(0.007, abs=1e-4)


@pytest.mark.slow
def test_a_probe_into_a_slot_is_not_blocked_as_by_a_convex_hull() -> None:
    """A U-shaped block: the slot (40 mm wide, 15 mm deep) is open for the 18 mm sensor."""
    base = trimesh.creation.box([0.3, 0.3, 0.1])
    wall = trimesh.creation.box([0.13, 0.3, 0.015])
    left, right = wall.copy(), wall.copy()
    left.apply_translation([-0.02 - 0.065, 0.0, 0.05 + 0.0075])
    right.apply_translation([0.02 + 0.065, 0.0, 0.05 + 0.0075])
    slotted = trimesh.util.concatenate([base, left, right])
    bottom = np.array([[0.0, 0.0, 0.05]])
    with Cell(use_acl_cache=False) as c:
        c.set_work_object(slotted, "m", T_WORLD_WOBJ, name="slotted")
        (open_slot,) = c.check_probes(bottom, UP)
        c.set_work_object(slotted.convex_hull, "m", T_WORLD_WOBJ, name="hull")
        (filled,) = c.check_probes(bottom, UP)
    assert open_slot.feasible, open_slot.reason
    assert not filled.feasible
    assert "sensor_body hits hull" in filled.reason


def test_batch_answers_match_single_queries(cell: Cell) -> None:
    pts = np.array([[0.0, 0.0, BOX / 2], [0.1, -0.1, BOX / 2], [-BOX / 2, 0.05, 0.0]])
    nrm = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]])
    batch = cell.check_probes(pts, nrm)
    for i, b in enumerate(batch):
        (one,) = cell.check_probes(pts[i : i + 1], nrm[i : i + 1])
        assert (one.status, one.reason, one.rotation_rad) == (b.status, b.reason, b.rotation_rad)
        np.testing.assert_allclose(one.q, b.q)
    assert batch[2].feasible  # the near side face looks at the robot


def test_bad_input(cell: Cell) -> None:
    with pytest.raises(NonFiniteError, match="points_wobj"):
        cell.check_probes([[0.0, np.nan, 0.2]], UP)
    with pytest.raises(NonFiniteError, match="normals_wobj"):
        cell.check_probes(TOP, [[0.0, 0.0, np.inf]])
    with pytest.raises(ShapeError, match="normals_wobj"):
        cell.check_probes(TOP, [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    with pytest.raises(ShapeError, match=r"points_wobj must be \(N, 3\)"):
        cell.check_probes([0.0, 0.0, 0.2], UP)
    with pytest.raises(DegenerateGeometryError, match="normals_wobj"):
        cell.check_probes(TOP, [[0.0, 0.0, 0.0]])
    with pytest.raises(UnknownFrameError, match="sensor"):
        cell.check_probes(TOP, UP, tcp="laser")
    assert cell.check_probes(np.zeros((0, 3)), np.zeros((0, 3))) == []


def test_tcp_frames_point_into_the_surface(rng) -> None:
    n = rng.normal(size=(20, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    p = rng.normal(size=(20, 3))
    angles = np.radians(np.arange(0, 360, 15))
    T = tcp_frames(p, n, angles)
    assert T.shape == (20, 24, 4, 4)
    R = T[..., :3, :3]
    np.testing.assert_allclose(
        R @ np.swapaxes(R, -1, -2), np.broadcast_to(np.eye(3), R.shape), atol=1e-12
    )
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-12)
    np.testing.assert_allclose(T[..., :3, 2], np.broadcast_to(-n[:, None], (20, 24, 3)), atol=1e-12)
    np.testing.assert_allclose(T[..., :3, 3], np.broadcast_to(p[:, None], (20, 24, 3)))
    # consecutive candidates turn x by the step about z
    cos = np.einsum("nri,nri->nr", T[:, 1:, :3, 0], T[:, :-1, :3, 0])
    np.testing.assert_allclose(cos, np.cos(np.radians(15)), atol=1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("which", ["ur5", "kuka"])
def test_vendor_robots_answer_through_numeric_ik(which, reference_dir) -> None:
    path = (
        reference_dir / "robots" / "ur5" / "ur5.urdf"
        if which == "ur5"
        else f"{pybullet_data.getDataPath()}/kuka_iiwa/model.urdf"
    )
    # the iiwa's tip link_7 has its frame at joint 7, its flange face 45 mm further out: the
    # tool goes there (a tool at the joint would sit inside link_6, which is now never allowed)
    mount = None if which == "ur5" else make_transform(p=[0, 0, 0.045])
    with Cell(path, use_acl_cache=False, acl_samples=300, T_flange_tool=mount) as c:
        c.set_work_object(trimesh.creation.box([0.2] * 3), "m", make_transform(p=[0.5, 0, 0.1]))
        near, far = c.check_probes([[0, 0, 0.1], [5, 0, 0]], [[0, 0, 1], [0, 0, 1]])
        assert c.solver.kind == "numeric"
    assert near.feasible, near.reason
    T = c.chain.fk(near.q)[0] @ c.T_flange_tcp("sensor")
    np.testing.assert_allclose(T[:3, 3], [0.5, 0, 0.2], atol=1e-5)
    assert not far.feasible and far.reason.startswith("out of reach")


def test_answers_do_not_depend_on_where_the_cell_stands(cell: Cell) -> None:
    """Moving base, work object and fixtures together by one world transform changes nothing."""
    T = make_transform(matrix_from_rotvec([0.2, -0.1, 1.0]), [3.0, -2.0, 0.5])
    pts = np.array([[0.0, 0.0, BOX / 2], [-BOX / 2, 0.1, 0.0], [0.0, 0.0, -BOX / 2]])
    nrm = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
    T_post = make_transform(p=[1.4 + 0.026, 0.0, 0.6075])
    cell.add_fixture("post", radius_m=0.010, height_m=0.015, T_world_fixture=T_post)
    try:
        here = cell.check_probes(pts, nrm)
    finally:
        cell.remove_fixture("post")
    with Cell(T_world_base=T, use_acl_cache=False) as moved:
        moved.set_work_object(trimesh.creation.box([BOX] * 3), "m", T @ T_WORLD_WOBJ, name="box")
        moved.add_fixture("post", radius_m=0.010, height_m=0.015, T_world_fixture=T @ T_post)
        there = moved.check_probes(pts, nrm)
    assert [r.status for r in here] == ["marginal", "feasible", "infeasible"]
    for a, b in zip(here, there):
        assert (a.status, a.reason) == (b.status, b.reason)
        np.testing.assert_equal(a.rotation_rad, b.rotation_rad)  # NaN == NaN here
        np.testing.assert_allclose(a.clearance_m, b.clearance_m, atol=1e-4)


def _same_answers(a: list, b: list) -> None:
    """Staged and plain checks agree (the tool stands at the planned flange pose in the staged
    one, at PyBullet's single-precision FK in the plain one: ~1e-8 m apart)."""
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert (x.status, x.reason, x.branch) == (y.status, y.reason, y.branch)
        np.testing.assert_equal(x.rotation_rad, y.rotation_rad)
        np.testing.assert_allclose(x.clearance_m, y.clearance_m, atol=1e-6)
        np.testing.assert_array_equal(x.q, y.q)


@pytest.mark.parametrize(
    ("height_m", "reason"),
    [
        (0.02, "sensor_body hits plate (clearance -17.0 mm)"),
        (0.05, "guide_tube_1 hits plate (clearance -27.0 mm)"),
        (0.10, "sensor_bracket hits plate (clearance -53.0 mm)"),
    ],
)
def test_tool_blocked_by_a_plate_in_every_rotation(cell: Cell, monkeypatch, height_m, reason):
    """A plate over the point blocks the tool in every rotation: still infeasible, naming the
    plate and the least-bad clearance, as the plain check says, for fewer queries.

    The sensor face lies 8 mm over the point (z 0.608 m); the 10 mm plate is centred
    ``height_m`` over it. 20 mm: the sensor body must rise 17 mm to clear the plate's top;
    50 mm: the tube ends (20 mm behind the face) 27 mm; 100 mm: the bracket (40-140 mm behind
    the face) must drop 53 mm below the plate."""
    T_plate = make_transform(p=[1.4, 0.0, 0.6 + height_m])
    cell.add_fixture("plate", size_m=(0.6, 0.6, 0.01), T_world_fixture=T_plate)
    # once first, uncounted: the first check of a new body makes one-time queries (run on its
    # own, the test counted them into the staged check: 77 against the plain check's 144)
    cell.check_probes(TOP, UP)
    calls = {"n": 0}
    closest = pb.getClosestPoints

    def counted(*args, **kwargs):
        calls["n"] += 1
        return closest(*args, **kwargs)

    monkeypatch.setattr(pb, "getClosestPoints", counted)
    try:
        (staged,) = cell.check_probes(TOP, UP)
        n_staged, calls["n"] = calls["n"], 0
        (plain,) = cell.check_probes(TOP, UP, staged=False)
        n_plain = calls["n"]
    finally:
        cell.remove_fixture("plate")
    assert staged.status == "infeasible" and staged.reason == reason
    _same_answers([staged], [plain])
    assert n_staged <= n_plain // 2  # one tool query per rotation, not per candidate


@pytest.fixture(scope="module")
def demo() -> Iterator[Cell]:
    from planner.demo import make_demo_cell

    with make_demo_cell(use_acl_cache=False) as c:
        yield c


@pytest.mark.slow
def test_demo_points_that_collide_in_every_pose_keep_their_answers(demo: Cell) -> None:
    """Stator points whose every candidate collides (the slow case of the web UI), a
    feasible yoke point, and a point the table blocks: staged answers equal the plain ones."""
    pts = np.array([[-0.135, -0.635, -0.069], [-0.122, -0.444, -0.067], [0.0, -0.6, -0.1375]])
    nrm = np.array([[0.0, -1.0, 0.0], [0.0, -0.866, -0.5], [1.0, 0.0, 0.0]])
    staged = demo.check_probes(pts, nrm)
    plain = demo.check_probes(pts, nrm, staged=False)
    assert [r.status for r in staged] == ["infeasible", "infeasible", "feasible"]
    assert staged[0].reason.startswith("link_5 hits work object")
    assert "hits" in staged[1].reason
    _same_answers(staged, plain)
