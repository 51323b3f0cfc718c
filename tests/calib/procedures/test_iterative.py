"""The iterative best fit (calib.procedures.iterative): rounds until the frame settles."""

from __future__ import annotations

import numpy as np
import pytest

from calib.errors import PlanError, ShapeError
from calib.frames import make_transform, matrix_from_rotvec, motion_between
from calib.paper.stator_layout import example_stator_points
from calib.procedures import ITERATIVE, Iterative, RolePoint  # type: ignore[attr-defined]
from calib.procedures.iterative import run_iterative_fit
from tests.box_part import BoxProbe

T_NOM = make_transform(None, [1.0, 0.2, 0.5])
T_TRUE = T_NOM @ make_transform(matrix_from_rotvec([0.01, -0.02, 0.015]), [0.004, -0.006, 0.003])
#: The A-H layout without its edge searches, plus a top point (edge searches measured in the
#: nominal frame would start off the face).
PTS = [p for p in example_stator_points().values() if p.search.kind == "approach"]


def _top() -> list:  # type: ignore[type-arg]
    from calib.probing import ProbePoint, SearchSpec

    spec = SearchSpec("approach", 0.08, 0.08)
    return [
        ProbePoint("T1", (-0.05, -0.2, 0.0), (0.0, 0.0, 1.0), spec),
        ProbePoint("T2", (-0.05, -0.9, 0.0), (0.0, 0.0, 1.0), spec),
    ]


def test_two_rounds_when_misplaced_one_when_at_nominal() -> None:
    probe = BoxProbe(T_TRUE)
    res = run_iterative_fit(PTS + _top(), probe, T_NOM)
    n = len(PTS) + 2
    assert res.n_probes == 2 * n  # the first round moves the frame by mm, the second not at all
    assert np.abs(motion_between(T_TRUE, res.T_base_wobj)).max() < 1e-9
    at_nominal = run_iterative_fit(PTS + _top(), BoxProbe(T_NOM), T_NOM)
    assert at_nominal.n_probes == n


def test_max_rounds_ends_a_frame_that_keeps_moving() -> None:
    """With noise every round's fit moves by about the noise: a tolerance below it runs every
    round (and the last round's fit is returned)."""
    from calib.probing import ProbeResult

    box, rng = BoxProbe(T_TRUE), np.random.default_rng(0)

    def noisy(cmd):  # type: ignore[no-untyped-def]
        res = box(cmd)
        return ProbeResult(res.point_m + rng.normal(0.0, 1e-5, 3), travel_m=res.travel_m)

    res = run_iterative_fit(PTS + _top(), noisy, T_NOM, tolerance_m=1e-9, max_rounds=3)
    assert res.n_probes == 3 * (len(PTS) + 2)
    with pytest.raises(ShapeError, match="max_rounds"):
        run_iterative_fit(PTS, BoxProbe(T_TRUE), T_NOM, max_rounds=0)
    with pytest.raises(ShapeError, match="tolerance_m"):
        run_iterative_fit(PTS, BoxProbe(T_TRUE), T_NOM, tolerance_m=0.0)


def test_procedure_keys_every_rounds_measurement_and_estimates_from_the_last() -> None:
    pts = [RolePoint("fit", p) for p in PTS + _top()]
    run = ITERATIVE.run(pts, T_NOM, BoxProbe(T_TRUE), Iterative())
    assert "A" in run.measured_m and "A#2" in run.measured_m and "A#3" not in run.measured_m
    measured = {
        p.point.id: np.array([run.measured_m[p.point.id], run.measured_m[f"{p.point.id}#2"]])
        for p in pts
    }
    measured["A"][0] += 0.01  # the first round's value is not used
    again = ITERATIVE.estimate(pts, measured, T_NOM, Iterative())
    assert np.abs(motion_between(T_TRUE, again.T_base_wobj)).max() < 1e-9


def test_settings_are_checked() -> None:
    with pytest.raises(PlanError, match="tolerance_m"):
        Iterative(tolerance_m=-1.0)
    with pytest.raises(PlanError, match="max_rounds"):
        Iterative(max_rounds=0)
    assert ITERATIVE.role_problem(["fit", "fit"], complete=True).startswith(
        "points: iterative needs at least 3 points"
    )
