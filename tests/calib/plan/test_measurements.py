"""Tests of calib.plan.measurements: strict loading, units and frames, sequences of retakes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from calib.frames import invert_transform, random_transform, transform_points
from calib.plan.measurements import (
    Measurements,
    MeasurementsError,
    load_measurements,
    measurements_from_json,
    save_measurements,
)


def _text(**fields: object) -> str:
    data: dict[str, object] = {
        "schema": "wobjcal.measurements/1",
        "frame": "base",
        "units": "mm",
        "points": {"A": [1000.0, -500.0, 250.0], "C": [1.0, 2.0, 3.0]},
    }
    data.update(fields)
    return json.dumps({k: v for k, v in data.items() if v is not None})


def test_mm_are_converted_to_metres() -> None:
    m = measurements_from_json(_text())
    np.testing.assert_allclose(m.points_m()["A"], [1.0, -0.5, 0.25], rtol=0, atol=1e-15)


def test_retakes_come_in_order() -> None:
    m = measurements_from_json(_text(retakes={"C": [[4.0, 5.0, 6.0], [7.0, 8.0, 9.0]]}))
    seq = m.sequence_m("C")
    np.testing.assert_allclose(seq * 1e3, [[1, 2, 3], [4, 5, 6], [7, 8, 9]])


def test_world_frame_is_converted(rng: np.random.Generator) -> None:
    T_world_base = random_transform(rng, 2.0, 3.0)
    p_world = np.array([0.3, -0.2, 0.9])
    m = measurements_from_json(_text(frame="world", units="m", points={"A": list(p_world)}))
    got = m.points_m(invert_transform(T_world_base))["A"]
    np.testing.assert_allclose(transform_points(T_world_base, got), p_world, atol=1e-12)
    with pytest.raises(MeasurementsError, match="'world' needs T_base_world"):
        m.points_m()


@pytest.mark.parametrize(
    ("fields", "message"),
    [
        ({"schema": "wobjcal.measurements/9"}, "schema: unsupported version"),
        ({"schema": None}, "schema: required field missing"),
        ({"units": "inch"}, "units: 'inch' is not a unit of this format (m or mm); convert to mm"),
        ({"frame": "tool0"}, "frame: invalid value 'tool0' (valid: 'base', 'world')"),
        ({"points": {"A": [1.0, 2.0]}}, "points.A: must have length 3, got 2"),
        ({"points": {"A": [1.0, "x", 2.0]}}, "points.A[1]: must be a number, got str"),
        ({"point": {}}, "point: unknown field"),
        ({"retakes": {"Q": [[1.0, 2.0, 3.0]]}}, "retakes.Q: no first measurement in points"),
        ({"failed": {"A": "no detection"}}, "failed: ['A'] are also listed in points"),
    ],
)
def test_malformed_measurements(fields: dict[str, object], message: str) -> None:
    with pytest.raises(MeasurementsError) as info:
        measurements_from_json(_text(**fields), source="meas.json")
    assert str(info.value).startswith("meas.json: ")
    assert message in str(info.value)


def test_nan_is_rejected_with_path() -> None:
    text = _text().replace("250.0", "NaN")
    with pytest.raises(
        MeasurementsError, match=r"points\.A\[2\]: must be a finite number, got NaN"
    ):
        measurements_from_json(text)


def test_missing_point_names_failure_reason() -> None:
    m = measurements_from_json(_text(failed={"D": "no detection within 50 mm"}))
    with pytest.raises(
        MeasurementsError, match=r"points\.D: not measured \(failed on the robot: no"
    ):
        m.sequence_m("D")


def test_save_load_round_trip(tmp_path: Path) -> None:
    m = Measurements.from_points_m({"A": [0.1, 0.2, 0.3], "B": [1.5, -0.25, 0.0]}, units="mm")
    path = save_measurements(m, tmp_path / "m.json")
    again = load_measurements(path)
    assert again == m
    np.testing.assert_allclose(again.points_m()["B"], [1.5, -0.25, 0.0], atol=1e-15)
    save_measurements(again, tmp_path / "m2.json")
    assert (tmp_path / "m2.json").read_bytes() == path.read_bytes()
