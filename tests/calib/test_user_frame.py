"""The 3-point user frame against known frames, its refusals, and probe points re-expressed."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from calib.errors import InputError
from calib.frames import random_transform, transform_directions, transform_points
from calib.probing import ProbePoint, SearchSpec
from calib.user_frame import probe_point_in, three_point_frame


@pytest.mark.parametrize("seed", range(5))
def test_three_points_give_the_known_frame(seed: int) -> None:
    rng = np.random.default_rng(seed)
    T = random_transform(rng, 1.0, np.pi)
    o, x, y = T[:3, 3], T[:3, 0], T[:3, 1]
    a, b, c = rng.uniform(0.05, 0.5), rng.uniform(-0.5, 0.5), rng.uniform(0.05, 0.5)
    got = three_point_frame(o, o + a * x, o + b * x + c * y)
    np.testing.assert_allclose(got, T, atol=1e-12)


def test_the_frame_is_the_controllers_construction() -> None:
    # x along origin -> P2; z = x cross (P3 - origin); y = z cross x: a point at -y flips z
    T = three_point_frame([1.0, 2.0, 3.0], [1.0, 2.5, 3.0], [0.0, 2.0, 3.0])
    np.testing.assert_allclose(T[:3, 3], [1.0, 2.0, 3.0])
    np.testing.assert_allclose(T[:3, 0], [0.0, 1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(T[:3, 2], [0.0, 0.0, 1.0], atol=1e-15)
    np.testing.assert_allclose(T[:3, 1], [-1.0, 0.0, 0.0], atol=1e-15)


@pytest.mark.parametrize(
    ("points", "message"),
    [
        (([0, 0, 0], [0, 0, 0], [0, 1, 0]), "the origin and the \\+x point coincide"),
        (([0, 0, 0], [1, 0, 0], [1, 0.0002, 0]), "the \\+x point and the xy-plane point coincide"),
        (([0, 0, 0], [1, 0, 0], [2, 0.0005, 0]), "collinear: the xy-plane point is 0.500 mm"),
        (([0, 0, 0], [1, 0, 0], [np.nan, 1, 0]), "xy-plane point: must be 3 finite"),
    ],
)
def test_coincident_collinear_or_bad_points_are_refused(points: tuple, message: str) -> None:
    with pytest.raises(InputError, match=message):
        three_point_frame(*(np.asarray(p, dtype=float) for p in points))


def test_probe_points_stay_put_in_the_world() -> None:
    rng = np.random.default_rng(7)
    T_old_new = random_transform(rng, 1.0, np.pi)
    T_new_old = np.linalg.inv(T_old_new)
    edge = ProbePoint(
        id="E",
        position_m=(0.1, 0.2, 0.3),
        normal=(0.0, 0.0, 1.0),
        search=SearchSpec(kind="edge", edge_direction=(1.0, 0.0, 0.0)),
        edge_normal=(1.0, 0.0, 0.0),
    )
    got = probe_point_in(T_new_old, edge)
    np.testing.assert_allclose(transform_points(T_old_new, got.position_m), edge.position_m)
    np.testing.assert_allclose(transform_directions(T_old_new, got.normal), edge.normal, atol=1e-12)
    assert got.search.edge_direction is not None and got.edge_normal is not None
    np.testing.assert_allclose(
        transform_directions(T_old_new, got.search.edge_direction), [1, 0, 0], atol=1e-12
    )
    np.testing.assert_allclose(
        transform_directions(T_old_new, got.edge_normal), [1, 0, 0], atol=1e-12
    )
    assert dataclasses.replace(got, position_m=edge.position_m).search.kind == "edge"
    back = probe_point_in(T_old_new, got)
    np.testing.assert_allclose(back.position_m, edge.position_m, atol=1e-12)
