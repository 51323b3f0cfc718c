"""Search commands from probe points (calib.probing): one frame and a batch of frames give the
same command, and a point built with lists (not hashable) is served like its tuple twin."""

from __future__ import annotations

import numpy as np

from calib.frames import random_transform
from calib.paper.stator_layout import example_stator_points
from calib.probing import ProbePoint, SearchCommand


def _fields(cmd: SearchCommand) -> list[np.ndarray]:
    return [
        np.asarray(v, dtype=float).reshape(-1, 3)
        for v in (cmd.start_m, cmd.direction, cmd.sensor_axis, cmd.nominal_m, cmd.stop_normal)
    ]


def test_one_frame_is_the_batch_of_one(rng: np.random.Generator) -> None:
    """The one-frame path (cached wobj vectors, two products) against the batch's general
    transforms, for the approaches and the edge searches of the stator's points."""
    for point in example_stator_points().values():
        for _ in range(5):
            T = random_transform(rng, 2.0, np.pi)
            one = SearchCommand.from_point(point, T)
            batch = SearchCommand.from_point(point, T[None])
            assert (one.point_id, one.kind, one.length_m) == (
                batch.point_id,
                batch.kind,
                batch.length_m,
            )
            for a, b in zip(_fields(one), _fields(batch), strict=True):
                np.testing.assert_allclose(a, b, rtol=0.0, atol=1e-14)
            np.testing.assert_array_equal(one.T_base_wobj_estimate, T)


def test_a_point_with_lists_is_served_like_its_tuple_twin(rng: np.random.Generator) -> None:
    point = example_stator_points()["G"]  # an edge point: direction and edge normal
    twin = ProbePoint(
        point.id,
        list(point.position_m),  # type: ignore[arg-type]
        list(point.normal),  # type: ignore[arg-type]
        point.search,
        None if point.edge_normal is None else list(point.edge_normal),  # type: ignore[arg-type]
    )
    T = random_transform(rng, 1.0, 1.0)
    for a, b in zip(
        _fields(SearchCommand.from_point(twin, T)),
        _fields(SearchCommand.from_point(point, T)),
        strict=True,
    ):
        np.testing.assert_array_equal(a, b)
