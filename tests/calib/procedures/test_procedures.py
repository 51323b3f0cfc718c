"""Step-by-step runners driven by an ideal analytic probe: a ray/plane intersection for approach
searches and a plane/plane edge for edge searches, on a misplaced random work object."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from calib.errors import ProbeFailedError, ShapeError, UnobservableError
from calib.estimators.layout import FaceLayout, random_face_layout
from calib.estimators.runners import run_best_fit, run_three_two_one
from calib.estimators.three_two_one import ThreeTwoOneLayout
from calib.frames import (
    invert_transform,
    make_transform,
    motion_between,
    random_transform,
    small_motion,
    transform_directions,
)
from calib.probing import ProbeResult, SearchCommand

seeds = st.integers(min_value=0, max_value=2**32 - 1)


def plane_probe(
    faces: FaceLayout,
    T_base_wobj_true: np.ndarray,
    log: list[SearchCommand] | None = None,
    noise: Callable[[], np.ndarray] | None = None,
) -> Callable[[SearchCommand], ProbeResult]:
    """An ideal sensor on the true (infinite) faces of ``faces`` placed at ``T_base_wobj_true``.

    Approach: the first crossing of the search line with the point's true face. Edge: move along
    the search line, look along the sensor axis at the true face, and stop where the spot seen
    crosses the true face the edge belongs to; the surface point there is returned.
    """
    n_base = transform_directions(T_base_wobj_true, faces.normals)
    d_base = faces.offsets_m + n_base @ T_base_wobj_true[:3, 3]
    by_id = {p.id: (f, p.edge_normal is not None) for p, f in zip(faces.points, faces.face_of)}

    def probe(cmd: SearchCommand) -> ProbeResult:
        if log is not None:
            log.append(cmd)
        face, is_edge = by_id[cmd.point_id]
        n, d = n_base[face], d_base[face]
        if not is_edge:
            t = (d - n @ cmd.start_m) / (n @ cmd.direction)
            if not 0.0 <= t <= cmd.length_m:
                return ProbeResult(None, f"no detection within {cmd.length_m * 1e3:.0f} mm")
            q = cmd.start_m + t * cmd.direction
        else:
            e, de, a = n_base[1], d_base[1], cmd.sensor_axis

            def seen(s: float) -> np.ndarray:
                p = cmd.start_m + s * cmd.direction
                return p + (d - n @ p) / (n @ a) * a

            f0, f1 = e @ seen(0.0) - de, e @ seen(1.0) - de
            t = -f0 / (f1 - f0)
            if not 0.0 <= t <= cmd.length_m:
                return ProbeResult(None, "edge not found")
            q = seen(t)
        if noise is not None:
            q = q + noise()
        return ProbeResult(q, travel_m=float(t))

    return probe


def _misplaced(rng: np.random.Generator, faces: FaceLayout) -> tuple[np.ndarray, np.ndarray]:
    """A nominal placement and the truth 20 mm / 3 deg (about the part's corner) away from it."""
    T_nominal = random_transform(rng, 2.0, np.pi)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    to_corner = make_transform(p=faces.corner_m)
    turn = to_corner @ small_motion(np.r_[0.0, 0.0, 0.0, np.deg2rad(3.0) * axis])
    turn = turn @ invert_transform(to_corner)
    return T_nominal, T_nominal @ make_transform(p=0.020 * direction) @ turn


def _faces(rng: np.random.Generator, counts=(3, 2, 1), n_edge: int = 0) -> FaceLayout:
    # searches long enough for 20 mm + 3 deg at up to ~0.6 m from the layout centre
    return random_face_layout(
        rng, counts, n_edge_points=n_edge, size_m=0.3, start_offset_m=0.08, overtravel_m=0.08
    )


@settings(derandomize=True, max_examples=25, deadline=None)
@given(seed=seeds)
def test_three_two_one_converges_from_misplacement(seed: int) -> None:
    rng = np.random.default_rng(seed)
    faces = _faces(rng)
    p = faces.points
    layout = ThreeTwoOneLayout.from_points(p[:3], p[3:5], p[5])
    T_nominal, T_true = _misplaced(rng, faces)
    log: list[SearchCommand] = []
    res = run_three_two_one(layout, plane_probe(faces, T_true, log), T_nominal, rounds=2)
    assert np.abs(motion_between(T_true, res.T_base_wobj)).max() < 1e-9
    assert res.n_probes == 12 and len(log) == 12
    # the order of the method: primary, secondary, tertiary, in each round
    assert [c.point_id for c in log[:6]] == [q.id for q in layout.points]
    # the secondary points are commanded in the estimate updated from the primary ones
    assert not np.allclose(log[3].T_base_wobj_estimate, T_nominal)
    np.testing.assert_allclose(log[6].T_base_wobj_estimate, res.estimates[2], atol=0)
    # second-round commands aim at the true surface points
    for cmd, step in zip(log[6:], res.probes[6:]):
        assert np.linalg.norm(cmd.nominal_m - step.measured_m) < 1e-9


@settings(derandomize=True, max_examples=20, deadline=None)
@given(seed=seeds)
def test_best_fit_converges_from_misplacement(seed: int) -> None:
    rng = np.random.default_rng(seed)
    faces = _faces(rng, (4, 3, 2), n_edge=2)
    T_nominal, T_true = _misplaced(rng, faces)
    res = run_best_fit(faces.points, plane_probe(faces, T_true), T_nominal, rounds=2)
    assert np.abs(motion_between(T_true, res.T_base_wobj)).max() < 1e-9
    assert res.n_probes == 2 * len(faces.points)
    assert res.fit.rms_m < 1e-10
    assert res.measured_base.shape == (len(faces.points), 3)


def test_progressive_updates_aim_later_points_better(rng: np.random.Generator) -> None:
    faces = _faces(rng, (4, 3, 2))
    T_nominal, T_true = _misplaced(rng, faces)
    aim_error = {}
    for progressive in (False, True):
        res = run_best_fit(
            faces.points, plane_probe(faces, T_true), T_nominal, progressive=progressive
        )
        first = res.probes[: len(faces.points)]
        # distance between where a point was expected and where it was really measured
        aim_error[progressive] = np.mean(
            [np.linalg.norm(s.command.nominal_m - s.measured_m) for s in first[5:]]
        )
    assert aim_error[True] < 0.5 * aim_error[False]


def test_noisy_probe_gives_error_of_the_noise_size(rng: np.random.Generator) -> None:
    faces = _faces(rng, (5, 4, 3))
    T_nominal, T_true = _misplaced(rng, faces)
    sigma = 5e-5
    probe = plane_probe(faces, T_true, noise=lambda: rng.normal(scale=sigma, size=3))
    res = run_best_fit(faces.points, probe, T_nominal, rounds=2, sigma_m=sigma)
    err = motion_between(T_true, res.T_base_wobj)
    std = np.sqrt(np.diag(res.fit.covariance))
    assert np.all(np.abs(err) < 5 * std)  # within 5 predicted sigma
    assert np.abs(err[:3]).max() > 1e-7  # and the noise really is there


def test_failed_probe_raises_with_point_id(rng: np.random.Generator) -> None:
    faces = _faces(rng)
    p = faces.points
    layout = ThreeTwoOneLayout.from_points(p[:3], p[3:5], p[5])
    T_nominal, T_true = _misplaced(rng, faces)
    inner = plane_probe(faces, T_true)

    def flaky(cmd: SearchCommand) -> ProbeResult:
        if cmd.point_id == p[4].id:
            return ProbeResult(None, "sensor already detecting at start")
        return inner(cmd)

    with pytest.raises(ProbeFailedError, match="already detecting") as info:
        run_three_two_one(layout, flaky, T_nominal)
    assert info.value.point_id == p[4].id
    with pytest.raises(ProbeFailedError):
        run_best_fit(p, flaky, T_nominal)


def test_bad_arguments_raise_named_errors(rng: np.random.Generator) -> None:
    faces = _faces(rng)
    probe = plane_probe(faces, np.eye(4))
    with pytest.raises(ShapeError, match="rounds"):
        run_best_fit(faces.points, probe, np.eye(4), rounds=0)
    with pytest.raises(ShapeError, match="T_base_wobj_start"):
        run_best_fit(faces.points, probe, np.eye(3))
    with pytest.raises(UnobservableError, match="not constrained"):
        run_best_fit(faces.points[:3], probe, np.eye(4))

    def garbage(cmd: SearchCommand) -> ProbeResult:
        return ProbeResult(np.array([np.nan, 0.0, 0.0]))

    with pytest.raises(ValueError, match="probe result for point"):
        run_best_fit(faces.points, garbage, np.eye(4))
