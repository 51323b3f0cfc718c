"""The live layout quality's speed-ups leave its numbers as they were (issue 13).

``planner.check.job.plan_quality`` of an A-H plan linearises the whole A-H run by central
differences (21 runs of the procedure). Four cuts made it faster (24.4 -> 13.1 ms of CPU per
change): the best fit is no longer linearised beside it when only the procedure's covariance is
wanted, a search command for one frame is built with one product per kind of vector, the ideal
plane probe moves the estimate onto the true part without a general 4x4 inverse, and the A-H
layout is validated once per set of points. Each is checked here against the slow way,
computed in the test.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import msgspec
import numpy as np
import pytest

from calib.frames import invert_transform, transform_directions, transform_points
from calib.plan.file import Plan, load_plan
from calib.plane_probe import PlaneProbe
from calib.probing import Probe, ProbePoint, ProbeResult, SearchCommand, SearchSpec
from calib.procedures import procedure_kind
from calib.procedures.linearize import RunFunction, linearize
from planner.check.job import plan_quality
from planner.check.simulatable import check_simulatable, work_object_mesh
from planner.sim.setup import SimulationSetup
from planner.validate.job import prediction_setup

PLANS = Path(__file__).resolve().parents[3] / "assets" / "plans"


@pytest.fixture(scope="module")
def ah() -> Plan:
    return load_plan(PLANS / "stator_section_ah.json")


def _setup(plan: Plan) -> SimulationSetup:
    return prediction_setup(plan, check_simulatable(plan))


def _moved(plan: Plan, index: int, shift_m: np.ndarray) -> Plan:
    pts = list(plan.points)
    p = np.asarray(pts[index].position_m) + shift_m
    pts[index] = msgspec.structs.replace(pts[index], position_m=tuple(float(c) for c in p))
    return msgspec.structs.replace(plan, points=pts)


@dataclass
class _SlowPlaneProbe(PlaneProbe):
    """The plane probe as it was: the estimate moved onto the part by a general 4x4 inverse."""

    def __call__(self, cmd: SearchCommand) -> ProbeResult:
        j = len(self.commands)
        self.commands.append(cmd)
        d = np.asarray(cmd.direction, dtype=np.float64)
        stop = -d if cmd.stop_normal is None else np.asarray(cmd.stop_normal, dtype=np.float64)
        T_move = self.T_base_wobj_true @ invert_transform(cmd.T_base_wobj_estimate)
        p = T_move[:3, :3] @ np.asarray(cmd.nominal_m, dtype=np.float64) + T_move[:3, 3]
        m = T_move[:3, :3] @ stop
        start = np.asarray(cmd.start_m, dtype=np.float64)
        t = float((p - start) @ m) / float(d @ m)
        if cmd.kind == "edge":
            face_n = -(T_move[:3, :3] @ np.asarray(cmd.sensor_axis, dtype=np.float64))
            t += self.edge_offset_m + self.edge_axis_gain * -float((start + t * d - p) @ face_n)
        t += float(self.eps.get(j, 0.0))
        return ProbeResult(start + t * d, travel_m=t)


def test_search_command_of_one_frame_is_the_general_transform() -> None:
    """The one-frame path of ``SearchCommand.from_point`` equals the batched (einsum) one."""
    rng = np.random.default_rng(5)
    from calib.frames import random_transform

    for spec, normal, edge_normal in [
        (SearchSpec("approach"), (0.0, 0.6, 0.8), None),
        (SearchSpec("edge", edge_direction=(0.0, 0.0, 1.0)), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    ]:
        point = ProbePoint("P", (0.1, -0.2, 0.05), normal, spec, edge_normal)
        T = random_transform(rng, 0.5, np.pi)
        one = SearchCommand.from_point(point, T)
        batch = SearchCommand.from_point(point, T[None])  # (1, 4, 4): the general path
        for name in ("start_m", "direction", "sensor_axis", "nominal_m", "stop_normal"):
            np.testing.assert_allclose(getattr(one, name), getattr(batch, name)[0], atol=1e-15)
        n = np.asarray(normal)
        np.testing.assert_allclose(one.sensor_axis, transform_directions(T, -n), atol=1e-15)
        np.testing.assert_allclose(one.nominal_m, transform_points(T, point.position_m), atol=1e-15)


def _run_of(setup: SimulationSetup) -> RunFunction:
    """The A-H run of ``setup`` as a function of the probe: the estimated frame's top rows."""
    kind = procedure_kind(setup.method)

    def run(probe: Probe) -> dict[str, np.ndarray]:
        res = kind.run(list(setup.points), setup.T_base_wobj_nominal, probe, setup.settings)
        return {"T": res.T_base_wobj[:3, :].ravel()}

    return run


def _linearize_slow(setup: SimulationSetup, step_m: float = 1e-6) -> np.ndarray:
    """Central differences of the A-H run with the slow probe."""
    run, T, off = _run_of(setup), setup.T_base_wobj_nominal, setup.edge_offset_m
    ideal = _SlowPlaneProbe(T, off)
    base = np.asarray(run(ideal)["T"])
    jac = np.zeros((base.size, len(ideal.commands)))
    for j in range(len(ideal.commands)):
        plus = np.asarray(run(_SlowPlaneProbe(T, off, 0.0, {j: step_m}))["T"])
        minus = np.asarray(run(_SlowPlaneProbe(T, off, 0.0, {j: -step_m}))["T"])
        jac[:, j] = (plus - minus) / (2 * step_m)
    return jac


def test_ah_linearisation_matches_the_slow_probe(ah: Plan) -> None:
    """The A-H run linearised with the fast plane probe gives the Jacobian of the slow one
    (to 1e-9 of its largest entry), on the shipped plan and on one with point D moved 3.6 mm
    along its face."""
    for plan in (ah, _moved(ah, 3, np.array([0.0, 0.003, -0.002]))):
        setup = _setup(plan)
        fast = linearize(_run_of(setup), setup.T_base_wobj_nominal, setup.edge_offset_m)
        slow = _linearize_slow(setup)
        scale = np.max(np.abs(slow))
        assert scale > 0.1  # a real Jacobian (metres and radians per metre of travel)
        np.testing.assert_allclose(fast.jacobians["T"], slow, rtol=0, atol=1e-9 * scale)


def test_procedure_covariance_does_not_depend_on_the_best_fit_column(ah: Plan) -> None:
    """``predict(..., best_fit=False)`` (what the live quality runs) gives the procedure's
    covariance bit for bit, and says the best fit was not computed (NaN)."""
    from planner.sim.predict import predict

    setup = _setup(ah)
    full = predict(setup)
    lean = predict(setup, best_fit=False)
    np.testing.assert_array_equal(lean.cov_procedure, full.cov_procedure)
    assert np.all(np.isnan(lean.cov_best_fit)) and np.all(np.isfinite(full.cov_best_fit))
    assert lean.n_searches == full.n_searches == 12  # A-H with the retakes, F and H approach first


def test_cached_layout_follows_a_moved_point(ah: Plan) -> None:
    """The A-H layout is cached by the points' values: the quality of a moved plan is the
    quality computed with an empty cache, and differs from the unmoved plan's; a layout the
    procedure refuses is still refused, with the same message, every time."""
    from calib.procedures.hultman2013 import _layout

    mesh = work_object_mesh(ah, PLANS, check_simulatable(ah))
    moved = _moved(ah, 3, np.array([0.0, 0.003, -0.002]))
    q0, _ = plan_quality(ah, mesh)
    q1, _ = plan_quality(moved, mesh)
    _layout.cache_clear()
    q1_fresh, _ = plan_quality(moved, mesh)
    assert q0 is not None and q1 is not None and q1_fresh is not None
    np.testing.assert_array_equal(q1.covariance, q1_fresh.covariance)
    assert np.max(np.abs(q1.covariance - q0.covariance)) > 1e-3 * np.max(np.abs(q0.covariance))
    a_up = _moved(ah, 0, np.array([0.0, 0.0, 0.004]))  # A no longer at B's height
    reasons = [plan_quality(a_up, mesh) for _ in range(2)]
    assert [q for q, _ in reasons] == [None, None]
    assert reasons[0][1] == reasons[1][1] and "A and B share z" in reasons[0][1]
