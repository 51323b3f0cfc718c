"""Landing risk (``planner.sim.landing``) and search reach (``planner.program.reach``): what
``wobjcal check`` and export judge of a program, against what the validation simulates on the
real mesh, and one verdict for check and validate."""

from __future__ import annotations

from pathlib import Path

import msgspec
import numpy as np
import pytest

from calib.models.proximity import ProximitySensor
from calib.plan.file import Plan, PlanError, load_plan
from calib.probing import ProbePoint, SearchSpec
from planner.check.job import plan_landing_risk
from planner.program.build import safety_spec
from planner.program.reach import search_problems
from planner.validate.job import check_simulatable, preflight, validate_plan, work_object_mesh

PLANS = Path(__file__).resolve().parents[3] / "assets" / "plans"
PLATE_321 = PLANS / "plate_holes_321.json"
STATOR = PLANS / "stator_section_ah.json"


def _mesh(plan: Plan):  # type: ignore[no-untyped-def]
    return work_object_mesh(plan, PLANS, check_simulatable(plan))


@pytest.mark.reference
@pytest.mark.slow
def test_a_nominal_program_on_narrow_faces_is_flagged_the_adaptive_one_is_not() -> None:
    """The plate's 3-2-1: its secondary and tertiary points sit on 12.7 mm side faces. Measured
    after the primary face has fixed height and tilts (RAPID) they land on them; measured in
    the nominal frame under 3 mm / 1 deg (FANUC TP) some land off, and those points are named."""
    plan = load_plan(PLATE_321)
    mesh = _mesh(plan)
    rapid = plan_landing_risk(plan, mesh, "rapid")
    tp = plan_landing_risk(plan, mesh, "fanuc")
    assert rapid is not None and tp is not None
    assert rapid.failed == 0.0 and rapid.point_problems() == {}
    assert tp.program == "TP, nominal 3-2-1" and tp.failed > 0.05
    problems = tp.point_problems()
    assert set(problems) == {"S1", "S2", "T1"}
    for w in problems.values():
        assert w.kind == "search" and "lands off its face" in w.text
        assert "adaptive program" in w.text
    # deterministic: the same seed gives the same shares
    again = plan_landing_risk(plan, mesh, "fanuc")
    assert again is not None and again.searches == tp.searches


@pytest.mark.slow
def test_the_risk_is_what_the_validation_simulates_on_the_real_mesh() -> None:
    """The share of calibrations in which D, E and G of the stator's nominal (FANUC TP) A-H program
    land over a slot hole, from the ideal part's planes and the faces' outlines, is the share
    the Monte Carlo on the real mesh counts as landed off its face (within sampling error)."""
    plan = load_plan(STATOR)
    risk = plan_landing_risk(plan, _mesh(plan), "fanuc")
    assert risk is not None
    report = validate_plan(plan, trials=120, seed=4, workers=1, plan_dir=PLANS, fmt="fanuc")
    simulated = {o.point_id: o.landed_off / o.searches for o in report.outcomes}
    for s in risk.searches:
        if s.key in ("D", "E", "G"):
            # 128 vs 120 samples of a share near 0.25: about four sigma of the difference is 0.15
            assert s.off_face == pytest.approx(simulated[s.key], abs=0.15), s
            assert s.off_face > 0.1
    assert set(risk.point_problems()) >= {"D", "E", "G"}
    # the adaptive program aims them after A, B and C: on the teeth
    rapid = plan_landing_risk(plan, _mesh(plan), "rapid")
    assert rapid is not None and rapid.point_problems() == {}


def test_a_kept_risk_is_of_the_same_sensor_and_the_same_part(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The landing risks kept between checks: a part loaded again (another mesh object, the
    same content) gets the kept risk without running the program again; a wider sensor face on
    the same mesh object (a UI edit of the sensor) gets its own, the one computed afresh."""
    from planner.check import job
    from planner.sim import landing

    plan = load_plan(STATOR)
    runs = []
    real = landing.landing_risk
    monkeypatch.setattr(landing, "landing_risk", lambda *a, **k: runs.append(1) or real(*a, **k))
    job._RISKS.clear()
    first = plan_landing_risk(plan, _mesh(plan))
    again = plan_landing_risk(plan, _mesh(plan))
    assert first is not None and again is first and len(runs) == 1
    sensor = plan.validation.sensor
    assert isinstance(sensor, ProximitySensor)
    wide = msgspec.structs.replace(sensor, face_diameter_m=3 * sensor.face_diameter_m)
    wider = msgspec.structs.replace(
        plan, validation=msgspec.structs.replace(plan.validation, sensor=wide)
    )
    mesh = _mesh(plan)
    kept = plan_landing_risk(wider, mesh)
    job._RISKS.clear()
    fresh = plan_landing_risk(wider, mesh)
    assert kept is not None and fresh is not None and len(runs) == 3
    assert kept.searches == fresh.searches
    assert kept.failed > first.failed  # the wide face meets the teeth: a different answer


@pytest.mark.reference
def test_search_reach_names_every_problem_of_every_point_at_once() -> None:
    plan = load_plan(PLATE_321)
    safety = safety_spec(plan)
    short = SearchSpec("approach", start_offset_m=0.001, overtravel_m=0.0005)
    edge = SearchSpec("edge", 0.0005, 0.0005, edge_direction=(1.0, 0.0, 0.0))
    pts = [
        ProbePoint("A", (0.05, 0.05, 0.0127), (0.0, 0.0, 1.0), short),
        ProbePoint("B", (0.1, 0.05, 0.0127), (0.0, 0.0, 1.0), edge),
        ProbePoint("C", (0.1, 0.1, 0.0127), (0.0, 0.0, 1.0)),  # 30 mm start, 20 mm overtravel
    ]
    why = search_problems(pts, safety, edge_offset_m=0.002)
    assert set(why) == {"A", "B"} and {w.kind for w in why.values()} == {"search"}
    a, b = why["A"].text, why["B"].text
    assert "ends 0.5 mm past the nominal face" in a
    assert "starts 0.5 mm before" in b and "ends 0.5 mm past the nominal edge" in b
    assert "2.0 mm past it" in b


@pytest.mark.reference
@pytest.mark.parametrize("overtravel_mm", [1.0, 3.9, 4.2, 20.0])
def test_check_and_validate_refuse_the_same_short_searches(overtravel_mm: float) -> None:
    """One rule: a search too short for the misplacement fails check's reach and validate's
    preflight alike (and a long enough one passes both)."""
    plan = load_plan(PLATE_321)
    p0 = plan.points[0]
    search = msgspec.structs.replace(p0.search, overtravel_m=overtravel_mm / 1000.0)
    pts = (msgspec.structs.replace(p0, search=search), *plan.points[1:])
    plan = msgspec.structs.replace(plan, points=pts)
    models = check_simulatable(plan)
    reach = search_problems([p.to_probe_point() for p in plan.points], safety_spec(plan))
    if reach:
        assert set(reach) == {p0.id}
        with pytest.raises(PlanError, match=rf"\({p0.id}\): the search ends"):
            preflight(plan, models, _mesh(plan))
    else:
        preflight(plan, models, _mesh(plan))
    # the bound, worked out here: 3 mm plus 1 deg about the points' centroid, along the normal
    c = np.mean([p.position_m for p in plan.points], axis=0)
    lever = float(np.linalg.norm(np.asarray(p0.position_m) - c))
    shift = (0.003 + lever * np.radians(1.0)) / np.cos(np.radians(1.0))
    assert 4.0e-3 < shift < 4.1e-3
    assert bool(reach) == (overtravel_mm / 1000.0 < shift)
