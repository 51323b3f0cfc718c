"""Tests of planner.calibrate.job: calibration from measured points with all three methods."""

from __future__ import annotations

from pathlib import Path

import msgspec
import numpy as np
import pytest

from calib.errors import InputError
from calib.frames import invert_transform, motion_between, random_transform, transform_points
from calib.plan.file import PlanError, load_plan
from calib.plan.measurements import Measurements, MeasurementsError
from calib.procedures.three_two_one import THREE_TWO_ONE, pick_roles
from planner.calibrate.job import calibrate_plan
from planner.plan_cell import nominal_T_base_wobj

REPO = Path(__file__).resolve().parents[3]
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"
SMALL = REPO / "tests" / "data" / "plans" / "valid_three_two_one.json"


def _ideal_stator():  # type: ignore[no-untyped-def]
    """The shipped stator plan with an ideal sensor: its edge-event offset measured as 0 (unset,
    every face would take the sensor model's 6.3 mm), so exact points recover the motion."""
    plan = load_plan(STATOR)
    return msgspec.structs.replace(
        plan, procedure=msgspec.structs.replace(plan.procedure, edge_event_offset_m=0.0)
    )


def _ideal_small():  # type: ignore[no-untyped-def]
    """The small 3-2-1 test plan (its tertiary point an edge search) with an ideal sensor."""
    plan = load_plan(SMALL)
    return msgspec.structs.replace(
        plan, procedure=msgspec.structs.replace(plan.procedure, edge_event_offset_m=0.0)
    )


def _measure(plan, T_true, units="m"):  # type: ignore[no-untyped-def]
    pts = {p.id: transform_points(T_true, p.position_m) for p in plan.points}
    return Measurements.from_points_m(pts, units=units)


@pytest.mark.slow
@pytest.mark.parametrize("method", ["hultman2013", "three_two_one", "best_fit"])
@pytest.mark.parametrize("units", ["m", "mm"])
def test_known_motion_is_recovered(method: str, units: str, rng: np.random.Generator) -> None:
    plan = _ideal_stator()
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
    plan = _ideal_small()
    T_true = nominal_T_base_wobj(plan) @ random_transform(rng, 0.02, np.radians(3.0))
    out = calibrate_plan(plan, _measure(plan, T_true), method)
    assert np.abs(motion_between(T_true, out.T_base_wobj)).max() < 1e-6


def test_hultman_needs_a_to_h_roles() -> None:
    plan = load_plan(SMALL)
    m = _measure(plan, nominal_T_base_wobj(plan))
    with pytest.raises(PlanError, match=r"hultman2013: points\[0\]\.role: must be one of"):
        calibrate_plan(plan, m, "hultman2013")


def test_unknown_method_and_missing_point() -> None:
    plan = _ideal_stator()
    m = _measure(plan, nominal_T_base_wobj(plan))
    with pytest.raises(
        InputError, match=r"unknown procedure \(--method\) '.*'; known: best_fit, hultman2013"
    ):
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

    plan = _ideal_stator()
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
    plan = _ideal_stator()
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
    plan = _ideal_stator()
    m = _measure(plan, nominal_T_base_wobj(plan))
    extra = Measurements(points={**m.points, "Z": (1.0, 2.0, 3.0)})
    with pytest.raises(InputError, match=r"points \['Z'\] are not in the plan"):
        calibrate_plan(plan, extra, "best_fit")


# ---- gross errors, misplacement bound, covariance (issue 10, item 1) -----------------------
def _measure_off(plan, T, point_id: str, offset_wobj):  # type: ignore[no-untyped-def]
    """Exact measurements at ``T`` with one point moved by ``offset_wobj`` (wobj frame, m)."""
    pts = {}
    for p in plan.points:
        x = np.asarray(p.position_m) + (np.asarray(offset_wobj) if p.id == point_id else 0.0)
        pts[p.id] = transform_points(T, x)
    return Measurements.from_points_m(pts, units="mm")


def test_a_point_10_mm_off_is_flagged_and_named() -> None:
    """Item 1: D 10 mm off along wobj x gave a frame 17 deg off, trusted. Now: D is named."""
    plan = _ideal_stator()
    out = calibrate_plan(plan, _measure_off(plan, nominal_T_base_wobj(plan), "D", (0.01, 0, 0)))
    assert not out.trusted
    assert out.screen is not None and out.screen.remeasure == ("D",)
    assert "D" in out.screen.flagged
    text = " ".join(out.problems)
    assert "re-measure D" in text and "D lies 10.000 mm off its face" in text
    assert "max_angle_rad" in text  # 17 deg is beyond the plan's 3 deg misplacement


def test_a_point_1_m_off_is_named_with_best_fit() -> None:
    plan = _ideal_stator()
    out = calibrate_plan(
        plan, _measure_off(plan, nominal_T_base_wobj(plan), "G", (1.0, 0, 0)), "best_fit"
    )
    assert not out.trusted and out.screen is not None
    assert out.screen.remeasure == ("G",)


@pytest.mark.slow
@pytest.mark.parametrize("method", ["hultman2013", "three_two_one", "best_fit"])
def test_noise_the_plan_expects_is_not_flagged(method: str, rng: np.random.Generator) -> None:
    """No false alarm: 25 calibrations with Gaussian noise at the plan's sensor and robot
    sigma plus 0.1 mm of face flatness, part misplaced within the plan's bound."""
    from planner.calibrate.job import expected_sigma_m

    plan = _ideal_stator()
    T_nom = nominal_T_base_wobj(plan)
    sigma = expected_sigma_m(plan)
    pivot = np.mean([p.position_m for p in plan.points], axis=0)
    for _ in range(25):
        T_true = T_nom @ plan.validation.misplacement.sample(rng, pivot)
        pts = {
            p.id: transform_points(T_true, p.position_m) + rng.normal(0, sigma, 3)
            for p in plan.points
        }
        out = calibrate_plan(plan, Measurements.from_points_m(pts), method)
        assert out.trusted, out.problems


@pytest.mark.slow
def test_simulated_calibrations_of_the_bulged_stator_are_trusted() -> None:
    """No false alarm on realistic data: the simulated sensor (ray bundle), robot errors and
    the bolted stator's bulged side face of `wobjcal validate`, 12 trials."""
    from planner.sim.trial import TrialRunner
    from planner.validate.job import simulation_setup, validation_models, work_object_mesh

    plan = load_plan(STATOR)
    from planner.program import execute

    m = validation_models(plan)
    part = work_object_mesh(plan, STATOR.parent, m)
    setup = simulation_setup(plan, m, part)
    runner = TrialRunner(setup, part)
    T_nom = setup.T_base_wobj_nominal
    # the plan's procedure with the sensor's edge-event offset, as a cell would measure it
    import msgspec

    plan = msgspec.structs.replace(plan, procedure=m.settings)
    for seed in np.random.SeedSequence(11).spawn(12):
        r = np.random.default_rng(seed)
        T_true = T_nom @ m.misplacement.sample(r, setup.pivot_wobj_m)
        probe = runner.simulator(
            runner.caster, T_true, r, sensor=m.sensor, robot_error=m.robot_error,
            faces=setup.faces, edge_inset_m=m.edge_inset_m,
        )  # fmt: skip
        res = execute(setup.program, T_nom, probe)  # what the exported RAPID program runs
        first = {k: v for k, v in res.measured_m.items() if "#" not in k}
        meas = Measurements.from_points_m(first)
        retakes = {k[:-2]: [tuple(v)] for k, v in res.measured_m.items() if k.endswith("#2")}
        assert len(first) == 8 and len(retakes) == 2  # A-H, C and D retaken
        meas = msgspec.structs.replace(meas, retakes=retakes)
        out = calibrate_plan(plan, meas)
        assert out.trusted, out.problems
        assert np.abs(motion_between(T_true, out.T_base_wobj)[:3]).max() < 2e-3


def test_six_points_have_no_redundancy_and_say_so() -> None:
    """A plain 3-2-1 (6 constraints) cannot see a gross error: said as a note, not hidden;
    the small plan's edge point adds one constraint: a misfit shows but cannot be located."""
    import msgspec

    from calib.plan.file import PlanPoint

    small = load_plan(SMALL)
    top = PlanPoint(id="T1", role="tertiary", position_m=(-0.05, -0.6, 0.0), normal=(0, 0, 1.0))
    plan = msgspec.structs.replace(small, points=[*small.points[:5], top])
    out = calibrate_plan(plan, _measure(plan, nominal_T_base_wobj(plan)), "three_two_one")
    assert out.trusted and out.screen is not None and out.screen.redundancy == 0
    assert any("no redundancy" in n for n in out.notes)
    moved = _measure_off(small, nominal_T_base_wobj(small), "P3", (0.005, 0, 0))
    off = calibrate_plan(small, moved)
    assert not off.trusted and off.screen is not None and off.screen.redundancy == 1
    assert off.screen.remeasure == () and "only 1 redundant constraint" in " ".join(off.problems)


def test_propagated_covariance_matches_best_fit_and_monte_carlo(rng: np.random.Generator) -> None:
    """The covariance propagated through `estimate` equals best_fit's analytic one (F and H,
    edge searches, counted by their edge coordinate only, as the procedure fits them), and for
    the A-H procedure it matches the scatter of 300 noisy replays within 20 %."""
    from calib.estimators.best_fit import best_fit
    from calib.estimators.layout import search_constraint_set
    from calib.procedures import procedure_kind
    from calib.procedures.uncertainty import propagated_covariance

    plan = _ideal_stator()
    T_nom = nominal_T_base_wobj(plan)
    points = plan.role_points()
    exact = {p.id: transform_points(T_nom, p.position_m)[None] for p in plan.points}
    sigma = 1e-4
    kind = procedure_kind("best_fit")
    cov = propagated_covariance(kind, points, exact, T_nom, None, sigma)
    cs = search_constraint_set([rp.point for rp in points])
    fit = best_fit(cs, np.array([exact[i][0] for i in cs.point_ids]), T_nom)
    np.testing.assert_allclose(cov, sigma**2 * fit.unit_covariance, rtol=1e-4, atol=1e-16)

    ah = procedure_kind("hultman2013")
    cov_ah = propagated_covariance(ah, points, exact, T_nom, plan.procedure, sigma)
    deltas = []
    for _ in range(300):
        noisy = {k: v + rng.normal(0, sigma, v.shape) for k, v in exact.items()}
        T = ah.estimate(points, noisy, T_nom, plan.procedure).T_base_wobj
        deltas.append(motion_between(T_nom, T))
    sample = np.cov(np.array(deltas).T)
    np.testing.assert_allclose(np.diag(sample), np.diag(cov_ah), rtol=0.2)


def test_absurd_coordinates_are_refused_naming_the_point() -> None:
    from calib.plan.measurements import measurements_from_json

    doc = '{"schema": "wobjcal.measurements/1", "units": "mm", "points": {"A": [1e308, 0, 0]}}'
    with pytest.raises(MeasurementsError, match=r"points\.A\[0\]: 1e\+308 mm is not a plausible"):
        measurements_from_json(doc)
    for literal in ("NaN", "Infinity", "1e999"):
        doc = f'{{"schema": "wobjcal.measurements/1", "points": {{"B": [0, {literal}, 0]}}}}'
        with pytest.raises(MeasurementsError, match=r"points\.B"):
            measurements_from_json(doc)


def test_absurd_plan_position_is_refused_naming_the_path() -> None:
    import json

    from calib.plan.file import plan_from_json

    doc = json.loads(STATOR.read_text())
    doc["points"][2]["position_m"][1] = 1e308
    with pytest.raises(PlanError, match=r"points\[2\]\.position_m: 1e\+308 m is not a plausible"):
        plan_from_json(json.dumps(doc))


@pytest.mark.slow
def test_a_nominal_best_fit_with_edge_searches_is_trusted_when_exact(
    rng: np.random.Generator,
) -> None:
    """The stator's points as a best fit run by its nominal program (every search in the
    nominal frame): F's and H's recorded points lie on their commanded tracks, off the true
    side face by up to a millimetre, which the fit does not count. Neither may the gross-error
    screen: on an ideal part every calibration is exact and trusted (the screen once fitted
    those commanded coordinates, flagged D and called 16 of 40 exact frames untrusted)."""
    from calib.plane_probe import PlaneProbe
    from calib.procedures import BestFit
    from planner.program import measuring_program
    from planner.program.execute import execute

    stator = load_plan(STATOR)
    plan = msgspec.structs.replace(
        stator,
        procedure=BestFit(edge_event_offset_m=0.0),
        points=[msgspec.structs.replace(p, role="fit") for p in stator.points],
    )
    program = measuring_program(plan, None)
    assert not program.adaptive and not program.steers_itself  # edge searches: nominal
    T_nom = nominal_T_base_wobj(plan)
    bound = plan.validation.misplacement
    pivot = np.mean([p.position_m for p in plan.points], axis=0)
    for _ in range(12):
        T_true = T_nom @ bound.sample(rng, pivot)  # anywhere the plan's bound lets the part lie
        run = execute(program, T_nom, PlaneProbe(T_true))
        out = calibrate_plan(plan, Measurements.from_points_m(run.measured_m))
        assert np.abs(motion_between(T_true, out.T_base_wobj)).max() < 1e-9
        assert out.screen.flagged == () and out.problems == (), out.problems
