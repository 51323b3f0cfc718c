"""The touch-trigger probe: its model (radius, pre-travel lobing) and its simulation against a
mesh (exact contact on faces, the cosine error of radius compensation, edges, refusals)."""

from __future__ import annotations

import math

import msgspec
import numpy as np
import pytest
import trimesh

from calib.errors import PlanError
from calib.frames import make_transform, matrix_from_rotvec
from calib.models import RobotErrorModel, TouchProbe
from calib.models.sensor import face_frame
from calib.plan.file import plan_from_json, plan_to_json
from calib.probing import ProbePoint, SearchCommand, SearchSpec
from planner.demo import stator_plan
from planner.sim.raycast import MeshRayCaster
from planner.sim.search_events import LANDED_OFF_FACE, FaceLookup
from planner.sim.touch import SimulatedTouchProbe, sweep_contact

BOX = trimesh.creation.box(extents=(0.4, 0.4, 0.1))
BOX.apply_translation((0.0, 0.0, -0.05))  # top face z = 0
TOP = ProbePoint("T", (0.05, 0.02, 0.0), (0.0, 0.0, 1.0), SearchSpec("approach", 0.02, 0.02))


def _probe(T_true: np.ndarray, sensor: TouchProbe, **kw) -> SimulatedTouchProbe:  # type: ignore[no-untyped-def]
    return SimulatedTouchProbe(
        MeshRayCaster(BOX),
        T_true,
        np.random.default_rng(0),
        sensor=sensor,
        robot_error=RobotErrorModel.none(),
        **kw,
    )


def test_model_is_a_sensor_without_edge_searches() -> None:
    s = TouchProbe(tip_diameter_m=0.002)
    assert s.KIND == "touch" and s.footprint_radius_m == 0.001 and s.standoff_m == 0.0
    assert not s.runs_edge_searches and s.edge_event_offset_m(0.003) == 0.0
    assert s.search_noise("approach", 0.003).sensor_sigma_m == s.trigger_repeatability_sigma_m
    with pytest.raises(PlanError, match="cannot run an edge search"):
        s.search_noise("edge", 0.003)
    with pytest.raises(PlanError, match="tip_diameter_m"):
        TouchProbe(tip_diameter_m=0.0)


def test_pretravel_lobing_has_three_lobes_and_vanishes_along_the_axis() -> None:
    s = TouchProbe(axial_pretravel_m=12e-6, side_pretravel_m=6e-6, lobing_amplitude_m=2e-6)
    axis = np.array([0.0, 0.0, -1.0])
    assert s.pretravel_error_m(-axis, axis) == 0.0  # qualified along the axis
    u, v = face_frame(axis)
    psi = math.radians(30.0)

    def err(phi: float) -> float:
        push = math.cos(psi) * axis + math.sin(psi) * (math.cos(phi) * u + math.sin(phi) * v)
        return s.pretravel_error_m(-push, axis)

    for phi in np.linspace(0.0, 2.0, 7):
        assert err(phi) == pytest.approx(err(phi + 2 * math.pi / 3), abs=1e-15)
        want = (6e-6 - 12e-6 + 2e-6 * math.cos(3 * phi)) * math.sin(psi) ** 2
        assert err(phi) == pytest.approx(want, abs=1e-15)


def test_square_face_is_measured_exactly() -> None:
    probe = _probe(np.eye(4), TouchProbe.ideal())
    res = probe(SearchCommand.from_point(TOP, np.eye(4)))
    assert res.ok and np.abs(res.point_m - TOP.position_m).max() < 1e-12
    assert res.travel_m == pytest.approx(0.02, abs=1e-12) and probe.events[0].landing is None


@pytest.mark.filterwarnings("error")
def test_sweep_along_an_axis_past_side_faces_is_clean() -> None:
    """Faces parallel to the motion are never met and raise no floating-point warnings."""
    tri = np.arange(len(BOX.faces))
    travel, normal, k = sweep_contact(
        MeshRayCaster(BOX), np.array([0.05, 0.02, 0.023]), np.array([0.0, 0.0, -1.0]), 0.003, tri
    )
    assert travel == pytest.approx(0.02, abs=1e-12) and k >= 0
    np.testing.assert_allclose(normal, [0.0, 0.0, 1.0], atol=1e-12)


@pytest.mark.parametrize("deg", [1.0, 3.0, 8.0])
def test_tilted_face_gives_the_cosine_error_of_radius_compensation(deg: float) -> None:
    """The ball meets a face tilted by theta at its tangent point; compensating along the
    commanded normal leaves the reported point r (1 - cos theta) outside the true face."""
    s = TouchProbe.ideal()
    T_true = make_transform(matrix_from_rotvec([math.radians(deg), 0.0, 0.0]), [0, 0, 0])
    res = _probe(T_true, s)(SearchCommand.from_point(TOP, np.eye(4)))
    n = T_true[:3, 2]
    gap = float(n @ res.point_m)  # the true top plane passes through the origin
    assert gap == pytest.approx(s.radius_m * (1.0 - math.cos(math.radians(deg))), rel=1e-9)


def test_a_ball_over_the_edge_touches_the_edge_and_says_so() -> None:
    s = TouchProbe.ideal()
    edge = ProbePoint(
        "E", (0.2 - 0.001, 0.0, 0.0), (0.0, 0.0, 1.0), SearchSpec("approach", 0.02, 0.02)
    )
    faces_all = trimesh.Trimesh(BOX.vertices, BOX.faces)
    top = np.flatnonzero(faces_all.face_normals[:, 2] > 0.9)
    tri_face = np.full(len(BOX.faces), -1)
    tri_face[top] = 0
    probe = _probe(np.eye(4), s, faces=FaceLookup(tri_face, {"E": 0}))
    res = probe(SearchCommand.from_point(edge, np.eye(4)))
    assert res.ok
    # half the ball hangs past the edge: the silhouette is partly off the face
    assert probe.events[0].off_fraction > 0.2
    # a ball centred 1 mm past the edge touches the edge line below its pole
    past = ProbePoint(
        "P", (0.2 + 0.001, 0.0, 0.0), (0.0, 0.0, 1.0), SearchSpec("approach", 0.02, 0.02)
    )
    probe = _probe(np.eye(4), s, faces=FaceLookup(tri_face, {"P": 0}))
    res = probe(SearchCommand.from_point(past, np.eye(4)))
    r = s.radius_m
    drop = r - math.sqrt(r * r - 0.001**2)  # the edge line meets the ball this far up
    assert res.point_m[2] == pytest.approx(-drop, abs=2e-5)  # reads low: off the face
    assert probe.events[0].landing == LANDED_OFF_FACE


def test_failures_are_reasons() -> None:
    probe = _probe(np.eye(4), TouchProbe())
    edge = ProbePoint(
        "F",
        (0.0, 0.2, 0.0),
        (0.0, 0.0, 1.0),
        SearchSpec("edge", 0.02, 0.02, (0.0, 1.0, 0.0)),
        edge_normal=(0.0, 1.0, 0.0),
    )
    assert probe(SearchCommand.from_point(edge, np.eye(4))).reason == (
        "a touch probe cannot run an edge search"
    )
    low = make_transform(None, [0.0, 0.0, -0.05])  # the part 50 mm lower: out of reach
    assert (
        "no contact within 40 mm"
        in _probe(low, TouchProbe())(SearchCommand.from_point(TOP, np.eye(4))).reason
    )
    high = make_transform(None, [0.0, 0.0, 0.03])  # the start lies inside the part
    assert (
        "inside the part"
        in _probe(high, TouchProbe())(SearchCommand.from_point(TOP, np.eye(4))).reason
    )


def test_plan_holds_a_touch_probe_and_old_plans_a_proximity_sensor() -> None:
    plan = stator_plan()
    touch = msgspec.structs.replace(
        plan, validation=msgspec.structs.replace(plan.validation, sensor=TouchProbe())
    )
    text = plan_to_json(touch)
    assert '"kind": "touch"' in text
    assert plan_from_json(text).validation.sensor == TouchProbe()
