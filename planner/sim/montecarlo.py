"""Monte Carlo validation of a calibration plan against the simulated sensor, robot and part.

:func:`simulate` runs any plan's setup (:class:`~planner.sim.setup.SimulationSetup`: any
procedure of the registry, any sensor kind, any work-object mesh): each trial misplaces the true
part by a random rigid motion within the tolerance, executes the plan's measuring program with
the simulated sensor (each search as the controller's program commands it, in the nominal frame
or the estimate so far), fits the same
measurements by least squares fed as the procedure is fed, and runs the x-offset run if the plan
has one (:mod:`planner.sim.trial`). The errors against the truth become the report's rows, each
beside the interval predicted from the program's linearisation (:mod:`planner.sim.predict`).
:func:`validate` is the same for the paper's A-H points on a stator geometry, as a script
would call it.

Trials are seeded one by one from ``rng`` (``SeedSequence.spawn``), so a run is repeatable and
does not depend on how trials are split over worker processes. A run starts and finishes in two
halves (:mod:`planner.sim.simulation_run`): the workers start first, so that the caller may
check the plan in its cell meanwhile. The ray-casting scene is built
once per worker; rays are moved into the part frame instead of moving the mesh.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray

from calib.errors import InputError, ShapeError
from calib.frames import check_transform
from calib.models import Misplacement, RobotErrorModel
from calib.models.proximity import ProximitySensor
from calib.paper.settings import Hultman2013
from calib.paper.stator_procedure import check_stator_points
from calib.plan.models import MAX_TRIALS
from calib.probing import ProbePoint
from calib.procedures import RolePoint
from planner.parts.stator import StatorGeometry
from planner.parts.stator_demo import STATOR_REPORT
from planner.parts.stator_mesh import build_stator_mesh
from planner.program.build import build_program
from planner.program.controllers import controller
from planner.program.safety import SafetySpec
from planner.program.settings import DEFAULT_EDGE_INSET_M, resolved_settings
from planner.sim.proximity import ReachabilityHook, cell_search_hook
from planner.sim.report import PAPER_TABLE1, ValidationReport
from planner.sim.report_points import report_rows
from planner.sim.rows import RowSpec
from planner.sim.setup import SimulationSetup, default_pivot, default_settings, face_lookup
from planner.sim.simulation_run import start_simulation

__all__ = [
    "DEFAULT_EDGE_INSET_M",
    "ValidationReport",
    "default_pivot",
    "default_settings",
    "simulate",
    "simulate_stator_ah",
]

FloatArray = NDArray[np.float64]

#: progress(done_trials, total_trials)
ProgressCallback = Callable[[int, int], None]


def simulate(
    setup: SimulationSetup,
    mesh: trimesh.Trimesh,
    rows: list[RowSpec],
    n_trials: int,
    rng: np.random.Generator,
    *,
    reachability: ReachabilityHook | None = None,
    cell: Any = None,
    reach_trials: int | None = None,
    protocol: tuple[int, int] | None = None,
    paper: Mapping[tuple[str, float], float] | None = None,
    workers: int | None = None,
    progress: ProgressCallback | None = None,
) -> ValidationReport:
    """Simulate the calibration of ``setup`` ``n_trials`` times and report every row.

    Args:
        setup: what every trial shares (see :mod:`planner.sim.setup`); its accuracy field is
            drawn here, once per run, from ``rng``.
        mesh: the true part mesh in wobj, metres.
        rows: the report's rows (:func:`planner.sim.report_points.report_rows`).
        n_trials: number of trials (>= 2).
        rng: source of all randomness; the same seed gives the same report.
        reachability: optional hook vetting each commanded search (runs in one process).
        cell: optional :class:`planner.cell.cell.Cell` with the part as its work object; each
            trial moves the work object to the true pose and vets every search with
            ``cell.check_search`` (:func:`planner.sim.proximity.cell_search_hook`). Runs in one
            process; the work object is put back at the end.
        reach_trials: with ``reachability`` or ``cell``, vet only the first ``reach_trials``
            trials that way and run the rest without it, in parallel; ``None`` vets every
            trial. Each trial draws the same numbers either way.
        protocol: ``(positions, repeats)``: also run the paper's protocol (every position's
            errors centred on that position's mean) beside the default.
        paper: the paper's half-widths by (row key, level), shown beside the rows.
        workers: worker processes (default: ``min(2, os.cpu_count())``; 1 runs in-process).
        progress: called as ``progress(done, total)`` while trials complete.

    Raises:
        InputError: bad arguments (named in the message), or a plan that cannot calibrate even
            on the ideal part (from the prediction; the workers already started are stopped).
    """
    if cell is not None and reachability is None:
        reachability = cell_search_hook(cell)
    n_reach = 0 if reachability is None else n_trials
    if reach_trials is not None and reachability is not None:
        if int(reach_trials) < 0:
            raise ShapeError(f"reach_trials must be >= 0, got {reach_trials!r}")
        n_reach = min(int(reach_trials), n_trials) if isinstance(n_trials, int) else 0
    run = start_simulation(
        setup, mesh, n_trials, rng, vetted=n_reach, protocol=protocol, workers=workers
    )
    return run.finish(rows, reachability=reachability, cell=cell, paper=paper, progress=progress)


def stator_setup(
    points: Mapping[str, ProbePoint],
    geometry: StatorGeometry,
    T_base_wobj_nominal: ArrayLike,
    *,
    mesh: trimesh.Trimesh | None = None,
    sensor: ProximitySensor | None = None,
    robot_error: RobotErrorModel | None = None,
    misplacement: Misplacement | tuple[float, float] | None = None,
    settings: Hultman2013 | None = None,
    pivot_wobj_m: ArrayLike | None = None,
    edge_inset_m: float = DEFAULT_EDGE_INSET_M,
    edge_tolerance_m: float = 2e-5,
    program: str | None = None,
) -> tuple[SimulationSetup, trimesh.Trimesh]:
    """The setup and mesh of the paper's A-H procedure on a stator (see :func:`validate`), with
    the program the controller ``program`` runs (``None``: the default, adaptive RAPID)."""
    T_nom = check_transform(T_base_wobj_nominal, "T_base_wobj_nominal")
    check_stator_points(points)
    if misplacement is None:
        misplacement = Misplacement()
    elif isinstance(misplacement, tuple):
        misplacement = Misplacement(
            max_translation_m=misplacement[0], max_angle_rad=misplacement[1]
        )
    sensor = sensor or ProximitySensor()
    cfg = default_settings(sensor, edge_inset_m) if settings is None else settings
    part = build_stator_mesh(geometry) if mesh is None else mesh
    role_points = tuple(RolePoint(role, p) for role, p in points.items())
    pivot = default_pivot(points) if pivot_wobj_m is None else np.asarray(pivot_wobj_m, float)
    resolved = resolved_settings(cfg, sensor, edge_inset_m)
    safety = SafetySpec(
        max_translation_m=misplacement.max_translation_m,
        max_angle_rad=misplacement.max_angle_rad,
        pivot_wobj_m=(float(pivot[0]), float(pivot[1]), float(pivot[2])),
        sensing_distance_m=sensor.sensing_distance_m,
    )
    setup = SimulationSetup(
        program=build_program(role_points, resolved, safety, controller(program)),
        T_base_wobj_nominal=T_nom,
        sensor=sensor,
        robot_error=robot_error or RobotErrorModel(),
        misplacement=misplacement,
        pivot_wobj_m=pivot,
        faces=face_lookup(part, role_points, sensor.footprint_radius_m),
        edge_inset_m=edge_inset_m,
        edge_tolerance_m=edge_tolerance_m,
    )
    return setup, part


def simulate_stator_ah(
    points: Mapping[str, ProbePoint],
    geometry: StatorGeometry,
    T_base_wobj_nominal: ArrayLike,
    n_trials: int,
    rng: np.random.Generator,
    *,
    procedure: str = "hultman2013",
    reachability: ReachabilityHook | None = None,
    cell: Any = None,
    reach_trials: int | None = None,
    workers: int | None = None,
    progress: ProgressCallback | None = None,
    **kwargs: Any,
) -> ValidationReport:
    """Simulate the paper's A-H procedure on a stator ``n_trials`` times (Table 1 rows).

    The script-level form of :func:`simulate` for ``points`` A-H (wobj frame, e.g.
    :func:`planner.parts.stator_demo.stator_ah_points`) on ``geometry``'s mesh; a plan of any
    procedure on any part validates with :func:`planner.validate.job.validate_plan`.

    Args:
        points: nominal probe points A-H, keyed by role.
        geometry: the stator geometry; the true part is its (bulged) mesh.
        T_base_wobj_nominal: ``(4, 4)`` nominal part pose, base frame.
        n_trials: number of trials (>= 2).
        rng: source of all randomness.
        procedure: ``"hultman2013"`` (the only procedure of this form).
        reachability, cell, reach_trials, workers, progress: as :func:`simulate`.
        **kwargs: ``mesh``, ``sensor``, ``robot_error``, ``misplacement``, ``settings``,
            ``pivot_wobj_m``, ``edge_inset_m``, ``edge_tolerance_m``, ``program`` of
            :func:`stator_setup`
            (settings default to the paper's with the sensor's analytic edge offset).

    Raises:
        InputError: bad arguments (named in the message).
    """
    if procedure != "hultman2013":
        raise InputError(f"procedure must be 'hultman2013' here, got {procedure!r}")
    if not isinstance(n_trials, int) or not 2 <= n_trials <= MAX_TRIALS:
        raise ShapeError(f"n_trials must be an integer 2 to {MAX_TRIALS:,}, got {n_trials!r}")
    setup, part = stator_setup(points, geometry, T_base_wobj_nominal, **kwargs)
    return simulate(
        setup,
        part,
        report_rows(STATOR_REPORT, part, geometry),
        n_trials,
        rng,
        reachability=reachability,
        cell=cell,
        reach_trials=reach_trials,
        paper=PAPER_TABLE1,
        workers=workers,
        progress=progress,
    )
