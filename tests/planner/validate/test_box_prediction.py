"""On an ideal box, every estimator's simulated intervals agree with the predicted ones.

A box has nothing that depends on where the misplaced part puts a search (no hole, no bulge,
flat faces), so the Monte Carlo of the full simulation (ray-cast sensor, robot noise, 20 mm and
3 deg misplacement, the procedure commanding each search in its estimate so far) and the
linearised procedure with the same noise figures must give the same intervals, up to the
Monte Carlo's own scatter: with n trials a standard deviation is known to about
1 / sqrt(2 n) (2.5 % for 800). The A-H plan uses a point sensor here (its edge event is the
edge itself, the exact disk's limit; the bench runs the 18 mm face with 16,384 rays and
10,000 trials: ``python -m bench.bench_validate``)."""

from __future__ import annotations

import pytest

from bench.box_plans import POINT_SENSOR, agreement, box_mesh, box_plans
from planner.validate.job import validate_plan

TRIALS = 800
#: Three standard errors of a standard deviation from TRIALS trials.
TOL = 3.0 / (2 * TRIALS) ** 0.5


@pytest.fixture(scope="module")
def mesh():  # type: ignore[no-untyped-def]
    return box_mesh()


@pytest.mark.slow
@pytest.mark.parametrize("method", ["hultman2013", "three_two_one", "best_fit", "iterative"])
def test_simulated_equals_predicted_on_a_box(method: str, mesh) -> None:  # type: ignore[no-untyped-def]
    plan = box_plans(POINT_SENSOR)[method]
    report = validate_plan(plan, trials=TRIALS, seed=21, mesh=mesh)
    assert report.n_ok == TRIALS, report.failures
    rel = agreement(report)
    assert set(rel) >= {"origin_x", "origin_y", "origin_z", "rot_x", "rot_y", "rot_z", "xyz_far"}
    bad = {k: round(v, 3) for k, v in rel.items() if abs(v) > TOL}
    assert not bad, f"simulated / predicted - 1 beyond {TOL:.3f}: {bad}"
    # nothing position-dependent: no landing over a hole or an edge, no failure
    assert not report.landings and not report.failures
