"""The x-offset matrix (eq. 13-14) and the slot-hole target function."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from calib.errors import DegenerateGeometryError, NonFiniteError, ShapeError
from calib.frames import invert_transform, make_transform, random_transform, transform_points
from calib.paper.xoffset import (
    SlotGrid,
    slot_positions_wobj,
    slot_target,
    xoffset_matrix,
    xoffset_probe_points,
)

GRID = SlotGrid(
    n_slots=12,
    n_layers=5,
    first_slot_y_m=-0.020,
    first_layer_z_m=-0.030,
    slot_step_y_m=-0.030,
    layer_step_z_m=-0.025,
)


def measured_grid(grid: SlotGrid, field) -> np.ndarray:
    """Nominal PX points (every second tooth, first and last layer) with x from ``field``."""
    rows = xoffset_probe_points(grid)
    px = np.array([[p.position_m for p in row] for row in rows])
    px[..., 0] = field(px[..., 1], px[..., 2])
    return px


@settings(max_examples=100, deadline=None, derandomize=True)
@given(
    c=st.floats(-0.003, 0.003),
    a=st.floats(-0.01, 0.01),
    b=st.floats(-0.01, 0.01),
    n_slots=st.integers(5, 40),
    n_layers=st.integers(2, 8),
    seed=st.integers(0, 2**32 - 1),
    jitter=st.booleans(),
)
def test_affine_field_is_reproduced_exactly(c, a, b, n_slots, n_layers, seed, jitter) -> None:
    grid = SlotGrid(n_slots, n_layers, -0.02, -0.03, -0.03, -0.025)

    def field(y, z):
        return c + a * y + b * z

    px = measured_grid(grid, field)
    if jitter:  # measured points off the nominal grid by up to 2 mm in y and z
        rng = np.random.default_rng(seed)
        px[..., 1:] += rng.uniform(-0.002, 0.002, px[..., 1:].shape)
        px[..., 0] = field(px[..., 1], px[..., 2])
    mx = xoffset_matrix(px, grid)
    holes = slot_positions_wobj(grid)
    assert mx.shape == (n_layers, n_slots)
    np.testing.assert_allclose(mx, field(holes[..., 1], holes[..., 2]), atol=1e-15)


def test_eq14_on_a_grid_hand_worked() -> None:
    # two levels z = -0.03, -0.13 and teeth y = -0.035, -0.095, ... (every second tooth)
    px = measured_grid(GRID, lambda y, z: 0.0 * y)
    px[..., 0] = [[0.0010, 0.0016, 0.0020, 0.0018, 0.0012, 0.0009],
                  [0.0004, 0.0007, 0.0011, 0.0010, 0.0006, 0.0002]]  # fmt: skip
    mx = xoffset_matrix(px, GRID)
    # slot 4 (y = -0.110), layer 3 (z = -0.080): between teeth 1 and 2 of level 0
    y, z = -0.110, -0.080
    s_y = (0.0020 - 0.0016) / (-0.155 - -0.095)
    s_z = (0.0007 - 0.0016) / (-0.130 - -0.030)
    assert mx[2, 3] == pytest.approx(0.0016 + s_y * (y - -0.095) + s_z * (z - -0.030), abs=1e-15)
    # slot 1 (y = -0.020) lies before the first tooth: extrapolated from teeth 0 and 1
    s_y0 = (0.0016 - 0.0010) / (-0.095 - -0.035)
    assert mx[0, 0] == pytest.approx(0.0010 + s_y0 * (-0.020 - -0.035), abs=1e-15)
    # the holes on the measured levels lie on straight lines between the measurements
    assert np.all(np.diff(mx[0, 1:3]) != 0)


def test_bulge_is_interpolated_not_exact_but_close() -> None:
    # a smooth bulge: linear interpolation over every second tooth errs a little, not much
    def bulge(y, z):
        return 0.002 * np.sin(np.pi * y / -0.36) * (1 + 2 * z)

    px = measured_grid(GRID, bulge)
    holes = slot_positions_wobj(GRID)
    err = np.abs(xoffset_matrix(px, GRID) - bulge(holes[..., 1], holes[..., 2]))
    assert 1e-6 < err.max() < 0.0005


def test_probe_points_sit_on_teeth_at_two_layers() -> None:
    rows = xoffset_probe_points(GRID)
    assert len(rows) == 2 and len(rows[0]) == len(range(1, 12, 2))
    assert rows[0][0].id == "PX1_1" and rows[1][-1].id == "PX5_11"
    # tooth 1 lies midway between slots 1 and 2
    assert rows[0][0].position_m == pytest.approx((0.0, -0.035, -0.030))
    assert rows[1][0].position_m == pytest.approx((0.0, -0.035, -0.130))
    assert all(p.normal == (1.0, 0.0, 0.0) for row in rows for p in row)


def test_slot_target_lands_on_known_holes(rng: np.random.Generator) -> None:
    T = make_transform(p=(1.0, 0.2, 0.6)) @ random_transform(rng, 0.1, math.radians(20))
    mx = xoffset_matrix(measured_grid(GRID, lambda y, z: 0.001 + 0.002 * y), GRID)
    # slot 1, layer 1, no offset: the first hole, WOCS rotation
    T1 = slot_target(T, GRID, 1, 1)
    np.testing.assert_allclose(T1[:3, 3], transform_points(T, [0, -0.020, -0.030]), atol=1e-15)
    np.testing.assert_allclose(T1[:3, :3], T[:3, :3], atol=1e-15)
    # slot 7, layer 4 with x-offset, 10 mm standoff and 30 deg about the slot axis
    Tk = slot_target(T, GRID, 7, 4, standoff_m=0.010, rotation_rad=math.radians(30), xoffset=mx)
    local = invert_transform(T) @ Tk
    y7, z4 = -0.020 - 6 * 0.030, -0.030 - 3 * 0.025
    np.testing.assert_allclose(local[:3, 3], [0.001 + 0.002 * y7 + 0.010, y7, z4], atol=1e-15)
    np.testing.assert_allclose(local[:3, 0], [1, 0, 0], atol=1e-15)  # about the slot axis
    assert math.atan2(local[2, 1], local[1, 1]) == pytest.approx(math.radians(30))
    # the same position as the array of all slot holes
    holes = slot_positions_wobj(GRID, mx)
    np.testing.assert_allclose(
        slot_target(T, GRID, 12, 5, xoffset=mx)[:3, 3], transform_points(T, holes[4, 11])
    )


@pytest.mark.parametrize(
    ("slot", "layer", "match"),
    [(0, 1, "slot must lie in 1..12"), (13, 1, "slot must lie in 1..12"),
     (1, 6, "layer must lie in 1..5"), (True, 1, "slot must be an integer"),
     (2.0, 1, "slot must be an integer")],
)  # fmt: skip
def test_slot_target_rejects_bad_numbers(slot, layer, match) -> None:
    with pytest.raises(ShapeError, match=match):
        slot_target(np.eye(4), GRID, slot, layer)


def test_slot_target_rejects_bad_values() -> None:
    with pytest.raises(ShapeError, match="standoff_m must be finite"):
        slot_target(np.eye(4), GRID, 1, 1, standoff_m=float("inf"))
    with pytest.raises(ShapeError, match=r"xoffset must be \(5, 12\)"):
        slot_target(np.eye(4), GRID, 1, 1, xoffset=np.zeros((12, 5)))
    with pytest.raises(ShapeError, match="T_base_wobj"):
        slot_target(np.eye(3), GRID, 1, 1)


def test_grid_validation() -> None:
    with pytest.raises(ShapeError, match=r"grid\.n_slots must be an integer >= 1"):
        SlotGrid(0, 2, 0.0, 0.0, -0.03, -0.03)
    with pytest.raises(ShapeError, match=r"grid\.slot_step_y_m must be non-zero"):
        SlotGrid(3, 2, 0.0, 0.0, 0.0, -0.03)
    with pytest.raises(ShapeError, match=r"grid\.first_layer_z_m must be finite"):
        SlotGrid(3, 2, 0.0, float("nan"), -0.03, -0.03)
    with pytest.raises(ShapeError, match="at least 2 distinct layers"):
        xoffset_probe_points(GRID, layers=(2, 2))


def test_xoffset_matrix_bad_measurements() -> None:
    px = measured_grid(GRID, lambda y, z: 0.0 * y)
    with pytest.raises(ShapeError, match="at least 2 levels"):
        xoffset_matrix(px[:1], GRID)
    with pytest.raises(ShapeError, match=r"px_wobj must be \(N, N, 3\)"):
        xoffset_matrix(px[..., :2], GRID)
    bad = px.copy()
    bad[0, 2, 0] = np.nan
    with pytest.raises(NonFiniteError, match="px_wobj"):
        xoffset_matrix(bad, GRID)
    shuffled = px[:, [0, 2, 1, 3, 4, 5]]
    with pytest.raises(DegenerateGeometryError, match=r"teeth .* strictly increasing or decr"):
        xoffset_matrix(shuffled, GRID)
    same_level = px.copy()
    same_level[1, :, 2] = same_level[0, :, 2]
    with pytest.raises(DegenerateGeometryError, match="levels"):
        xoffset_matrix(same_level, GRID)
