"""One Monte Carlo trial: seeded, and a failed probe becomes a recorded failure."""

from __future__ import annotations

import numpy as np

from calib.models import Misplacement, RobotErrorModel
from calib.models.proximity import ProximitySensor
from calib.probing import SearchSpec
from planner.parts.stator import StatorGeometry
from planner.parts.stator_demo import nominal_T_base_wobj, stator_ah_points
from planner.parts.stator_mesh import build_stator_mesh
from planner.sim.montecarlo import default_pivot
from planner.sim.trial import SimulationSetup, TrialRunner

G = StatorGeometry.full_section()
MESH = build_stator_mesh(G)


def _setup(points) -> SimulationSetup:  # type: ignore[no-untyped-def]
    return SimulationSetup(
        points=points,
        geometry=G,
        T_base_wobj_nominal=nominal_T_base_wobj(),
        sensor=ProximitySensor(),
        robot_error=RobotErrorModel(),
        misplacement=Misplacement(),
        pivot_wobj_m=default_pivot(points),
    )


def test_same_seed_same_trial_and_errors_are_small() -> None:
    runner = TrialRunner(_setup(stator_ah_points(G)), MESH)
    seed = np.random.SeedSequence(42)
    a, b = runner.run_trial(seed, None), runner.run_trial(seed, None)
    assert a.failure == "" and np.array_equal(a.delta_procedure, b.delta_procedure)
    assert np.abs(a.delta_procedure[:3]).max() < 1e-3  # within a millimetre
    assert np.abs(a.delta_best_fit[:3]).max() < 1e-3
    other = runner.run_trial(np.random.SeedSequence(43), None)
    assert not np.array_equal(other.delta_procedure, a.delta_procedure)


def test_failed_probe_is_recorded_with_point_and_reason() -> None:
    points = stator_ah_points(G, approach=SearchSpec("approach", 0.050, 0.060))
    res = TrialRunner(_setup(points), MESH).run_trial(
        np.random.SeedSequence(1), lambda cmd: "unreachable: joint 5 at limit"
    )
    assert res.failure == "A: unreachable: joint 5 at limit"
    assert np.all(np.isnan(res.delta_procedure)) and np.all(np.isnan(res.delta_best_fit))


def test_default_settings_carry_the_sensors_edge_offset() -> None:
    from calib.paper.settings import Hultman2013
    from planner.sim.montecarlo import DEFAULT_EDGE_INSET_M, default_settings

    sensor = ProximitySensor()
    s = default_settings(sensor, beta1_rad=0.2)
    assert s.beta1_rad == 0.2
    assert s.edge_event_offset_m == sensor.edge_event_offset_m(DEFAULT_EDGE_INSET_M) > 0.005
    assert default_settings(sensor, edge_event_offset_m=0.0) == Hultman2013(edge_event_offset_m=0.0)
    assert _setup(stator_ah_points(G)).settings == default_settings(sensor)
