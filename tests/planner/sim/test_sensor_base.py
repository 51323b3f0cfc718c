"""The contract every simulated sensor keeps (:class:`planner.sim.sensor_base.SimulatedSensor`),
run over every simulator of the sensor registry: the same events, failures, reachability
vetting, landing judgement, seeding and in-turn runs, whatever the sensor's own model."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
import trimesh

from calib.frames import make_transform, matrix_from_rotvec
from calib.models import ProximitySensor, RobotErrorModel, TouchProbe
from calib.probing import ProbePoint, SearchCommand, SearchSpec
from planner.reasons import Reason
from planner.sim.raycast import MeshRayCaster
from planner.sim.search_events import LANDED_OFF_FACE, PARTLY_OFF_FACE, FaceLookup
from planner.sim.sensor_base import SimulatedSensor
from planner.sim.sensors import SENSORS

# a 0.4 x 0.4 x 0.1 m block whose top face is z = 0, centred on the origin in x and y
BOX = trimesh.creation.box(extents=(0.4, 0.4, 0.1))
BOX.apply_translation((0.0, 0.0, -0.05))
CASTER = MeshRayCaster(BOX)
UP = (0.0, 0.0, 1.0)
IDEAL = {"proximity": ProximitySensor.ideal(), "touch": TouchProbe.ideal()}
NOISY = {"proximity": ProximitySensor(), "touch": TouchProbe()}
T_TRUE = make_transform(matrix_from_rotvec([0.01, -0.02, 0.3]), [0.8, 0.1, 0.5])


@pytest.fixture(params=sorted(SENSORS))
def kind(request: pytest.FixtureRequest) -> str:
    return str(request.param)


def _probe(kind: str, sensor: Any = None, seed: int = 0, **kw: Any) -> SimulatedSensor:
    kw.setdefault("robot_error", RobotErrorModel.none())
    simulator = SENSORS[kind].load()
    probe = simulator(
        CASTER, T_TRUE, np.random.default_rng(seed), sensor=sensor or IDEAL[kind], **kw
    )
    assert isinstance(probe, SimulatedSensor)
    return probe


def _command(x: float, y: float, z: float = 0.0, offset: float = 0.02) -> SearchCommand:
    point = ProbePoint("p", (x, y, z), UP, SearchSpec("approach", offset, 0.02))
    return SearchCommand.from_point(point, T_TRUE)


def test_every_registered_simulator_derives_from_the_base() -> None:
    for entry in SENSORS.values():
        assert issubclass(entry.load(), SimulatedSensor), entry.name


def test_an_ideal_approach_measures_the_true_face_and_records_one_event(kind: str) -> None:
    probe = _probe(kind)
    res = probe(_command(0.05, -0.03))
    assert res.ok and res.reason == ""
    p_wobj = np.linalg.inv(T_TRUE) @ np.append(res.point_m, 1.0)
    assert np.allclose(p_wobj[:3], [0.05, -0.03, 0.0], atol=1e-9)
    assert res.travel_m == pytest.approx(0.02, abs=1e-9)
    (event,) = probe.events
    assert (event.point_id, event.kind, event.cause, event.landing) == ("p", "approach", None, None)
    assert event.reason == ""
    assert event.travel_m == res.travel_m


def test_failures_are_reasons_recorded_as_events(kind: str) -> None:
    probe = _probe(kind)
    inside = probe(_command(0.0, 0.0, z=-0.03, offset=0.01))  # starts 20 mm inside the block
    assert not inside.ok and inside.point_m is None and "inside the part" in inside.reason
    beyond = probe(_command(0.5, 0.0))  # nothing under the search
    assert not beyond.ok and "within 40 mm" in beyond.reason
    assert [e.reason for e in probe.events] == [inside.reason, beyond.reason]
    assert all(np.isnan(e.travel_m) for e in probe.events)


def test_a_search_that_runs_out_of_travel_or_starts_inside_is_a_search_reason(kind: str) -> None:
    """The sensor decides these: a ``search`` reason on the event, without a pair, its words
    the result's."""
    probe = _probe(kind)
    inside = probe(_command(0.0, 0.0, z=-0.03, offset=0.01))
    beyond = probe(_command(0.5, 0.0))
    for res, event in zip((inside, beyond), probe.events, strict=True):
        assert event.cause is not None and event.cause.kind == "search", event
        assert event.cause.pair is None and str(event.cause) == res.reason
    what = "detection" if kind == "proximity" else "contact"
    assert probe.events[1].cause == Reason("search", f"no {what} within 40 mm")


def test_the_hook_vets_the_path_cut_at_the_event(kind: str) -> None:
    seen: list[SearchCommand] = []

    def refuse(cmd: SearchCommand) -> Reason:
        seen.append(cmd)
        return Reason("reach", "unreachable or colliding: test")

    probe = _probe(kind, reachability=refuse)
    res = probe(_command(0.05, -0.03))
    assert res.reason == "unreachable or colliding: test" and res.point_m is None
    assert seen[0].length_m == pytest.approx(0.02, abs=1e-9)  # start to the event, not 40 mm
    assert probe.events[-1].reason == res.reason
    passing = _probe(kind, reachability=lambda cmd: None)
    assert passing(_command(0.05, -0.03)).ok


def test_a_search_the_hook_refuses_keeps_the_hooks_kind_and_pair(kind: str) -> None:
    """A collision the cell finds on the path run fails the search with the cell's kind and
    pair; an unreachable path with its own kind."""
    hit = Reason(
        "collision", "unreachable or colliding: at 3.0 mm: link_6 hits clamp", ("link_6", "clamp")
    )
    probe = _probe(kind, reachability=lambda cmd: hit)
    assert probe(_command(0.05, -0.03)).reason == str(hit)
    assert probe.events[-1].cause == hit and probe.events[-1].cause.pair == ("link_6", "clamp")
    limit = Reason("joint_limit", "unreachable or colliding: at 0.0 mm: joint 5 at limit (j5)")
    probe = _probe(kind, reachability=lambda cmd: limit)
    assert not probe(_command(0.05, -0.03)).ok
    assert probe.events[-1].cause == limit and probe.events[-1].cause.pair is None


def test_a_footprint_partly_over_an_edge_is_judged_on_its_face(kind: str) -> None:
    top = np.flatnonzero(BOX.face_normals[:, 2] > 0.99)
    face_id = np.full(len(BOX.faces), -1, dtype=np.int64)
    face_id[top] = 0
    faces = FaceLookup(face_id, {"p": 0})
    r = IDEAL[kind].footprint_radius_m if kind == "touch" else NOISY[kind].footprint_radius_m
    sensor = IDEAL[kind] if kind == "touch" else ProximitySensor(repeatability_sigma_m=0.0)
    probe = _probe(kind, sensor=sensor, faces=faces)
    res = probe(_command(0.2 - 0.5 * r, 0.0))  # the footprint's centre 0.5 r inside the edge
    assert res.ok
    assert probe.events[-1].landing == PARTLY_OFF_FACE and 0.0 < probe.events[-1].off_fraction < 0.5
    assert probe.events[-1].landing.kind == "footprint" and probe.events[-1].cause is None


def test_a_footprint_off_its_face_is_a_footprint_reason(kind: str) -> None:
    """An approach meant for a face it misses (here: the face is another one) succeeds, and
    its event says where it landed with a ``footprint`` reason."""
    face_id = np.zeros(len(BOX.faces), dtype=np.int64)  # every triangle on face 0
    faces = FaceLookup(face_id, {"p": 1})  # but the search was meant for face 1
    probe = _probe(kind, faces=faces)
    assert probe(_command(0.05, -0.03)).ok
    event = probe.events[-1]
    assert event.landing == LANDED_OFF_FACE and event.landing.kind == "footprint"
    assert str(event.landing) == "landed off its face" and event.cause is None


def test_the_same_seed_gives_the_same_numbers(kind: str) -> None:
    noisy = RobotErrorModel()
    a = _probe(kind, NOISY[kind], seed=3, robot_error=noisy)(_command(0.05, -0.03))
    b = _probe(kind, NOISY[kind], seed=3, robot_error=noisy)(_command(0.05, -0.03))
    c = _probe(kind, NOISY[kind], seed=4, robot_error=noisy)(_command(0.05, -0.03))
    assert a.ok and np.array_equal(a.point_m, b.point_m) and a.travel_m == b.travel_m
    assert c.ok and not np.array_equal(a.point_m, c.point_m)


def test_run_in_turn_is_each_in_turn_up_to_the_first_failure(kind: str) -> None:
    noisy = RobotErrorModel()
    commands = [_command(x, 0.1 * x) for x in (-0.1, 0.0, 0.1)]
    commands += [_command(0.5, 0.0), _command(0.12, 0.0)]  # the fourth finds nothing
    batch = _probe(kind, NOISY[kind], seed=5, robot_error=noisy)
    one = _probe(kind, NOISY[kind], seed=5, robot_error=noisy)
    got = batch.run_in_turn(commands)
    want = []
    for cmd in commands:
        want.append(one(cmd))
        if not want[-1].ok:
            break
    assert len(got) == len(want) == 4 and not got[-1].ok
    for g, w in zip(got, want, strict=True):
        assert g.reason == w.reason and (g.travel_m == w.travel_m or not g.ok)
        assert (g.point_m is None and w.point_m is None) or np.array_equal(g.point_m, w.point_m)
    assert batch.events == one.events
