"""Layout quality (planner.sim.quality through planner.check.job.plan_quality): real numbers on
the shipped plate plans, a weak layout named as such, a free degree of freedom refused."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import msgspec
import numpy as np
import pytest

from calib.estimators.layout import constraint_jacobian
from calib.plan.file import Plan, load_plan
from planner.check.job import plan_quality
from planner.check.simulatable import check_simulatable, work_object_mesh

PLANS = Path(__file__).resolve().parents[3] / "assets" / "plans"


@pytest.fixture(scope="module")
def plate(reference_dir: Path) -> tuple[Plan, Plan, object]:
    p321 = load_plan(PLANS / "plate_holes_321.json")
    best = load_plan(PLANS / "plate_holes_best_fit.json")
    mesh = work_object_mesh(p321, PLANS, check_simulatable(p321))
    return p321, best, mesh


def _moved(plan: Plan, index: int, position_m: tuple[float, float, float]) -> Plan:
    pts = list(plan.points)
    pts[index] = msgspec.structs.replace(pts[index], position_m=position_m)
    return msgspec.structs.replace(plan, points=pts)


def test_least_squares_closed_form_is_the_linearised_procedure(plate: tuple) -> None:
    """The quality's fast path for the best fit (``(A^T W A)^-1``) equals the procedure
    linearised by :func:`planner.sim.predict.predict`, run by run (the one definition)."""
    from planner.sim.predict import predict
    from planner.sim.quality import least_squares_covariance

    _, best, mesh = plate
    q, note = plan_quality(best, mesh)
    assert q is not None, note
    setup = _setup(best)
    closed = least_squares_covariance(setup)
    assert closed is not None
    np.testing.assert_allclose(q.covariance, closed, rtol=0, atol=0)  # the fast path ran
    linearised = predict(setup).cov_procedure
    np.testing.assert_allclose(closed, linearised, rtol=1e-4, atol=1e-16)
    P = np.array([p.position_m for p in best.points])
    N = np.array([p.normal for p in best.points])
    J = constraint_jacobian(N, P)  # and it is var (J^T J)^-1
    np.testing.assert_allclose(
        closed, q.noise_sigma_m**2 * np.linalg.inv(J.T @ J), rtol=1e-9, atol=1e-18
    )
    assert q.rating == "ok" and q.problem == ""
    # no fast path for a shared TCP error, nor for another procedure
    import dataclasses

    tcp = msgspec.structs.replace(setup.robot_error, tcp_sigma_m=1e-5)
    assert least_squares_covariance(dataclasses.replace(setup, robot_error=tcp)) is None
    # 3-2-1: six constraints solved exactly, the same closed form
    s321 = _setup(plate[0])
    closed = least_squares_covariance(s321)
    assert closed is not None
    np.testing.assert_allclose(closed, predict(s321).cov_procedure, rtol=1e-6, atol=1e-16)


def _setup(plan: Plan) -> Any:
    from planner.validate.job import prediction_setup

    return prediction_setup(plan, check_simulatable(plan))


def test_poi_half_width_is_the_validation_reports_prediction(plate: tuple) -> None:
    """The quality's error at the point of interest is the number ``wobjcal validate`` puts
    in its predicted column (one definition)."""
    from planner.validate.job import validate_plan

    p321, _, mesh = plate
    q, _ = plan_quality(p321, mesh)
    assert q is not None
    report = validate_plan(p321, trials=4, seed=1, workers=1, plan_dir=PLANS, mesh=mesh)
    (poi,) = q.poi
    for level, half in zip(poi.levels_percent, poi.half_width_m, strict=True):
        (row,) = [r for r in report.rows if r.key == poi.key and r.level_percent == level]
        assert row.procedure_predicted == pytest.approx(half * 1e3, rel=1e-9)
        assert poi.at(level) == pytest.approx(half, rel=1e-12)


def test_close_secondary_points_make_a_weak_layout_named_in_words(plate: tuple) -> None:
    """The issue's case: 3-2-1 with its two secondary points 5 mm apart. The rotation about
    the primary normal (wobj z) is barely held: weak, and the error at the far corner grows
    by more than an order of magnitude."""
    p321, _, mesh = plate
    good, _ = plan_quality(p321, mesh)
    s1 = p321.points[3].position_m
    weak_plan = _moved(p321, 4, (s1[0], s1[1] + 0.005, s1[2]))
    weak, _ = plan_quality(weak_plan, mesh)
    assert good is not None and weak is not None
    assert good.rating == "ok" and weak.rating == "weak"
    assert weak.noise_gain > 10.0 > good.noise_gain
    assert weak.weakest.startswith("rotation about an axis along wobj z")
    assert weak.weakest_unit == "deg" and weak.weakest_amount > 1.0  # deg per 0.1 mm
    assert "weak layout" in weak.problem and "per 0.1 mm" in weak.problem
    # the weakest motion carries the largest rotation sigma: about z
    assert int(np.argmax(weak.sigma[3:])) == 2
    assert weak.poi[0].half_width_m[0] > 10 * good.poi[0].half_width_m[0]


def test_one_face_only_leaves_motions_free(plate: tuple) -> None:
    _, best, mesh = plate
    top = [p for p in best.points if p.normal[2] > 0.5]
    plan = msgspec.structs.replace(best, points=top)
    q, _ = plan_quality(plan, mesh)
    assert q is not None and q.rating == "unobservable"
    assert "6 degrees of freedom" in q.problem
    assert any("translation along wobj x" in f for f in q.free)
    assert math.isinf(q.noise_gain)


@pytest.mark.slow
def test_check_cli_shows_quality_marginal_and_fails_free_layout(
    plate: tuple, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from calib.plan.file import save_plan
    from planner.cli.main import main

    p321, best, _ = plate
    s1 = p321.points[3].position_m
    weak = _moved(p321, 4, (s1[0], s1[1] + 0.005, s1[2]))
    ref = str(PLANS.resolve() / p321.work_object.mesh)
    wo = msgspec.structs.replace(p321.work_object, mesh=ref)
    save_plan(msgspec.structs.replace(weak, work_object=wo), tmp_path / "weak.json")
    assert main(["check", str(tmp_path / "weak.json"), "--json"]) == 0  # marginal passes
    out = json.loads(capsys.readouterr().out)
    assert out["layout_status"] == "marginal"
    assert out["quality"]["rating"] == "weak"
    assert "rotation about an axis along wobj z" in out["quality"]["weakest"]
    assert out["quality"]["points_of_interest"][0]["half_width_mm"][0] > 0.5
    assert main(["check", str(tmp_path / "weak.json")]) == 0
    text = capsys.readouterr().out
    assert "layout quality" in text and "marginal" in text and "per 0.1 mm" in text

    top = [p for p in best.points if p.normal[2] > 0.5]
    free = msgspec.structs.replace(best, points=top, work_object=wo)
    save_plan(free, tmp_path / "free.json")
    assert main(["check", str(tmp_path / "free.json"), "--json"]) == 1
    out = json.loads(capsys.readouterr().out)
    assert out["layout_status"] == "infeasible" and out["layout"]
