"""Tests of planner.calibrate: calibration from measured points with all three methods."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from calib.errors import InputError
from calib.frames import invert_transform, motion_between, random_transform, transform_points
from calib.plan.file import PlanError, load_plan
from calib.plan.measurements import Measurements, MeasurementsError
from calib.procedures.three_two_one import THREE_TWO_ONE, pick_roles
from planner.calibrate import calibrate_plan
from planner.plan_cell import nominal_T_base_wobj

REPO = Path(__file__).resolve().parent.parent
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"
SMALL = REPO / "tests" / "data" / "plans" / "valid_three_two_one.json"


def _measure(plan, T_true, units="m"):  # type: ignore[no-untyped-def]
    pts = {p.id: transform_points(T_true, p.position_m) for p in plan.points}
    return Measurements.from_points_m(pts, units=units)


@pytest.mark.parametrize("method", ["hultman2013", "three_two_one", "best_fit"])
@pytest.mark.parametrize("units", ["m", "mm"])
def test_known_motion_is_recovered(method: str, units: str, rng: np.random.Generator) -> None:
    plan = load_plan(STATOR)
    T_nom = nominal_T_base_wobj(plan)
    for _ in range(5):
        T_true = T_nom @ random_transform(rng, 0.010, np.radians(2.0))
        out = calibrate_plan(plan, _measure(plan, T_true, units), method)
        err = motion_between(T_true, out.T_base_wobj)
        assert np.abs(err).max() < 1e-6, err
        assert max(abs(r) for r in out.residuals_m.values()) < 1e-6
        assert out.method == method


@pytest.mark.parametrize("method", ["three_two_one", "best_fit"])
def test_small_plan_recovers_motion(method: str, rng: np.random.Generator) -> None:
    plan = load_plan(SMALL)
    T_true = nominal_T_base_wobj(plan) @ random_transform(rng, 0.02, np.radians(3.0))
    out = calibrate_plan(plan, _measure(plan, T_true), method)
    assert np.abs(motion_between(T_true, out.T_base_wobj)).max() < 1e-6


def test_hultman_needs_a_to_h_roles() -> None:
    plan = load_plan(SMALL)
    m = _measure(plan, nominal_T_base_wobj(plan))
    with pytest.raises(PlanError, match=r"hultman2013: points\[0\]\.role: must be one of"):
        calibrate_plan(plan, m, "hultman2013")


def test_unknown_method_and_missing_point() -> None:
    plan = load_plan(STATOR)
    m = _measure(plan, nominal_T_base_wobj(plan))
    with pytest.raises(InputError, match="method must be one of"):
        calibrate_plan(plan, m, "guess")
    partial = Measurements(
        points={k: v for k, v in m.points.items() if k != "E"}, failed={"E": "no detection"}
    )
    with pytest.raises(MeasurementsError, match=r"points\.E: not measured \(failed on the robot"):
        calibrate_plan(plan, partial, "hultman2013")
    out = calibrate_plan(plan, partial, "best_fit")  # 7 points still fix all 6 DOF
    assert out.skipped_ids == ("E",) and "E" not in out.used_ids


def test_world_frame_measurements_use_T_world_base(rng: np.random.Generator) -> None:
    import msgspec

    from calib.plan.file import Pose

    plan = load_plan(STATOR)
    T_world_base = random_transform(rng, 1.0, 1.0)
    robot = msgspec.structs.replace(plan.cell.robot, T_world_base=Pose.from_matrix(T_world_base))
    plan = msgspec.structs.replace(plan, cell=msgspec.structs.replace(plan.cell, robot=robot))
    T_nom = nominal_T_base_wobj(plan)
    np.testing.assert_allclose(
        T_nom, invert_transform(T_world_base) @ plan.work_object.T_world_wobj.matrix(), atol=1e-12
    )
    T_true = T_nom @ random_transform(rng, 0.01, 0.02)
    world = {p.id: list(transform_points(T_world_base @ T_true, p.position_m)) for p in plan.points}
    m = Measurements(frame="world", points={k: tuple(v) for k, v in world.items()})
    out = calibrate_plan(plan, m, "best_fit")
    assert np.abs(motion_between(T_true, out.T_base_wobj)).max() < 1e-6


def test_retakes_feed_c2_d2(rng: np.random.Generator) -> None:
    """The replay returns the retake for C2/D2: a retake off the face moves the result."""
    plan = load_plan(STATOR)
    T_nom = nominal_T_base_wobj(plan)
    m = _measure(plan, T_nom)
    exact = calibrate_plan(plan, m, "hultman2013").T_base_wobj
    c = np.array(m.points["D"]) + 0.001 * T_nom[:3, 0]  # 1 mm out of the side face
    moved = Measurements(points=m.points, retakes={"D": [tuple(c)]})
    T = calibrate_plan(plan, moved, "hultman2013").T_base_wobj
    shift = invert_transform(exact) @ T
    assert shift[0, 3] == pytest.approx(0.001, abs=1e-9)  # D2 fixes the final x origin


def test_three_two_one_roles_are_picked_from_faces() -> None:
    roles = pick_roles(load_plan(STATOR).role_points())
    ids = {r: [rp.point.id for rp in pts] for r, pts in roles.items()}
    assert len(ids["primary"]) == 3 and set(ids["primary"]) <= {"A", "B", "D", "E", "G"}
    assert set(ids["secondary"]) == {"F", "H"}  # the top face, found by the edge searches
    assert ids["tertiary"] == ["C"]
    small = THREE_TWO_ONE.assign(load_plan(SMALL).role_points())  # the plan's own roles
    assert [rp.point.id for rp in small if rp.role == "secondary"] == ["S1", "S2"]


def test_measured_point_not_in_plan_is_an_error() -> None:
    plan = load_plan(STATOR)
    m = _measure(plan, nominal_T_base_wobj(plan))
    extra = Measurements(points={**m.points, "Z": (1.0, 2.0, 3.0)})
    with pytest.raises(InputError, match=r"points \['Z'\] are not in the plan"):
        calibrate_plan(plan, extra, "best_fit")
