"""One Monte Carlo trial: seeded, a failed probe becomes a recorded failure, every procedure
of the registry runs through the same trial."""

from __future__ import annotations

import numpy as np
import pytest

from calib.models import Misplacement, RobotErrorModel
from calib.models.proximity import ProximitySensor
from calib.probing import SearchSpec
from calib.procedures import PROCEDURES, RolePoint
from calib.procedures.three_two_one import pick_roles
from planner.parts.stator import StatorGeometry
from planner.parts.stator_demo import nominal_T_base_wobj, stator_ah_points
from planner.parts.stator_mesh import build_stator_mesh
from planner.program.build import build_program
from planner.program.controllers import controller
from planner.program.settings import DEFAULT_EDGE_INSET_M, resolved_settings
from planner.reasons import Reason
from planner.sim.montecarlo import stator_setup
from planner.sim.search_events import SearchFailure
from planner.sim.setup import default_settings
from planner.sim.trial import TrialRunner

G = StatorGeometry.full_section()
MESH = build_stator_mesh(G)


def _runner(points) -> TrialRunner:  # type: ignore[no-untyped-def]
    setup, mesh = stator_setup(points, G, nominal_T_base_wobj(), mesh=MESH)
    return TrialRunner(setup, mesh)


def test_same_seed_same_trial_and_errors_are_small() -> None:
    runner = _runner(stator_ah_points(G))
    seed = np.random.SeedSequence(42)
    a, b = runner.run_trial(seed, None), runner.run_trial(seed, None)
    assert a.failure == "" and np.array_equal(a.delta_procedure, b.delta_procedure)
    assert np.abs(a.delta_procedure[:3]).max() < 1e-3  # within a millimetre
    assert np.abs(a.delta_best_fit[:3]).max() < 1e-3
    # the adaptive RAPID program: an edge point approaches its face before its edge search
    assert a.searched == (
        *("A", "B", "C", "D", "E", "F@face", "F", "G", "H@face", "H", "C2", "D2"),
    )
    other = runner.run_trial(np.random.SeedSequence(43), None)
    assert not np.array_equal(other.delta_procedure, a.delta_procedure)


def test_a_shared_position_seed_gives_the_same_misplacement() -> None:
    """The paper's protocol: two trials of one position see the same part pose, other noise."""
    runner = _runner(stator_ah_points(G))
    pos = np.random.SeedSequence(7)
    a = runner.run_trial((np.random.SeedSequence(1), pos), None)
    b = runner.run_trial((np.random.SeedSequence(2), pos), None)
    assert not np.array_equal(a.delta_procedure, b.delta_procedure)
    # the pose is common: the errors differ only by the noise (tens of micrometres), not by
    # where the part lies (the edge offset's misplacement effects are common too)
    assert np.abs(a.delta_procedure[:3] - b.delta_procedure[:3]).max() < 5e-4


def test_failed_probe_is_recorded_with_point_and_reason() -> None:
    points = stator_ah_points(G, approach=SearchSpec("approach", 0.050, 0.060))
    why = Reason("joint_limit", "unreachable: joint 5 at limit")
    res = _runner(points).run_trial(np.random.SeedSequence(1), lambda cmd: why)
    assert res.failure == "A: unreachable: joint 5 at limit"
    assert res.failed_search == SearchFailure("A", why)  # the hook's kind, the same words
    assert np.all(np.isnan(res.delta_procedure)) and np.all(np.isnan(res.delta_best_fit))
    assert res.events[0].reason == "unreachable: joint 5 at limit"
    assert res.events[0].cause == why


def test_a_failed_face_approach_keeps_the_hooks_kind_and_pair_in_the_programs_words() -> None:
    """The adaptive RAPID program runs F's approach to its face before F's edge search: a
    collision the cell finds there stops the trial at F, in the program's words around the
    hook's, with the collision's kind and pair."""
    hit = Reason("collision", "unreachable or colliding: link_6 hits clamp", ("link_6", "clamp"))
    res = _runner(stator_ah_points(G)).run_trial(
        np.random.SeedSequence(1), lambda cmd: hit if cmd.point_id == "F@face" else None
    )
    words = "approach to the face: unreachable or colliding: link_6 hits clamp"
    assert res.failure == f"F: {words}"
    assert res.failed_search == SearchFailure("F", Reason("collision", words, ("link_6", "clamp")))
    assert res.events[-1].point_id == "F@face" and res.events[-1].cause == hit


def test_search_failure_takes_the_kind_of_the_failed_searchs_event() -> None:
    """The last event is the search that failed (a program stops there): its kind and pair,
    the procedure's words; a search refused before it ran (no failed event of it) is a
    ``search`` reason."""
    from calib.errors import ProbeFailedError
    from planner.sim.search_events import ProbeEvent
    from planner.sim.trial import search_failure

    missed = Reason("search", "no detection within 50 mm")
    ok = ProbeEvent("C", "approach", travel_m=0.03)
    failed = ProbeEvent("D", "approach", cause=missed)
    exc = ProbeFailedError("D", "no detection within 50 mm")
    assert search_failure(exc, [ok, failed]) == SearchFailure("D", missed)
    face = ProbeEvent("F@face", "approach", cause=missed)
    got = search_failure(ProbeFailedError("F", f"approach to the face: {missed}"), [ok, face])
    assert got.cause == Reason("search", f"approach to the face: {missed}")
    past = ProbeFailedError("D2", "the measured start lies past the end of the search")
    assert search_failure(past, [ok]) == SearchFailure("D2", Reason("search", past.reason))
    assert search_failure(past, [failed]).cause.kind == "search"  # not D2's event
    assert search_failure(past, []).search == "D2"


@pytest.mark.parametrize("method", list(PROCEDURES))
def test_every_procedure_runs_in_the_same_trial(method: str) -> None:
    """The trial executes the program of each procedure of the registry: each calibrates the
    misplaced stator to within a millimetre and half a degree (the stator's weakest rotation,
    about y, scatters by 0.07 deg). The fits use the approach points of A-H and two on the top
    face: measured all at once in the nominal frame, an edge search would start off the face."""
    import dataclasses

    from calib.probing import ProbePoint

    kind = PROCEDURES[method]
    ah = stator_ah_points(G)
    pts = [RolePoint(r, p) for r, p in ah.items()]
    spec = SearchSpec("approach", 0.050, 0.060)
    top = [
        ProbePoint(f"T{i}", (-0.06, y, 0.0), (0.0, 0.0, 1.0), spec)
        for i, y in ((1, -0.1), (2, -0.6))
    ]
    if method == "three_two_one":
        pts = [RolePoint(r, rp.point) for r, rps in pick_roles(pts).items() for rp in rps]
    elif method != "hultman2013":
        plain = [p for p in ah.values() if p.search.kind == "approach"]
        pts = [RolePoint("fit", p) for p in plain + top]
    setup, mesh = stator_setup(stator_ah_points(G), G, nominal_T_base_wobj(), mesh=MESH)
    settings = resolved_settings(kind.settings_type(), setup.sensor, DEFAULT_EDGE_INSET_M)
    program = build_program(pts, settings, setup.program.safety, controller(None))
    setup = dataclasses.replace(setup, program=program)
    res = TrialRunner(setup, mesh).run_trial(np.random.SeedSequence(5), None)
    assert res.failure == "", res.failure
    assert np.abs(res.delta_procedure[:3]).max() < 1e-3
    assert np.abs(res.delta_procedure[3:]).max() < np.radians(0.5)


def test_default_settings_carry_the_sensors_edge_offset() -> None:
    from calib.paper.settings import Hultman2013

    sensor = ProximitySensor()
    s = default_settings(sensor, beta1_rad=0.2)
    assert s.beta1_rad == 0.2
    assert s.edge_event_offset_m == sensor.edge_event_offset_m(DEFAULT_EDGE_INSET_M) > 0.005
    assert default_settings(sensor, edge_event_offset_m=0.0) == Hultman2013(edge_event_offset_m=0.0)
    setup, _ = stator_setup(stator_ah_points(G), G, nominal_T_base_wobj(), mesh=MESH)
    assert setup.settings == default_settings(sensor)
    assert setup.misplacement == Misplacement() and setup.robot_error == RobotErrorModel()
