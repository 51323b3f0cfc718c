"""The simulated x-offset run (planner.sim.xoffset): exact on an affine bulge, and it cancels
the calibrated frame's errors along x, as the paper measures it in the calibrated frame."""

from __future__ import annotations

import numpy as np

from calib.frames import invert_transform, make_transform, matrix_from_rotvec, transform_points
from calib.paper.settings import XOffsetRun
from calib.paper.xoffset import SlotGrid
from calib.probing import ProbeResult, SearchCommand
from planner.sim.xoffset import run_xoffset, xoffset_setup

GRID = SlotGrid(12, 4, -0.02, -0.025, -0.024, -0.015)
C, A, B = 0.0003, -0.0004, 0.002  # the true side face: x = C + A y + B z (wobj of the part)
T_TRUE = make_transform(matrix_from_rotvec([0.0, 0.1, 0.2]), [1.0, -0.3, 0.8])


def face_probe(cmd: SearchCommand) -> ProbeResult:
    """An ideal approach onto the affine face of the part at ``T_TRUE``."""
    T = invert_transform(T_TRUE)
    s = transform_points(T, cmd.start_m)
    d = T[:3, :3] @ np.asarray(cmd.direction)
    f = lambda p: p[0] - (C + A * p[1] + B * p[2])  # noqa: E731
    t = f(s) / (f(s) - f(s + d))
    return ProbeResult(transform_points(T_TRUE, s + t * d), travel_m=t)


def _holes() -> np.ndarray:
    y, z = np.meshgrid(GRID.slot_y_m, GRID.layer_z_m)
    return np.stack([C + A * y + B * z, y, z], axis=-1)


def test_affine_bulge_is_reproduced_at_every_hole() -> None:
    xs = xoffset_setup(XOffsetRun(grid=GRID), _holes())
    err = run_xoffset(xs, face_probe, T_TRUE, T_TRUE)
    assert err.shape == (GRID.n_slots * GRID.n_layers, 3)
    assert np.abs(err).max() < 1e-12


def test_the_run_cancels_the_frames_x_error() -> None:
    """A calibrated frame 0.2 mm off along x and tilted 0.05 deg about y: the targets placed
    with the matrix lie on the true holes in x (measured in that frame); those at x = 0 carry
    the frame's shift and tilt less the bulge, 29-185 um here."""
    d = make_transform(matrix_from_rotvec([0.0, np.radians(0.05), 0.0]), [0.0002, 0.0, 0.0])
    T_cal = T_TRUE @ d
    xs = xoffset_setup(XOffsetRun(grid=GRID), _holes())
    with_mx = run_xoffset(xs, face_probe, T_cal, T_TRUE)
    assert np.abs(with_mx[:, 0]).max() < 1e-9
    placed = transform_points(d, xs.targets_wobj.reshape(-1, 3))
    without = placed - xs.holes_wobj.reshape(-1, 3)
    t = xs.targets_wobj.reshape(-1, 3)
    bulge = C + A * t[:, 1] + B * t[:, 2]
    tilt = np.radians(0.05)
    expected = 0.0002 + np.cos(tilt) * t[:, 0] + np.sin(tilt) * t[:, 2] - bulge
    np.testing.assert_allclose(without[:, 0], expected, atol=1e-12)
    assert np.abs(without[:, 0]).min() > 2.5e-5
