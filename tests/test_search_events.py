"""Where a footprint landed, and the adapter from Cell.check_search to a reachability hook."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from calib.probing import ProbePoint, SearchCommand
from planner.parts.stator import StatorGeometry
from planner.sim.search_events import cell_search_hook, footprint_landing

G = StatorGeometry.full_section()
SIDE = np.array([-1.0, 0.0, 0.0])  # sensor axis looking at the side face (normal +x)
SHORT = np.array([0.0, -1.0, 0.0])  # looking at the short side (normal +y)


def test_side_face_landings() -> None:
    hole = np.array([0.0, G.slot_y_m[10], G.layer_z_m[3]])
    web = np.array([0.0, G.tooth_y_m[10], G.web_z_m[3]])
    near_top = np.array([0.0, G.tooth_y_m[10], -0.005])
    assert footprint_landing(G, hole, SIDE, 0.009) == "over slot hole"
    assert footprint_landing(G, web, SIDE, 0.009) == ""
    assert footprint_landing(G, near_top, SIDE, 0.009) == "off face"
    # a hole more than a hole radius away from the centre is not a landing over a hole
    assert footprint_landing(G, hole + np.array([0.0, 0.0051, 0.0]), SIDE, 0.009) == ""


def test_short_side_landings() -> None:
    assert footprint_landing(G, np.array([-0.03, 0.0, -0.15]), SHORT, 0.009) == ""
    assert footprint_landing(G, np.array([-0.005, 0.0, -0.15]), SHORT, 0.009) == "off face"
    assert footprint_landing(G, np.array([-0.03, 0.0, -0.195]), SHORT, 0.009) == "off face"


def test_cell_hook_reports_the_cells_reason() -> None:
    seen = []

    def check_search(command, step_m):  # the Cell method's signature
        seen.append((command.point_id, step_m))
        bad = command.point_id == "far"
        return SimpleNamespace(feasible=not bad, reason="joint 3 at limit" if bad else "")

    hook = cell_search_hook(SimpleNamespace(check_search=check_search), step_m=0.004)
    near = SearchCommand.from_point(ProbePoint("near", (0, 0, 0), (1, 0, 0)), np.eye(4))
    far = SearchCommand.from_point(ProbePoint("far", (0, 0, 0), (1, 0, 0)), np.eye(4))
    assert hook(near) == ""
    assert hook(far) == "unreachable or colliding: joint 3 at limit"
    assert seen == [("near", 0.004), ("far", 0.004)]
