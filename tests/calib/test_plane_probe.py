"""The one ideal probe (calib.plane_probe): a search ends on the plane of the face it looks for
on the part where it truly lies; ``within_length`` (the check's dry run) fails a search as the
robot does when that plane lies outside the search, and otherwise answers exactly as without."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from calib.frames import make_transform, matrix_from_rotvec
from calib.paper.stator_layout import example_stator_points
from calib.plane_probe import PlaneProbe
from calib.probing import SearchCommand

T_NOM = make_transform(matrix_from_rotvec([0.1, -0.2, 0.3]), [1.0, 0.2, 0.5])


def _command(point_id: str) -> SearchCommand:
    return SearchCommand.from_point(example_stator_points()[point_id], T_NOM)


@pytest.mark.parametrize("point_id", ["A", "F"])
def test_on_the_nominal_part_a_search_ends_at_its_nominal_point(point_id: str) -> None:
    """An approach ends on its nominal point; an edge search there plus the edge offset."""
    cmd = _command(point_id)
    offset = 0.004 if cmd.kind == "edge" else 0.0
    res = PlaneProbe(T_NOM, edge_offset_m=offset, within_length=True)(cmd)
    assert res.ok
    np.testing.assert_allclose(res.point_m, cmd.nominal_m + offset * cmd.direction, atol=1e-12)
    assert res.travel_m == pytest.approx(float((cmd.nominal_m - cmd.start_m) @ cmd.direction)
                                         + offset, abs=1e-12)  # fmt: skip


def test_within_length_fails_past_the_end_and_changes_nothing_inside() -> None:
    cmd = _command("A")
    inside = make_transform(None, T_NOM[:3, :3] @ np.array([-0.005, 0.0, 0.0]))  # 5 mm in
    past = make_transform(None, T_NOM[:3, :3] @ np.array([-0.1, 0.0, 0.0]))  # 100 mm in
    for T in (inside @ T_NOM, T_NOM):
        free, bounded = PlaneProbe(T)(cmd), PlaneProbe(T, within_length=True)(cmd)
        assert bounded.ok and bounded.travel_m == free.travel_m
    free = PlaneProbe(past @ T_NOM)(cmd)
    assert free.ok and free.travel_m > cmd.length_m  # the linearisation's answer
    bounded = PlaneProbe(past @ T_NOM, within_length=True)(cmd)
    assert not bounded.ok
    assert bounded.reason == f"no event within {cmd.length_m * 1e3:.1f} mm"


def test_a_search_parallel_to_its_face_fails_and_eps_moves_the_jth_event() -> None:
    cmd = _command("A")
    n = np.asarray(cmd.stop_normal)
    along_face = np.cross(n, cmd.sensor_axis + np.array([0.3, -0.2, 0.1]))
    sideways = dataclasses.replace(cmd, direction=along_face / np.linalg.norm(along_face))
    assert "parallel" in PlaneProbe(T_NOM)(sideways).reason
    probe = PlaneProbe(T_NOM, eps={1: 2e-6})
    first, second = probe(cmd), probe(cmd)
    assert second.travel_m - first.travel_m == pytest.approx(2e-6, abs=1e-15)
    assert len(probe.commands) == 2 and all(c is cmd for c in probe.commands)
