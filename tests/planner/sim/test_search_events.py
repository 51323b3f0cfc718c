"""Where a footprint landed (over the whole footprint, against the part's planar faces), and
the adapter from Cell.check_search to a reachability hook."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from calib.models import ProximitySensor, RobotErrorModel
from calib.probing import ProbePoint, SearchCommand
from calib.procedures import RolePoint
from planner.parts.stator import StatorGeometry
from planner.parts.stator_mesh import build_stator_mesh
from planner.program.model import search_keys
from planner.reasons import Reason
from planner.sim.proximity import SimulatedProbe
from planner.sim.raycast import MeshRayCaster
from planner.sim.search_events import (
    LANDED_OFF_FACE,
    PARTLY_OFF_FACE,
    FaceLookup,
    cell_search_hook,
    search_group,
)
from planner.sim.setup import face_lookup

G = StatorGeometry.prototype()
X = (1.0, 0.0, 0.0)


def test_landing_counts_the_footprint_off_its_face() -> None:
    faces = FaceLookup(np.array([0, 0, 1, -1]), {"A": 0})
    assert faces.landing("A", np.array([0, 1, 0, 0])) == (None, 0.0)
    assert faces.landing("A", np.array([0, 2, 3, -1])) == (PARTLY_OFF_FACE, 0.75)
    assert faces.landing("A", np.array([3, 0, 0, 0])) == (LANDED_OFF_FACE, 0.25)
    assert faces.landing("unknown", np.array([3, 3])) == (None, 0.0)
    assert LANDED_OFF_FACE.kind == PARTLY_OFF_FACE.kind == "footprint"


@pytest.fixture(scope="module")
def probe_on_stator() -> tuple[SimulatedProbe, np.ndarray]:
    mesh = build_stator_mesh(G, deformed=False)
    spots = {
        "web": (0.0, float(G.tooth_y_m[5]), float(G.web_z_m[2])),
        "hole": (0.0, float(G.slot_y_m[5]), float(G.layer_z_m[2])),
        "tooth_at_layer": (0.0, float(G.tooth_y_m[5]), float(G.layer_z_m[2])),
        "top": (0.0, float(G.tooth_y_m[5]), -0.004),
    }
    points = [RolePoint("fit", ProbePoint(k, v, X)) for k, v in spots.items()]
    sensor = ProximitySensor(repeatability_sigma_m=0.0)
    faces = face_lookup(mesh, points[:1], sensor.footprint_radius_m)  # the side face's id
    side = faces.intended["web"]
    faces = FaceLookup(faces.triangle_face, {k: side for k in spots})
    probe = SimulatedProbe(
        MeshRayCaster(mesh),
        np.eye(4),
        np.random.default_rng(0),
        sensor=sensor,
        robot_error=RobotErrorModel.none(),
        faces=faces,
    )
    for rp in points:
        assert probe(SearchCommand.from_point(rp.point, np.eye(4))).ok
    return probe, np.array([e.off_fraction for e in probe.events])


def test_stator_landings_over_the_whole_footprint(probe_on_stator) -> None:
    """A web between layers holds the whole 18 mm face; over a hole the centre is off the
    face; over a tooth at a layer's height the face overlaps the holes on both sides by a
    small, known share; near the top edge part of it hangs past the edge."""
    probe, frac = probe_on_stator
    landing = {e.point_id: e.landing for e in probe.events}
    assert landing == {
        "web": None,
        "hole": LANDED_OFF_FACE,
        "tooth_at_layer": PARTLY_OFF_FACE,
        "top": PARTLY_OFF_FACE,
    }
    r = ProximitySensor().radius_m
    # the hole's share of the face: a 5 mm hole in a 9 mm disk (its neighbours are too far)
    assert frac[1] == pytest.approx((G.hole_diameter_m / 2) ** 2 / r**2, abs=0.01)
    # two 5 mm holes 12 mm to either side: lens overlaps of a 9 mm and a 5 mm circle
    d, R, h = G.slot_pitch_m / 2, r, G.hole_diameter_m / 2
    lens = (
        R**2 * np.arccos((d**2 + R**2 - h**2) / (2 * d * R))
        + h**2 * np.arccos((d**2 + h**2 - R**2) / (2 * d * h))
        - 0.5 * np.sqrt((-d + R + h) * (d + R - h) * (d - R + h) * (d + R + h))
    )
    assert frac[2] == pytest.approx(2 * lens / (np.pi * R**2), abs=0.01)
    # 4 mm below the top: the segment of the disk above the edge
    t = 0.004 / r
    seg = (np.arccos(t) - t * np.sqrt(1 - t * t)) / np.pi
    assert frac[3] == pytest.approx(seg, abs=0.01)


def test_search_ids_of_roles_and_retakes() -> None:
    pts = [
        RolePoint("A", ProbePoint("yoke_left", (0, 0, 0), X)),
        RolePoint("fit", ProbePoint("P1", (0, 1, 0), X)),
        RolePoint("fit", ProbePoint("P2", (0, 2, 0), X)),
    ]
    aliases = search_keys(pts)
    assert aliases["A"] == aliases["A2"] == aliases["yoke_left"] == "yoke_left"
    assert "fit" not in aliases and aliases["P2"] == "P2"
    assert search_group("PX1_3") == search_group("PX6_41") != search_group("P1")


def test_cell_hook_reports_the_cells_reason_with_its_kind_and_pair() -> None:
    seen = []
    causes = {
        "far": Reason("joint_limit", "at 0.0 mm: joint 3 at limit (j3)"),
        "hit": Reason(
            "collision", "at 12.0 mm: link_6 hits clamp (clearance -1.0 mm)", ("link_6", "clamp")
        ),
    }

    def check_search(command, step_m, exact_clearance):  # the Cell method's arguments
        assert exact_clearance is False  # the verdict only
        seen.append((command.point_id, step_m))
        cause = causes.get(command.point_id)
        return SimpleNamespace(feasible=cause is None, cause=cause)

    hook = cell_search_hook(SimpleNamespace(check_search=check_search), step_m=0.004)
    near, far, hit = (
        SearchCommand.from_point(ProbePoint(pid, (0, 0, 0), (1, 0, 0)), np.eye(4))
        for pid in ("near", "far", "hit")
    )
    assert hook(near) is None
    assert hook(far) == Reason(
        "joint_limit", "unreachable or colliding: at 0.0 mm: joint 3 at limit (j3)"
    )
    refused = hook(hit)
    assert refused is not None and (refused.kind, refused.pair) == (
        "collision",
        ("link_6", "clamp"),
    )
    assert str(refused) == (
        "unreachable or colliding: at 12.0 mm: link_6 hits clamp (clearance -1.0 mm)"
    )
    assert seen == [("near", 0.004), ("far", 0.004), ("hit", 0.004)]


def test_cell_hook_refuses_an_infeasible_answer_without_its_cause() -> None:
    def check_search(command, step_m, exact_clearance):
        return SimpleNamespace(feasible=False, cause=None, reason="words only")

    hook = cell_search_hook(SimpleNamespace(check_search=check_search))
    cmd = SearchCommand.from_point(ProbePoint("p", (0, 0, 0), (1, 0, 0)), np.eye(4))
    with pytest.raises(TypeError, match="must carry its cause"):
        hook(cmd)
