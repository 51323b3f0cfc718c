"""Simulated searches against a known box and the stator: exact points, edges, failures."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh

from calib.frames import make_transform, matrix_from_rotvec
from calib.models.proximity import ProximitySensor
from calib.models.robot_error import RobotErrorModel
from calib.probing import ProbePoint, SearchCommand, SearchSpec
from planner.reasons import Reason
from planner.sim.proximity import SimulatedProbe
from planner.sim.raycast import MeshRayCaster

# a 0.4 x 0.4 x 0.2 m block whose top face is z = 0 and whose +y edge face is y = 0
BOX = trimesh.creation.box(extents=(0.4, 0.4, 0.2))
BOX.apply_translation((0.0, -0.2, -0.1))
CASTER = MeshRayCaster(BOX)
TOP = (0.0, 0.0, 1.0)


def _probe(T_base_wobj=None, **kw) -> SimulatedProbe:
    kw.setdefault("robot_error", RobotErrorModel.none())
    kw.setdefault("sensor", ProximitySensor(repeatability_sigma_m=0.0))
    T = np.eye(4) if T_base_wobj is None else T_base_wobj
    return SimulatedProbe(CASTER, T, np.random.default_rng(7), **kw)


def _tilted() -> np.ndarray:
    return make_transform(matrix_from_rotvec([0.02, -0.03, 0.5]), [0.9, 0.1, 0.6])


def test_ideal_approach_returns_the_true_surface_point_exactly() -> None:
    T_true = _tilted()
    probe = _probe(T_true, sensor=ProximitySensor.ideal())
    nominal = make_transform(None, [0.004, -0.003, 0.005])  # estimate off by a few mm
    point = ProbePoint("p", (0.05, -0.1, 0.0), TOP)
    res = probe(SearchCommand.from_point(point, T_true @ nominal))
    assert res.ok
    p_true = np.linalg.inv(T_true) @ np.append(res.point_m, 1.0)
    assert abs(p_true[2]) < 1e-12  # on the true top face


def test_approach_with_full_face_switches_exactly_at_sn() -> None:
    probe = _probe()
    res = probe(SearchCommand.from_point(ProbePoint("p", (0.0, -0.2, 0.0), TOP), np.eye(4)))
    assert np.allclose(res.point_m, [0.0, -0.2, 0.0], atol=1e-12)
    assert res.travel_m == pytest.approx(0.030)


def test_failures_are_reasons_not_numbers() -> None:
    probe = _probe()
    close = ProbePoint("c", (0.0, -0.2, 0.0), TOP, SearchSpec(start_offset_m=0.002))
    shifted = make_transform(None, [0.0, 0.0, 0.005])  # part 5 mm higher than planned
    res = probe(SearchCommand.from_point(close, np.linalg.inv(shifted)))
    assert not res.ok and res.reason == "sensor already detecting at start"
    off = ProbePoint("o", (0.5, -0.2, 0.0), TOP)  # nothing below
    res = probe(SearchCommand.from_point(off, np.eye(4)))
    assert res.point_m is None and res.reason == "no detection within 50 mm"
    assert [e.reason for e in probe.events] == [
        "sensor already detecting at start",
        "no detection within 50 mm",
    ]


def test_edge_search_finds_a_straight_edge_within_the_model_bias() -> None:
    sensor = ProximitySensor(repeatability_sigma_m=0.0)
    inset = 0.003
    probe = _probe(sensor=sensor, edge_inset_m=inset, edge_tolerance_m=1e-7)
    # slide over the top face towards +y until the face ends at y = 0
    point = ProbePoint(
        "f", (0.05, 0.0, 0.0), TOP, SearchSpec("edge", 0.06, 0.03, (0.0, 1.0, 0.0)), (0, 1, 0)
    )
    res = probe(SearchCommand.from_point(point, np.eye(4)))
    assert res.ok
    bias = sensor.edge_event_offset_m(inset)
    assert bias > 1e-3
    assert res.point_m[1] == pytest.approx(bias, abs=0.05e-3)  # ray-bundle discretisation
    assert res.point_m[2] == pytest.approx(0.0, abs=1e-12)  # reported on the commanded path


def test_ideal_edge_search_is_exact() -> None:
    probe = _probe(sensor=ProximitySensor.ideal(), edge_tolerance_m=1e-13)
    point = ProbePoint(
        "f", (0.05, 0.0, 0.0), TOP, SearchSpec("edge", 0.06, 0.03, (0.0, 1.0, 0.0)), (0, 1, 0)
    )
    res = probe(SearchCommand.from_point(point, np.eye(4)))
    assert abs(res.point_m[1]) < 1e-12


def test_edge_search_must_start_detecting() -> None:
    probe = _probe()
    point = ProbePoint(
        "f", (0.05, 0.0, 0.0), TOP, SearchSpec("edge", 0.30, 0.03, (0.0, 1.0, 0.0)), (0, 1, 0)
    )  # starts 0.3 m before the edge: off the 0.4 m block's far side? no: y = -0.3, on it
    res = probe(SearchCommand.from_point(point, make_transform(None, [0.0, 0.0, 0.02])))
    assert res.reason == "sensor not detecting at start of edge search"


def test_repeatability_noise_has_the_modelled_spread(rng) -> None:
    sensor = ProximitySensor(repeatability_sigma_m=4e-5)
    robot = RobotErrorModel(repeatability_sigma_m=2e-5)
    probe = SimulatedProbe(CASTER, np.eye(4), rng, sensor=sensor, robot_error=robot)
    cmd = SearchCommand.from_point(ProbePoint("p", (0.0, -0.2, 0.0), TOP), np.eye(4))
    z = np.array([probe(cmd).point_m[2] for _ in range(400)])
    # reported = commanded at the switch: the robot offset along z and the jitter both add
    expect = math.hypot(4e-5, 2e-5)
    assert np.std(z) == pytest.approx(expect, rel=0.15)
    assert abs(np.mean(z)) < 4 * expect / math.sqrt(400)


def test_reachability_hook_fails_the_probe_with_its_reason() -> None:
    why = Reason("joint_limit", "unreachable: joint 5 at limit")
    probe = _probe(reachability=lambda cmd: why)
    res = probe(SearchCommand.from_point(ProbePoint("p", (0.0, -0.2, 0.0), TOP), np.eye(4)))
    assert res.reason == "unreachable: joint 5 at limit" and probe.events[-1].cause == why


def _commands(T: np.ndarray) -> list[SearchCommand]:
    """Approaches on the top face (noisy, a tilted part), an edge search between them, one
    approach with nothing below (it fails), and one after it."""
    top = [ProbePoint(f"t{i}", (0.03 * i - 0.15, -0.05 - 0.01 * i, 0.0), TOP) for i in range(9)]
    edge = ProbePoint(
        "f", (0.05, 0.0, 0.0), TOP, SearchSpec("edge", 0.06, 0.03, (0.0, 1.0, 0.0)), (0, 1, 0)
    )
    off = ProbePoint("o", (0.5, -0.2, 0.0), TOP)
    points = [*top[:4], edge, *top[4:], off, top[0]]
    return [SearchCommand.from_point(p, T) for p in points]


@pytest.mark.parametrize("stop_at", [None, "o"])
def test_searches_in_turn_equal_one_by_one(stop_at: str | None) -> None:
    """``run_in_turn`` (one ray cast for a run of approaches: the x-offset run) gives the same
    points, failures, events and noise as the probe called on each search until one fails."""
    T = _tilted()
    cmds = _commands(T @ make_transform(None, [0.001, -0.002, 0.0005]))
    if stop_at is None:
        cmds = [c for c in cmds if c.point_id != "o"]
    noise = {
        "robot_error": RobotErrorModel(repeatability_sigma_m=2e-5),
        "sensor": ProximitySensor(),
    }
    one, batch = _probe(T, **noise), _probe(T, **noise)
    expected = []
    for c in cmds:
        expected.append(one(c))
        if not expected[-1].ok:
            break
    got = batch.run_in_turn(cmds)
    assert [r.reason for r in got] == [r.reason for r in expected]
    assert len(got) == (len(cmds) if stop_at is None else 11)  # up to and with the failure
    for a, b in zip(got, expected, strict=True):
        assert (a.point_m is None) == (b.point_m is None)
        if a.point_m is not None:
            assert np.array_equal(a.point_m, b.point_m) and a.travel_m == b.travel_m
    assert batch.events == one.events
    if stop_at is None:  # the same noise drawn: both generators are in the same state
        assert batch.rng.random() == one.rng.random()


class _ManyHook:
    """A reachability hook that refuses one search and counts how it is asked."""

    def __init__(self, refuse: str) -> None:
        self.refuse = refuse
        self.single: list[str] = []
        self.batches: list[list[tuple[str, float]]] = []

    def _why(self, cmd: SearchCommand) -> Reason | None:
        return (
            Reason("collision", f"{cmd.point_id} hits a clamp")
            if cmd.point_id == self.refuse
            else None
        )

    def __call__(self, cmd: SearchCommand) -> Reason | None:
        self.single.append(cmd.point_id)
        return self._why(cmd)

    def many(self, cmds: list[SearchCommand]) -> list[Reason | None]:
        self.batches.append([(c.point_id, c.length_m) for c in cmds])
        return [self._why(c) for c in cmds]


@pytest.mark.parametrize("refuse", ["t5", "none"])
def test_a_hook_asked_for_many_searches_at_once_gives_the_same_run(refuse: str) -> None:
    """The x-offset run's approaches are vetted in one call of the hook's ``many`` (the cell
    checks their paths together): the same results and events as each vetted in turn, the
    run ending at the refused search; the paths asked for are those the sensor ends, each as
    long as its travel."""
    T = _tilted()
    cmds = [c for c in _commands(T) if c.point_id not in ("f", "o")]  # approaches only
    noise = {"robot_error": RobotErrorModel(repeatability_sigma_m=2e-5)}
    plain_hook, many_hook = _ManyHook(refuse), _ManyHook(refuse)
    one = _probe(T, reachability=plain_hook, **noise)
    batch = _probe(T, reachability=many_hook, **noise)
    expected = []
    for c in cmds:
        expected.append(one(c))
        if not expected[-1].ok:
            break
    got = batch.run_in_turn(cmds)
    assert [r.reason for r in got] == [r.reason for r in expected]
    assert len(got) == (6 if refuse == "t5" else len(cmds))
    assert batch.events == one.events
    assert many_hook.single == [] and len(many_hook.batches) == 1
    asked = many_hook.batches[0]
    assert [pid for pid, _ in asked] == [c.point_id for c in cmds]  # the sensor ends them all
    travels = [r.travel_m for r in expected if r.ok]
    assert [length for _, length in asked][: len(travels)] == travels
