"""The demo cell and the paper's A-H points on the stator section."""

from __future__ import annotations

import math

import numpy as np
import pytest

from calib.frames import check_transform
from calib.paper.stator_procedure import check_stator_points
from planner.demo import make_demo_cell
from planner.parts.stator import StatorGeometry
from planner.parts.stator_demo import BETA1_RAD, nominal_T_base_wobj, stator_ah_points

GEOM = StatorGeometry.full_section()


def test_nominal_pose_leans_back_by_beta1() -> None:
    T = check_transform(nominal_T_base_wobj())
    x_w, y_w, z_w = T[:3, 0], T[:3, 1], T[:3, 2]
    assert x_w[0] < -0.9  # the side face looks back towards the robot at the base origin
    assert math.asin(z_w[0]) == pytest.approx(BETA1_RAD)  # its top leans away (base +x)
    assert np.allclose(y_w, [0.0, -1.0, 0.0])
    # the robot's metre of the side face is centred in front of the robot
    near, far = T @ [0, 0, 0, 1], T @ [0, -GEOM.reach_length_m, 0, 1]
    assert near[1] == pytest.approx(-far[1])


def _disk(centre_yz: np.ndarray, r: float, n: int = 121) -> tuple[np.ndarray, np.ndarray]:
    u = np.linspace(-r, r, n)
    yy, zz = np.meshgrid(u, u)
    inside = yy**2 + zz**2 <= r**2
    return centre_yz[0] + yy[inside], centre_yz[1] + zz[inside]


def test_points_pass_the_procedure_layout_and_avoid_slot_holes() -> None:
    pts = stator_ah_points(GEOM)
    check_stator_points(pts)
    r = 0.009
    for pid in "ABDEG":  # the 18 mm footprint sees only metal
        y, z = _disk(np.array(pts[pid].position_m[1:]), r)
        assert not GEOM.hole_near(y, z).any(), pid
        assert y.max() < 0 and y.min() > -GEOM.length_m and z.max() < 0, pid
    for pid in "AB":
        assert pts[pid].position_m[2] + r < GEOM.slot_region_bottom_m
    c = pts["C"].position_m
    assert -GEOM.depth_m < c[0] - r and c[0] + r < 0 and c[2] - r > -GEOM.height_m
    # F and H slide up a tooth from E's and G's height to the top edge
    for edge, start in (("F", "E"), ("H", "G")):
        assert pts[edge].position_m[1] == pts[start].position_m[1]
        assert pts[edge].search.start_offset_m == pytest.approx(-pts[start].position_m[2])


def test_demo_cell_holds_the_stator_at_the_nominal_pose() -> None:
    cell = make_demo_cell(GEOM)
    try:
        assert np.allclose(cell.T_base_wobj, nominal_T_base_wobj())
        assert "table" in cell.fixtures
        assert cell.work_object is not None
    finally:
        cell.close()


def test_demo_points_are_reachable() -> None:
    pytest.importorskip("planner.cell.probe.feasibility")
    pts = stator_ah_points(GEOM)
    cell = make_demo_cell(GEOM)
    try:
        res = cell.check_probes(
            np.array([p.position_m for p in pts.values()]),
            np.array([p.normal for p in pts.values()]),
            tcp="sensor",
        )
        bad = {pid: r.reason for pid, r in zip(pts, res) if not r.feasible}
        assert not bad
    finally:
        cell.close()
