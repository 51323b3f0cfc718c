"""The paper's A-H procedure against an ideal analytic probe on a randomly posed stator box."""

from __future__ import annotations

import math
import pickle
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from calib.errors import DegenerateGeometryError, PlanError, ProbeFailedError, ShapeError
from calib.frames import (
    invert_transform,
    make_transform,
    matrix_from_rotvec,
    matrix_from_tait_bryan_zyx,
    motion_between,
    random_transform,
    transform_points,
)
from calib.paper.settings import Hultman2013
from calib.paper.stator_procedure import (
    check_stator_points,
    example_stator_points,
    probe_from_measurements,
    run_stator_procedure,
)
from calib.probing import ProbeResult, SearchCommand
from tests.box_part import BoxProbe


def nominal_pose(alpha_rad: float, position_m, robot_at_plus_x: bool = False) -> np.ndarray:
    """The preliminary WOCS: side face inclined by the paper's beta1 = 15 deg, top leaning
    towards base +x; WOCS y along base +y, or along base -y when the robot is at +x (as in
    ``planner.parts.stator_demo``: WOCS x towards the robot at the base origin)."""
    beta = math.radians(15.0)
    if robot_at_plus_x:
        return make_transform(
            matrix_from_tait_bryan_zyx(math.pi + alpha_rad, -beta, 0.0), position_m
        )
    return make_transform(matrix_from_tait_bryan_zyx(alpha_rad, beta, 0.0), position_m)


def pose_error(T_est: np.ndarray, T_true: np.ndarray) -> tuple[float, float]:
    """(translation error in m, rotation error in rad) of an estimate against the truth."""
    delta = motion_between(T_true, T_est)
    return float(np.linalg.norm(delta[:3])), float(np.linalg.norm(delta[3:]))


LAYOUT = check_stator_points(example_stator_points())


@settings(max_examples=60, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2**32 - 1), retake=st.booleans(), facing=st.booleans())
def test_noise_free_random_pose_is_exact(seed: int, retake: bool, facing: bool) -> None:
    rng = np.random.default_rng(seed)
    position = rng.uniform([0.8, -0.5, 0.3], [1.4, 0.5, 1.0])
    T_prelim = nominal_pose(rng.uniform(-0.15, 0.15), position, robot_at_plus_x=facing)
    T_true = T_prelim @ random_transform(rng, 0.020, math.radians(3.0))
    probe = BoxProbe(T_true)
    res = run_stator_procedure(LAYOUT, T_prelim, probe, Hultman2013(retake_c_d=retake))
    dt, dr = pose_error(res.T_base_wobj, T_true)
    assert dt < 1e-9 and dr < 1e-9
    assert res.n_probes == (10 if retake else 8) == len(probe.calls)


def test_converges_from_worst_misplacement_commanded_in_wrong_frame() -> None:
    T_prelim = nominal_pose(0.0, (1.1, 0.0, 0.6))
    axis = np.array([1.0, -1.0, 1.0]) / math.sqrt(3.0)
    misplace = make_transform(matrix_from_rotvec(axis * math.radians(3.0)), 0.020 * axis)
    T_true = T_prelim @ misplace
    res = run_stator_procedure(example_stator_points(), T_prelim, BoxProbe(T_true))
    # the first searches went where the part is not: A and B land > 10 mm from their nominal
    for pid in "AB":
        miss = np.linalg.norm(res.measured_m[pid] - res.commands[pid].nominal_m)
        assert miss > 0.010
    start_dt, start_dr = pose_error(T_prelim, T_true)
    assert start_dt >= 0.019 and start_dr >= math.radians(2.99)
    errors = [pose_error(u.T_base_wobj, T_true) for u in res.updates]
    assert errors[-1][0] < 1e-9 and errors[-1][1] < 1e-9
    # later searches are commanded in the improved estimate: D2 lands on its nominal
    d2_miss = np.linalg.norm(res.measured_m["D2"] - res.commands["D2"].nominal_m)
    assert d2_miss < 1e-9


def test_steps_follow_the_paper(rng: np.random.Generator) -> None:
    T_prelim = nominal_pose(0.05, (1.0, 0.2, 0.7))
    T_true = T_prelim @ random_transform(rng, 0.015, math.radians(2.0))
    res = run_stator_procedure(LAYOUT, T_prelim, BoxProbe(T_true))
    assert [u.point_ids for u in res.updates] == [
        ("A", "B"), ("B",), ("C",), ("A", "B", "D", "E"), ("E",), ("H", "F", "D"),
        ("H",), ("C2",), ("D2",),
    ]  # fmt: skip
    assert list(res.measured_m) == ["A", "B", "C", "D", "E", "F", "G", "H", "C2", "D2"]
    R_true = T_true[:3, :3]
    # after A, B, D, E the x axis is the side-face normal exactly (all four lie on the face)
    np.testing.assert_allclose(res.updates[3].T_base_wobj[:3, 0], R_true[:, 0], atol=1e-12)
    # but y still follows A -> B, which was commanded in the wrong frame (rotation about x)
    assert np.linalg.norm(res.updates[3].T_base_wobj[:3, 1] - R_true[:, 1]) > 1e-6
    # the final rotation (H, F, D) is exact before any origin update
    np.testing.assert_allclose(res.updates[5].T_base_wobj[:3, :3], R_true, atol=1e-12)
    # each origin step moves the origin along one WOCS axis only
    for i, axis in ((1, 0), (2, 1), (4, 0), (6, 2), (7, 1), (8, 0)):
        before, after = res.updates[i - 1].T_base_wobj, res.updates[i].T_base_wobj
        shift_w = before[:3, :3].T @ (after[:3, 3] - before[:3, 3])
        assert np.all(np.abs(np.delete(shift_w, axis)) < 1e-12)
        np.testing.assert_array_equal(after[:3, :3], before[:3, :3])
    # the edge points lie on the true top edge, x = z = 0 in the true WOCS
    for pid in "FH":
        p_true = transform_points(invert_transform(T_true), res.measured_m[pid])
        assert abs(p_true[0]) < 1e-12 and abs(p_true[2]) < 1e-12
    # eq. 12's P3 lies 50 mm above B
    assert res.constructed_m["P3"][2] - res.measured_m["B"][2] == pytest.approx(0.050)


def test_faces_off_the_origin_are_handled() -> None:
    offset = np.array([-0.010, 0.020, -0.030])  # the WOCS origin is not at the box corner
    pts = {
        k: replace(p, position_m=tuple(np.asarray(p.position_m) + offset))
        for k, p in example_stator_points().items()
    }
    T_prelim = nominal_pose(-0.1, (1.2, 0.1, 0.5))
    T_true = T_prelim @ random_transform(np.random.default_rng(7), 0.02, math.radians(3.0))
    res = run_stator_procedure(pts, T_prelim, BoxProbe(T_true, offset_wobj=offset))
    dt, dr = pose_error(res.T_base_wobj, T_true)
    assert dt < 1e-9 and dr < 1e-9


def test_replayed_measurements_give_the_same_frame(rng: np.random.Generator) -> None:
    T_prelim = nominal_pose(0.0, (1.0, 0.0, 0.5))
    T_true = T_prelim @ random_transform(rng, 0.02, math.radians(3.0))
    first = run_stator_procedure(LAYOUT, T_prelim, BoxProbe(T_true))
    noisy = {k: v + rng.normal(0, 1e-4, 3) for k, v in first.measured_m.items()}
    again = run_stator_procedure(LAYOUT, T_prelim, probe_from_measurements(noisy))
    assert set(again.measured_m) == set(noisy)
    dt, dr = pose_error(again.T_base_wobj, T_true)
    assert 1e-6 < dt < 0.005 and 1e-6 < dr < math.radians(0.5)  # noise moves it, a little


@pytest.mark.parametrize("failing", ["A", "C", "F", "G", "C2", "D2"])
def test_probe_failure_names_the_point(failing: str) -> None:
    T = nominal_pose(0.0, (1.0, 0.0, 0.5))
    probe = BoxProbe(T, fail={failing})
    with pytest.raises(ProbeFailedError) as info:
        run_stator_procedure(LAYOUT, T, probe)
    assert info.value.point_id == failing
    assert info.value.reason == "sensor already detecting at start"
    assert probe.calls[-1] == failing


def test_search_that_misses_the_part_fails_with_reason() -> None:
    T_prelim = nominal_pose(0.0, (1.0, 0.0, 0.5))
    T_true = T_prelim @ make_transform(p=(0.0, 0.0, -0.15))  # part 150 mm lower: D hits air
    with pytest.raises(ProbeFailedError) as info:
        run_stator_procedure(LAYOUT, T_prelim, BoxProbe(T_true))
    assert info.value.point_id == "D" and "no detection" in info.value.reason


def test_missing_replayed_measurement_fails() -> None:
    T = nominal_pose(0.0, (1.0, 0.0, 0.5))
    full = run_stator_procedure(LAYOUT, T, BoxProbe(T)).measured_m
    partial = {k: v for k, v in full.items() if k != "D2"}
    with pytest.raises(ProbeFailedError, match="no measurement for 'D2'"):
        run_stator_procedure(LAYOUT, T, probe_from_measurements(partial))


def test_bad_probe_output_is_an_input_error() -> None:
    T = nominal_pose(0.0, (1.0, 0.0, 0.5))
    with pytest.raises(ShapeError, match="probe result for point A"):
        run_stator_procedure(LAYOUT, T, lambda cmd: ProbeResult(np.zeros(2)))
    with pytest.raises(ShapeError, match="probe must return a ProbeResult, got tuple for point A"):
        run_stator_procedure(LAYOUT, T, lambda cmd: (1.0, 2.0, 3.0))


def test_degenerate_measurements_raise() -> None:
    T = nominal_pose(0.0, (1.0, 0.0, 0.5))
    with pytest.raises(DegenerateGeometryError, match="A and B coincide"):
        run_stator_procedure(LAYOUT, T, lambda cmd: ProbeResult(np.ones(3)))


def test_bad_layout_raises_before_probing() -> None:
    pts = example_stator_points()
    pts["E"] = replace(pts["E"], position_m=(0.0, -0.1, -0.01))
    probe = BoxProbe(np.eye(4))
    with pytest.raises(DegenerateGeometryError, match="E lies below D"):
        run_stator_procedure(pts, np.eye(4), probe)
    assert probe.calls == []


def test_bad_preliminary_frame_raises() -> None:
    with pytest.raises(ShapeError, match="T_base_wobj_prelim"):
        run_stator_procedure(LAYOUT, np.eye(3), BoxProbe(np.eye(4)))


def test_edge_searches_can_start_from_measured_e_and_g(rng: np.random.Generator) -> None:
    T_prelim = nominal_pose(0.1, (1.0, -0.2, 0.8))
    T_true = T_prelim @ random_transform(rng, 0.02, math.radians(3.0))
    cfg = Hultman2013(edge_start_from_measured=True, edge_start_offset_m=0.003)
    res = run_stator_procedure(LAYOUT, T_prelim, BoxProbe(T_true), cfg)
    dt, dr = pose_error(res.T_base_wobj, T_true)
    assert dt < 1e-9 and dr < 1e-9
    T_f = res.commands["F"].T_base_wobj_estimate
    for edge, start in (("F", "E"), ("H", "G")):
        cmd = res.commands[edge]
        np.testing.assert_allclose(cmd.start_m, res.measured_m[start] + 0.003 * T_f[:3, 0])
        # the search still ends at the height where the plan's search ends
        plan = SearchCommand.from_point(LAYOUT.points[edge], T_f)
        end_cmd = cmd.start_m + cmd.length_m * cmd.direction
        end_plan = plan.start_m + plan.length_m * plan.direction
        assert cmd.direction @ (end_cmd - end_plan) == pytest.approx(0.0, abs=1e-12)
        assert np.linalg.norm(cmd.start_m - plan.start_m) > 0.002  # not the plan's start
        # the robot recorded its TCP 3 mm outside the face; the procedure moved it back
        raw_true = transform_points(invert_transform(T_true), res.measured_m[edge])
        assert raw_true[0] == pytest.approx(0.003, abs=1e-12)
        assert raw_true[2] == pytest.approx(0.0, abs=1e-12)


class LateEdgeProbe(BoxProbe):
    """A box probe whose sensor reports edges 3 mm past them along the search."""

    def __call__(self, cmd: SearchCommand) -> ProbeResult:
        res = super().__call__(cmd)
        if cmd.kind == "edge" and res.point_m is not None:
            return ProbeResult(res.point_m + 0.003 * cmd.direction, travel_m=res.travel_m + 0.003)
        return res


def test_known_edge_event_offset_is_removed(rng: np.random.Generator) -> None:
    T_prelim = nominal_pose(-0.05, (1.0, 0.3, 0.6))
    T_true = T_prelim @ random_transform(rng, 0.02, math.radians(3.0))
    late = run_stator_procedure(LAYOUT, T_prelim, LateEdgeProbe(T_true))
    dt, dr = pose_error(late.T_base_wobj, T_true)
    assert dt > 0.002  # uncorrected, the z origin is 3 mm off
    cfg = Hultman2013(edge_event_offset_m=0.003)
    fixed = run_stator_procedure(LAYOUT, T_prelim, LateEdgeProbe(T_true), cfg)
    dt, dr = pose_error(fixed.T_base_wobj, T_true)
    assert dt < 1e-9 and dr < 1e-9


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"beta1_rad": math.pi / 2}, "beta1_rad: must lie in"),
        ({"beta1_rad": float("nan")}, "beta1_rad: must lie in"),
        ({"p3_height_m": 0.0}, "p3_height_m: must be > 0"),
        ({"edge_start_offset_m": -0.001}, "edge_start_offset_m: must be >= 0"),
        ({"edge_event_offset_m": float("inf")}, "edge_event_offset_m: must be finite"),
    ],
)
def test_bad_settings_raise(kwargs, match) -> None:
    with pytest.raises(PlanError, match=match):
        Hultman2013(**kwargs)


def test_points_keyed_by_role_are_commanded_under_the_role() -> None:
    pts = {k: replace(p, id=f"plan_{k.lower()}") for k, p in example_stator_points().items()}
    T = nominal_pose(0.0, (1.0, 0.0, 0.5))
    probe = BoxProbe(T)
    res = run_stator_procedure(pts, T, probe)
    assert probe.calls == ["A", "B", "C", "D", "E", "F", "G", "H", "C2", "D2"]
    assert all(res.commands[k].point_id == k for k in res.commands)
    again = run_stator_procedure(pts, T, probe_from_measurements(res.measured_m))
    np.testing.assert_array_equal(again.T_base_wobj, res.T_base_wobj)


def test_result_and_layout_pickle_for_worker_processes() -> None:
    T = nominal_pose(0.0, (1.0, 0.0, 0.5))
    res = run_stator_procedure(LAYOUT, T, BoxProbe(T))
    back = pickle.loads(pickle.dumps(res))
    np.testing.assert_array_equal(back.T_base_wobj, res.T_base_wobj)
    assert list(back.measured_m) == list(res.measured_m)
    assert pickle.loads(pickle.dumps(LAYOUT)).face_coords_wobj == LAYOUT.face_coords_wobj
