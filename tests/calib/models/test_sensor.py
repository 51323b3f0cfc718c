"""The proximity-sensor model: coverage, switching distance, slot-hole effect, edge offset."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from calib.errors import PlanError
from calib.models.proximity import ProximitySensor, sunflower_disk
from calib.models.robot_error import RobotErrorModel
from calib.plan import plan_from_json, plan_to_json
from calib.probing import ProbePoint, SearchCommand
from planner.demo import stator_plan
from planner.parts.stator import StatorGeometry
from planner.parts.stator_mesh import build_stator_mesh
from planner.sim.proximity import SimulatedProbe
from planner.sim.raycast import MeshRayCaster


def test_full_flat_target_switches_at_sensing_distance() -> None:
    s = ProximitySensor()
    assert s.signal(np.full(s.n_rays, s.sensing_distance_m)) == pytest.approx(1.0)
    d0 = 0.0213
    assert s.switch_travel_m(np.full(s.n_rays, d0)) == pytest.approx(d0 - s.sensing_distance_m)
    assert math.isinf(s.switch_travel_m(np.full(s.n_rays, np.inf)))


def test_partial_coverage_switches_closer_by_lambda_log() -> None:
    s = ProximitySensor()
    d = np.full(s.n_rays, 0.02)
    d[: s.n_rays // 4] = np.inf  # a quarter of the face sees no metal
    shift = s.switch_travel_m(d) - (0.02 - s.sensing_distance_m)
    assert shift == pytest.approx(s.coverage_shift_m(0.75), rel=1e-12)
    assert s.coverage_shift_m(0.75) == pytest.approx(s.decay_length_m * math.log(4 / 3))


def test_inclined_face_reads_closer_by_the_disk_average() -> None:
    """On a face tilted by theta the rays see d0 + x tan(theta); the exponential average over
    a uniform disk is 2 I1(aR) / (aR) with a = tan(theta) / lambda (scipy), so the sensor
    switches earlier by lambda ln of that."""
    from scipy.special import i1

    s = ProximitySensor()
    tilt = math.radians(3.0)
    d = 0.02 + s.face_points_m[:, 0] * math.tan(tilt)
    aR = math.tan(tilt) / s.decay_length_m * s.radius_m
    early = s.decay_length_m * math.log(2 * i1(aR) / aR)
    assert early > 5e-6
    travel = s.switch_travel_m(d)
    assert travel == pytest.approx(0.02 - s.sensing_distance_m - early, abs=1e-6)


def test_sunflower_points_fill_the_disk_evenly() -> None:
    p = sunflower_disk(256, 0.009)
    r = np.linalg.norm(p, axis=1)
    assert r.max() < 0.009
    # equal-area: the inner half of the area holds half the points
    assert abs(np.sum(r < 0.009 / math.sqrt(2)) - 128) <= 2
    assert np.allclose(sunflower_disk(1, 0.009), 0.0)


def test_hysteresis_and_jitter_levels() -> None:
    s = ProximitySensor()
    assert s.off_level() == pytest.approx(math.exp(-0.1 * 0.008 / s.decay_length_m))
    assert s.on_level(0.0001) < 1.0 < s.on_level(-0.0001)
    assert ProximitySensor.ideal().off_level() == 1.0


def test_edge_event_offset_solves_the_disk_segment() -> None:
    s = ProximitySensor()
    t = s.edge_event_offset_m(0.003)
    u = t / s.radius_m
    covered = (math.acos(u) - u * math.sqrt(1 - u * u)) / math.pi
    assert covered == pytest.approx(s.off_level() * math.exp(-0.003 / s.decay_length_m))
    assert 0 < t < s.radius_m
    assert ProximitySensor.ideal().edge_event_offset_m(0.003) == 0.0
    with pytest.raises(PlanError, match="inset"):
        s.edge_event_offset_m(-0.01)


def test_slot_hole_reads_farther_than_tooth_by_the_predicted_amount() -> None:
    """A probe centred over a slot hole vs over a tooth web, against an independent prediction:
    the covered fraction of the exact disk from a fine grid and the exact round holes."""
    g = StatorGeometry.prototype()
    sensor = ProximitySensor(repeatability_sigma_m=0.0)
    probe = SimulatedProbe(
        MeshRayCaster(build_stator_mesh(g, deformed=False)),
        np.eye(4),
        np.random.default_rng(0),
        sensor=sensor,
        robot_error=RobotErrorModel.none(),
    )

    def reading(y: float, z: float) -> float:  # how far behind the face the point reads
        cmd = SearchCommand.from_point(ProbePoint("p", (0.0, y, z), (1.0, 0.0, 0.0)), np.eye(4))
        return -float(probe(cmd).point_m[0])

    def covered(y: float, z: float) -> float:
        u = np.linspace(-1, 1, 801) * sensor.radius_m
        yy, zz = np.meshgrid(u, u)
        inside = yy**2 + zz**2 <= sensor.radius_m**2
        return 1.0 - float(g.hole_near(y + yy[inside], z + zz[inside]).mean())

    hole = (float(g.slot_y_m[5]), float(g.layer_z_m[2]))
    tooth = (float(g.tooth_y_m[5]), float(g.web_z_m[2]))
    predicted = sensor.decay_length_m * math.log(covered(*tooth) / covered(*hole))
    measured = reading(*hole) - reading(*tooth)
    assert predicted > 0.3e-3  # the effect is real: a few tenths of a millimetre
    assert measured == pytest.approx(predicted, abs=0.03e-3)
    assert [e.landing for e in probe.events] == [None, None]  # no face lookup given: unjudged


def test_bad_parameters_name_the_field() -> None:
    with pytest.raises(PlanError, match=r"^sensing_distance_m: must be > 0"):
        ProximitySensor(sensing_distance_m=0.0)
    with pytest.raises(PlanError, match=r"^n_rays: must be an integer >= 1"):
        ProximitySensor(n_rays=0)


def test_bad_sensor_in_a_plan_file_names_the_json_path() -> None:
    """The plan holds the same sensor object; a bad field names its path in the file."""
    raw = json.loads(plan_to_json(stator_plan()))
    raw["validation"]["sensor"]["sensing_distance_m"] = -0.008
    with pytest.raises(PlanError, match=r"validation\.sensor.*sensing_distance_m.*> 0"):
        plan_from_json(json.dumps(raw))
    assert isinstance(stator_plan().validation.sensor, ProximitySensor)


def test_sensor_registry_gives_the_simulator_of_the_plans_sensor() -> None:
    from calib.models import TouchProbe
    from planner.sim.sensors import SENSORS, sensor_kind
    from planner.sim.touch import SimulatedTouchProbe

    kind = sensor_kind(stator_plan().validation.sensor)
    assert kind is SENSORS["proximity"] and kind.load() is SimulatedProbe
    assert kind.name == ProximitySensor.KIND
    touch = sensor_kind(TouchProbe())
    assert touch is SENSORS["touch"] and touch.load() is SimulatedTouchProbe
    # every sensor kind of the plan's union has a simulator, and back
    import typing

    from calib.models import SensorSettings

    assert {t.KIND for t in typing.get_args(SensorSettings)} == set(SENSORS)

    class Unknown:
        KIND = "capacitive"
        footprint_radius_m = 0.01
        standoff_m = 0.002

    with pytest.raises(
        PlanError,
        match=r"unknown sensor simulator \(validation.sensor.kind\) 'capacitive'; known: "
        r"proximity, touch$",
    ):
        sensor_kind(Unknown())


def _face_frame_numpy(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The face frame as numpy computed it before it went to plain floats (the reference)."""
    ax, ay, az = (float(c) for c in axis)
    u = np.array([0.0, az, -ay]) if abs(ax) < 0.9 else np.array([-az, 0.0, ax])
    u /= math.sqrt(float(u @ u))
    v = np.array([ay * u[2] - az * u[1], az * u[0] - ax * u[2], ax * u[1] - ay * u[0]])
    return u, v


def test_the_face_frame_is_the_numpy_one_to_the_bit(rng: np.random.Generator) -> None:
    """Every ray of a proximity search starts on this frame: a last-bit change moves a ray
    that lies on a triangle's edge to the next triangle (the stator's golden landing counts
    caught one), so the float version must give numpy's bits, near e_x and off it."""
    from calib.models.sensor import face_frame

    axes = rng.normal(size=(5000, 3))
    axes[:100] = [1.0, 0.0, 0.0] + 0.3 * axes[:100]  # about e_x: the other helper
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    for a in [*axes, np.array([0.0, 0.0, -1.0]), np.array([-1.0, 0.0, 0.0])]:
        got, want = face_frame(a), _face_frame_numpy(a)
        np.testing.assert_array_equal(got[0], want[0])
        np.testing.assert_array_equal(got[1], want[1])
