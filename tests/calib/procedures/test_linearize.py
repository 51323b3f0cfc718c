"""The predicted accuracy of a procedure from its linearised run (calib.procedures.linearize):
exact on the ideal part, equal to the best fit's own covariance, and against a Monte Carlo of
the 3-2-1 closed form."""

from __future__ import annotations

import numpy as np
import pytest

from calib.estimators.best_fit import best_fit
from calib.estimators.layout import random_face_layout
from calib.estimators.three_two_one import ThreeTwoOneLayout, three_two_one
from calib.frames import make_transform, matrix_from_rotvec, motion_between
from calib.models import SearchNoise
from calib.paper.stator_layout import example_stator_points
from calib.plane_probe import PlaneProbe
from calib.probing import SearchCommand
from calib.procedures import BEST_FIT, HULTMAN2013, THREE_TWO_ONE, RolePoint
from calib.procedures.linearize import event_covariance, linearize

T_NOM = make_transform(matrix_from_rotvec([0.1, -0.2, 0.3]), [1.0, 0.2, 0.5])
T_TRUE = T_NOM @ make_transform(matrix_from_rotvec([0.02, -0.01, 0.015]), [0.01, -0.006, 0.004])


def test_plane_probe_lets_every_procedure_find_the_true_frame() -> None:
    pts = [RolePoint(r, p) for r, p in example_stator_points().items()]
    run = HULTMAN2013.run(pts, T_NOM, PlaneProbe(T_TRUE, edge_offset_m=0.0), None)
    assert np.abs(motion_between(T_TRUE, run.T_base_wobj)).max() < 1e-9
    fit = [RolePoint("fit", rp.point) for rp in pts]
    run = BEST_FIT.run(fit, T_NOM, PlaneProbe(T_TRUE), None)
    assert np.abs(motion_between(T_TRUE, run.T_base_wobj)).max() < 1e-9


def test_best_fit_prediction_is_the_estimators_covariance(rng: np.random.Generator) -> None:
    """Noise sigma along each approach: the linearised run's covariance equals
    ``sigma^2 (J^T J)^-1`` of :func:`calib.estimators.best_fit.best_fit`."""
    layout = random_face_layout(rng, (4, 3, 3))
    pts = [RolePoint("fit", p) for p in layout.points]

    def run(probe):  # type: ignore[no-untyped-def]
        return {"f": motion_between(T_NOM, BEST_FIT.run(pts, T_NOM, probe, None).T_base_wobj)}

    lin = linearize(run, T_NOM)
    assert len(lin.commands) == 2 * len(pts)  # two rounds; the first only steers the second
    sigma = 5e-5
    C = event_covariance(lin.commands, [SearchNoise(sigma)] * len(lin.commands), 0.0)
    q = np.array([T_NOM[:3, :3] @ p.position_m + T_NOM[:3, 3] for p in layout.points])
    cov = best_fit(layout.points, q, T_NOM, sigma_m=sigma).covariance
    np.testing.assert_allclose(lin.covariance("f", C), cov, rtol=1e-5, atol=1e-20)
    # the robot's repeatability along a search counts the same as the sensor's noise
    C_robot = event_covariance(lin.commands, [SearchNoise(0.0)] * len(lin.commands), sigma)
    np.testing.assert_allclose(C_robot, C, rtol=1e-12)


@pytest.mark.slow
def test_three_two_one_prediction_matches_a_monte_carlo(rng: np.random.Generator) -> None:
    layout = random_face_layout(rng)
    pts = [
        RolePoint(r, p)
        for r, p in zip(
            ("primary",) * 3 + ("secondary",) * 2 + ("tertiary",), layout.points, strict=True
        )
    ]

    def run(probe):  # type: ignore[no-untyped-def]
        return {"f": motion_between(T_NOM, THREE_TWO_ONE.run(pts, T_NOM, probe, None).T_base_wobj)}

    lin = linearize(run, T_NOM)
    sigma = 4e-5
    cov = lin.covariance("f", event_covariance(lin.commands, [SearchNoise(sigma)] * 6, 0.0))
    lay = ThreeTwoOneLayout.from_points(layout.points[:3], layout.points[3:5], layout.points[5])
    R, t = T_NOM[:3, :3], T_NOM[:3, 3]
    q0 = np.array([R @ p.position_m + t for p in lay.points])
    n = np.array([R @ lay.normals[k] for k in (0, 0, 0, 1, 1, 2)])
    draws = np.array(
        [
            motion_between(T_NOM, three_two_one(lay, q0 + e[:, None] * n, T_NOM).T_base_wobj)
            for e in rng.normal(0.0, sigma, (4000, 6))
        ]
    )
    sim = np.cov(draws.T)
    np.testing.assert_allclose(np.sqrt(np.diag(sim)), np.sqrt(np.diag(cov)), rtol=0.05)


def test_a_tcp_error_correlates_the_searches() -> None:
    T = np.eye(4)
    a = np.array([0.0, 0.0, -1.0])
    cmds = [
        SearchCommand(f"p{i}", "approach", np.zeros(3), a, 0.05, a, T, np.zeros(3), -a)
        for i in range(2)
    ]
    C = event_covariance(cmds, [SearchNoise(0.0)] * 2, robot_sigma_m=0.0, tcp_sigma_m=1e-4)
    assert C[0, 1] == pytest.approx(1e-8) and C[0, 0] == pytest.approx(1e-8)
    C = event_covariance(cmds, [SearchNoise(0.0)] * 2, robot_sigma_m=1e-4)
    assert C[0, 1] == 0.0 and C[1, 1] == pytest.approx(1e-8)


def test_edge_gain_couples_the_standoff() -> None:
    """An edge search's event moves with its axis gain when the track runs closer."""
    edge = example_stator_points()["F"]
    cmd = SearchCommand.from_point(edge, T_NOM)
    closer = make_transform(None, T_NOM[:3, :3] @ np.array([0.001, 0.0, 0.0]))  # face 1 mm out
    base = PlaneProbe(T_NOM, edge_offset_m=0.006, edge_axis_gain=1.2)(cmd)
    moved = PlaneProbe(closer @ T_NOM, edge_offset_m=0.006, edge_axis_gain=1.2)(cmd)
    assert moved.travel_m - base.travel_m == pytest.approx(1.2 * 0.001, rel=1e-9)
