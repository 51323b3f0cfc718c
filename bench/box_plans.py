"""Plans of every procedure on an ideal box (a stator-sized block without holes or bulge).

Used by ``bench/bench_validate.py`` and ``tests/planner/validate/test_box_prediction.py`` to
compare the
simulated intervals with the predicted ones: on a box there is nothing position-dependent
(no hole, no bulge, flat faces), so the two must agree up to the Monte Carlo's own scatter and
what the prediction leaves out on purpose (the ray bundle's residual error of edge events, kept
small here with a finely sampled sensor face, and the early switch over faces tilted by the
misplacement, second order).

The box is the stator-like block of ``tests/box_part.py``: x in [-0.25, 0], y in [-1.2, 0],
z in [-0.40, 0] m in its wobj frame (side face x = 0, short side y = 0, top z = 0), placed
before the IRB 4400 as the demo stator is.
"""

from __future__ import annotations

import numpy as np
import trimesh

from calib.models import ProximitySensor
from calib.paper.settings import Hultman2013
from calib.paper.stator_layout import example_stator_points
from calib.plan.file import Plan, PlanPoint, Pose, ValidationSpec, WorkObjectSpec
from calib.plan.report_spec import PointOfInterest, ReportSpec
from calib.probing import ProbePoint, SearchSpec
from calib.procedures import BestFit, Iterative, ThreeTwoOne
from planner.parts.stator_demo import nominal_T_base_wobj

#: Box extents (x, y, z) and its centre in its wobj frame, m.
EXTENTS = (0.25, 1.2, 0.40)
CENTRE = (-0.125, -0.6, -0.20)
#: A proximity sensor whose face is sampled finely enough that its edge events follow the exact
#: disk (with the default 256 rays an edge event moves only about 0.9 times as far with the
#: track's standoff, and in steps); the A-H plan, the one with edge searches, uses it.
FINE_SENSOR = ProximitySensor(n_rays=16384, n_scan_rays=37)
#: A point sensor with the default noise: its edge event is the edge itself (the exact disk's
#: limit for a vanishing face), fast enough for tests.
POINT_SENSOR = ProximitySensor(face_diameter_m=0.0, n_rays=1, n_scan_rays=1)
_X, _Y, _Z = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)
_SEARCH = SearchSpec("approach", start_offset_m=0.080, overtravel_m=0.080)


def box_mesh() -> trimesh.Trimesh:
    """The ideal box (12 triangles), wobj frame, metres."""
    mesh = trimesh.creation.box(extents=EXTENTS)
    mesh.apply_translation(CENTRE)
    return mesh


def _points(role: str, spots: list[tuple[str, tuple[float, float, float], tuple]]) -> list:
    return [PlanPoint.from_probe_point(ProbePoint(i, p, n, _SEARCH), role) for i, p, n in spots]


def box_plans(edge_sensor: ProximitySensor = FINE_SENSOR) -> dict[str, Plan]:
    """One plan per procedure on the box, keyed by method: the default proximity sensor, and
    ``edge_sensor`` for the A-H plan (the one with edge searches)."""
    ah = example_stator_points()
    side = [
        ("S1", (0.0, -1.0, -0.3), _X),
        ("S2", (0.0, -0.2, -0.3), _X),
        ("S3", (0.0, -0.6, -0.05), _X),
    ]
    top = [("T1", (-0.05, -0.9, 0.0), _Z), ("T2", (-0.05, -0.2, 0.0), _Z)]
    short = [("C1", (-0.12, 0.0, -0.2), _Y)]
    fit = [*side, ("S4", (0.0, -0.5, -0.35), _X), *top, ("T3", (-0.2, -0.5, 0.0), _Z)]
    fit += [*short, ("C2", (-0.05, 0.0, -0.35), _Y), ("C3", (-0.2, 0.0, -0.05), _Y)]
    methods = {
        "hultman2013": (
            [PlanPoint.from_probe_point(p, role=r) for r, p in ah.items()],
            Hultman2013(),
        ),
        "three_two_one": (
            _points("primary", side) + _points("secondary", top) + _points("tertiary", short),
            ThreeTwoOne(),
        ),
        "best_fit": (_points("fit", fit), BestFit()),
        "iterative": (_points("fit", fit), Iterative()),
    }
    report = ReportSpec(
        levels_percent=(95.5,),
        points_of_interest=[
            PointOfInterest(name="far", position_m=(0.0, -1.2, -0.4), components="xyz")
        ],
        regions=[],
    )
    T = nominal_T_base_wobj()
    return {
        m: Plan(
            name=f"box_{m}",
            work_object=WorkObjectSpec(mesh="box.stl", T_world_wobj=Pose.from_matrix(T)),
            points=pts,
            procedure=proc,
            validation=ValidationSpec(
                sensor=edge_sensor if m == "hultman2013" else ProximitySensor(), report=report
            ),
        )
        for m, (pts, proc) in methods.items()
    }


def agreement(report) -> dict[str, float]:  # type: ignore[no-untyped-def]
    """``{row key: simulated / predicted - 1}`` of the procedure's rows at their first level."""
    out: dict[str, float] = {}
    for r in report.rows:
        if r.key not in out and np.isfinite(r.procedure) and r.procedure_predicted > 0:
            out[r.key] = r.procedure / r.procedure_predicted - 1.0
    return out
