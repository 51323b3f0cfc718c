"""One Monte Carlo trial, and the per-process state the trials share (see
:func:`planner.sim.montecarlo.validate`).

A worker process holds one :class:`SimulationSetup` and one ray caster of the part
(:func:`init_worker`); each trial draws its own misplacement and noise from its own seed
(:func:`run_trial`), so results do not depend on which process runs which trial.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import msgspec
import numpy as np
import trimesh
from numpy.typing import NDArray

from calib.errors import InputError, ProbeFailedError
from calib.estimators.best_fit import best_fit
from calib.estimators.layout import constraint_set
from calib.frames import motion_between
from calib.models import AccuracyField, Misplacement, RobotErrorModel
from calib.models.proximity import ProximitySensor
from calib.paper.settings import Hultman2013
from calib.paper.stator_procedure import check_stator_points, run_stator_procedure
from calib.probing import ProbePoint
from calib.procedures.hultman2013 import ROLES
from planner.parts.stator import StatorGeometry
from planner.sim.probe import ReachabilityHook
from planner.sim.raycast import MeshRayCaster
from planner.sim.sensors import sensor_kind

FloatArray = NDArray[np.float64]

#: Edge searches run this far inside the face along the sensor axis by default, m.
DEFAULT_EDGE_INSET_M = 0.003


def default_settings(
    sensor: ProximitySensor, edge_inset_m: float = DEFAULT_EDGE_INSET_M, **kwargs: Any
) -> Hultman2013:
    """A-H settings for a simulation: ``kwargs`` (e.g. ``beta1_rad``) plus, unless given, the
    sensor's analytic straight-edge offset for ``edge_inset_m`` as ``edge_event_offset_m``.

    Without it F and H are taken where the sensor stops detecting, ~6 mm past the edge with the
    default sensor, and the WOCS z origin is off by as much.
    """
    kwargs.setdefault("edge_event_offset_m", sensor.edge_event_offset_m(edge_inset_m))
    return Hultman2013(**kwargs)


def resolved_settings(
    settings: Hultman2013, sensor: ProximitySensor, edge_inset_m: float = DEFAULT_EDGE_INSET_M
) -> Hultman2013:
    """``settings`` with an unset edge-event offset replaced by the sensor's analytic
    straight-edge offset at ``edge_inset_m`` (what a robot cell measures once on a reference
    edge; see :meth:`ProximitySensor.edge_event_offset_m`)."""
    if settings.edge_event_offset_m is not None:
        return settings
    offset = sensor.edge_event_offset_m(edge_inset_m)
    return msgspec.structs.replace(settings, edge_event_offset_m=offset)


@dataclass(frozen=True)
class SimulationSetup:
    """Everything a worker needs to run trials (picklable).

    Attributes:
        points: the nominal probe points A-H, wobj frame.
        geometry: the stator geometry (for the mesh, slot holes and landings).
        T_base_wobj_nominal: ``(4, 4)`` the nominal part pose, base frame.
        sensor: sensor model.
        robot_error: robot error model.
        misplacement: part placement tolerance.
        pivot_wobj_m: ``(3,)`` pivot of the misplacement rotation, nominal wobj, m.
        accuracy_field: the robot's absolute-accuracy field for this run, or None.
        settings: settings of the A-H procedure; ``None`` (default): the paper's, with the
            sensor's analytic straight-edge offset for ``edge_inset_m`` as the known edge offset.
        edge_inset_m: edge searches run this far inside the face along the sensor axis.
    """

    points: Mapping[str, ProbePoint]
    geometry: StatorGeometry
    T_base_wobj_nominal: FloatArray
    sensor: ProximitySensor
    robot_error: RobotErrorModel
    misplacement: Misplacement
    pivot_wobj_m: FloatArray
    accuracy_field: AccuracyField | None = None
    settings: Hultman2013 | None = None
    edge_inset_m: float = DEFAULT_EDGE_INSET_M
    edge_tolerance_m: float = 2e-5

    def __post_init__(self) -> None:
        if self.settings is None:
            object.__setattr__(self, "settings", default_settings(self.sensor, self.edge_inset_m))


@dataclass(frozen=True)
class TrialResult:
    """One trial.

    Attributes:
        failure: ``""`` or ``"<point>: <reason>"``.
        landings: ``"<point>: <landing>"`` of approaches that landed over a hole or off a face.
        delta_procedure: ``(6,)`` procedure frame error ``(dx, dy, dz, rx, ry, rz)`` in the true
            wobj axes (m, rad); NaN on failure.
        delta_best_fit: ``(6,)`` the same for the least-squares fit.
    """

    failure: str
    landings: tuple[str, ...]
    delta_procedure: FloatArray
    delta_best_fit: FloatArray


class TrialRunner:
    """Runs trials of one setup: holds the part's ray caster and the A-H layout (built once).

    Args:
        setup: what every trial shares.
        mesh: the true part mesh in its own (wobj) frame, metres.
        cell: optional cell whose work object each trial moves to the true part pose before
            the searches are vetted by a reachability hook (in this process only; the cell is
            not picklable). ``None``: no cell.
    """

    def __init__(self, setup: SimulationSetup, mesh: trimesh.Trimesh, cell: Any = None) -> None:
        self.setup = setup
        self.caster = MeshRayCaster(mesh)
        self.layout = check_stator_points(setup.points)
        self.constraints = constraint_set([setup.points[k] for k in ROLES])
        self.cell = cell
        self.simulator = sensor_kind(setup.sensor).load()

    def run_trial(
        self, seed: np.random.SeedSequence, reach: ReachabilityHook | None
    ) -> TrialResult:
        """One simulated calibration with its own misplacement and noise from ``seed``."""
        setup = self.setup
        rng = np.random.default_rng(seed)
        T_nom = setup.T_base_wobj_nominal
        T_true = T_nom @ setup.misplacement.sample(rng, setup.pivot_wobj_m)
        if self.cell is not None and reach is not None:  # the cell's part goes where it really is
            self.cell.move_work_object(self.cell.T_world_base @ T_true)
        probe = self.simulator(
            self.caster,
            T_true,
            rng,
            sensor=setup.sensor,
            robot_error=setup.robot_error,
            accuracy_field=setup.accuracy_field,
            geometry=setup.geometry,
            reachability=reach,
            edge_inset_m=setup.edge_inset_m,
            edge_tolerance_m=setup.edge_tolerance_m,
        )
        nan6 = np.full(6, np.nan)
        failure = ""
        d_proc = d_fit = nan6
        settings = setup.settings
        assert settings is not None  # set in SimulationSetup.__post_init__
        try:
            res = run_stator_procedure(self.layout, T_nom, probe, settings)
            d_proc = motion_between(T_true, res.T_base_wobj)
            q = np.array([res.measured_m[k] for k in ROLES])
            edge = settings.edge_offset_m  # the same known edge offset as the procedure
            for k in ("F", "H"):
                q[ROLES.index(k)] -= edge * res.commands[k].direction
            fit = best_fit(self.constraints, q, T_nom, sigma_m=1e-4)
            d_fit = motion_between(T_true, fit.T_base_wobj)
        except ProbeFailedError as exc:
            failure = f"{exc.point_id}: {exc.reason}"
        except InputError as exc:  # degenerate measurements: a failed calibration, not a crash
            failure = f"procedure: {exc}"
        landings = tuple(f"{e.point_id}: {e.landing}" for e in probe.events if e.landing)
        return TrialResult(failure, landings, d_proc, d_fit)

    def run_chunk(
        self, seeds: list[np.random.SeedSequence], reach: ReachabilityHook | None = None
    ) -> list[TrialResult]:
        """Trials of ``seeds`` in order."""
        return [self.run_trial(s, reach) for s in seeds]


#: The runner of a worker process (set by :func:`init_worker`, the pool's initializer).
_PROCESS_RUNNER: list[TrialRunner] = []


def init_worker(setup: SimulationSetup, mesh: trimesh.Trimesh) -> None:
    """Process-pool initializer: build this process's :class:`TrialRunner` (no cell)."""
    _PROCESS_RUNNER[:] = [TrialRunner(setup, mesh)]


def run_chunk_in_worker(seeds: list[np.random.SeedSequence]) -> list[TrialResult]:
    """Run ``seeds`` on this worker process's runner (see :func:`init_worker`)."""
    return _PROCESS_RUNNER[0].run_chunk(seeds)
