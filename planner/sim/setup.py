"""What every trial of a validation shares: :class:`SimulationSetup`, and how it is built.

The setup holds the plan's points with their roles, the procedure (its registry name and its
settings, with the sensor's edge-event offset filled in), the nominal pose, the physical models
(sensor, robot error, misplacement), the true part's planar faces for the landing check, and
the x-offset run if the plan has one. It is picklable: worker processes get a copy.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import trimesh
from numpy.typing import NDArray

from calib.models import Misplacement, RobotErrorModel
from calib.models.robot_error import AccuracyField
from calib.models.sensor import SensorModel
from calib.paper.settings import Hultman2013
from calib.probing import ProbePoint
from calib.procedures import RolePoint
from calib.procedures.base import edge_offset_of
from planner.faces.array_cache import ArrayCache
from planner.faces.checks import check_plan_faces
from planner.faces.detection import find_planar_faces
from planner.program.model import MeasuringProgram, search_keys
from planner.program.settings import DEFAULT_EDGE_INSET_M
from planner.sim.search_events import FaceLookup
from planner.sim.xoffset import XOffsetSetup

FloatArray = NDArray[np.float64]


def default_settings(
    sensor: SensorModel, edge_inset_m: float = DEFAULT_EDGE_INSET_M, **kwargs: Any
) -> Hultman2013:
    """A-H settings for a simulation: ``kwargs`` (e.g. ``beta1_rad``) plus, unless given, the
    sensor's analytic straight-edge offset for ``edge_inset_m`` as ``edge_event_offset_m``.

    Without it F and H are taken where the sensor stops detecting, ~6 mm past the edge with the
    default sensor, and the WOCS z origin is off by as much.
    """
    kwargs.setdefault("edge_event_offset_m", sensor.edge_event_offset_m(edge_inset_m))
    return Hultman2013(**kwargs)


def default_pivot(points: Sequence[RolePoint] | Mapping[str, ProbePoint]) -> FloatArray:
    """Centroid of the nominal probe points (wobj, m): the default misplacement pivot."""
    pts = points.values() if isinstance(points, Mapping) else [rp.point for rp in points]
    return np.mean([p.position_m for p in pts], axis=0)


def face_lookup(
    mesh: trimesh.Trimesh,
    points: Sequence[RolePoint],
    footprint_radius_m: float,
    cache: ArrayCache | None = None,
) -> FaceLookup:
    """The true part's planar faces and the face each search should land on.

    The faces are found with the sensor's footprint (:func:`find_planar_faces`, cached per
    mesh in memory, and in ``cache`` when given: the jobs pass the cell's disk cache); each
    point's face is the one :func:`check_plan_faces` finds under it.
    """
    radius = max(float(footprint_radius_m), 1e-4)
    faces = find_planar_faces(
        mesh, min_area_m2=np.pi * radius**2, footprint_radius_m=radius, cache=cache
    )
    checks = check_plan_faces(faces, [rp.point for rp in points], footprint_radius_m=radius)
    by_id = {rp.point.id: c.face_id for rp, c in zip(points, checks, strict=True)}
    intended = {alias: by_id[pid] for alias, pid in search_keys(points).items()}
    return FaceLookup(np.asarray(faces.face_id, dtype=np.int64), intended)


@dataclass(frozen=True)
class SimulationSetup:
    """Everything a worker needs to run trials (picklable).

    The program holds the plan's points with their roles, the procedure and its settings
    (edge-event offset resolved, :func:`planner.program.settings.resolved_settings`):
    :attr:`points`, :attr:`method` and :attr:`settings` read them from it, so a setup cannot
    simulate one procedure and predict another.

    Attributes:
        program: the measuring program each trial executes (the one a controller runs for
            the plan: :func:`planner.program.build.measuring_program`).
        T_base_wobj_nominal: ``(4, 4)`` the nominal part pose, base frame.
        sensor: the sensor model (any kind of :data:`calib.models.SensorSettings`).
        robot_error: robot error model.
        misplacement: part placement tolerance.
        pivot_wobj_m: ``(3,)`` pivot of the misplacement rotation, nominal wobj, m.
        accuracy_field: the robot's absolute-accuracy field for this run, or None.
        faces: the true part's planar faces for the landing check, or None.
        xoffset: the paper's x-offset run after the procedure, or None.
        edge_inset_m: edge searches run this far inside the face along the sensor axis.
        edge_tolerance_m: edge bisection tolerance, m.
    """

    program: MeasuringProgram
    T_base_wobj_nominal: FloatArray
    sensor: Any
    robot_error: RobotErrorModel
    misplacement: Misplacement
    pivot_wobj_m: FloatArray
    accuracy_field: AccuracyField | None = None
    faces: FaceLookup | None = None
    xoffset: XOffsetSetup | None = None
    edge_inset_m: float = DEFAULT_EDGE_INSET_M
    edge_tolerance_m: float = 2e-5

    @property
    def points(self) -> tuple[RolePoint, ...]:
        """The plan's probe points with their roles, wobj frame (the program's)."""
        return self.program.points

    @property
    def method(self) -> str:
        """The procedure's registry name (:data:`calib.procedures.PROCEDURES`)."""
        return self.program.method

    @property
    def settings(self) -> Any:
        """The procedure's settings, edge-event offset resolved (the program's)."""
        return self.program.settings

    @property
    def edge_offset_m(self) -> float:
        """The edge-event offset the procedure removes from edge searches, m."""
        return edge_offset_of(self.settings)

    @property
    def noise_figures(self) -> dict[str, float]:
        """The 1-sigma noise figures of this setup, m, by name (for the report)."""
        s = self.sensor.search_noise("approach", self.edge_inset_m).sensor_sigma_m
        out = {"sensor": s, "robot repeatability": self.robot_error.repeatability_sigma_m}
        if self.robot_error.tcp_sigma_m:
            out["TCP"] = self.robot_error.tcp_sigma_m
        if self.robot_error.accuracy_amplitude_m:
            out["robot accuracy field (RMS, not in the prediction)"] = (
                self.robot_error.accuracy_amplitude_m
            )
        return out
