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
does not depend on how trials are split over worker processes. The ray-casting scene is built
once per worker; rays are moved into the part frame instead of moving the mesh.
"""

from __future__ import annotations

import dataclasses
import logging
import os
import time
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray

from calib.errors import InputError, ShapeError
from calib.frames import check_transform
from calib.limits import MAX_PROTOCOL_TRIALS
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
from planner.sim.error_map import error_map
from planner.sim.predict import predict
from planner.sim.proximity import ReachabilityHook, cell_search_hook
from planner.sim.report import PAPER_TABLE1, ValidationReport
from planner.sim.report_points import report_rows
from planner.sim.rows import RowSpec
from planner.sim.setup import SimulationSetup, default_pivot, default_settings, face_lookup
from planner.sim.summary import build_report
from planner.sim.trial import TrialResult, TrialSeed, run_all

__all__ = [
    "DEFAULT_EDGE_INSET_M",
    "ValidationReport",
    "default_pivot",
    "default_settings",
    "simulate",
    "simulate_stator_ah",
]

FloatArray = NDArray[np.float64]
log = logging.getLogger(__name__)

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
            on the ideal part (from the prediction, before any trial runs).
    """
    if not isinstance(n_trials, int) or not 2 <= n_trials <= MAX_TRIALS:
        raise ShapeError(f"n_trials must be an integer 2 to {MAX_TRIALS:,}, got {n_trials!r}")
    if protocol is not None and (min(protocol) < 2 or len(protocol) != 2):
        raise ShapeError(f"protocol must be (positions, repeats), each >= 2, got {protocol!r}")
    if protocol is not None and protocol[0] * protocol[1] > MAX_PROTOCOL_TRIALS:
        raise ShapeError(
            f"protocol: {protocol[0]:,} x {protocol[1]:,} trials, at most "
            f"{MAX_PROTOCOL_TRIALS:,} (every trial's result stays in memory until the report)"
        )
    prediction = predict(setup)  # before the run: a plan that cannot work fails here
    setup = dataclasses.replace(setup, accuracy_field=setup.robot_error.sample_field(rng))
    seeds: list[TrialSeed] = list(np.random.SeedSequence(int(rng.integers(2**63))).spawn(n_trials))
    extra: list[TrialSeed] = []
    if protocol is not None:
        base = np.random.SeedSequence(int(rng.integers(2**63)))
        for pos in base.spawn(protocol[0]):
            extra += [(noise, pos) for noise in pos.spawn(protocol[1])]
    n_workers = min(2, os.cpu_count() or 1) if workers is None else max(1, int(workers))
    if cell is not None and reachability is None:
        reachability = cell_search_hook(cell)
    n_reach = 0 if reachability is None else n_trials
    if reach_trials is not None and reachability is not None:
        if int(reach_trials) < 0:
            raise ShapeError(f"reach_trials must be >= 0, got {reach_trials!r}")
        n_reach = min(int(reach_trials), n_trials)
    total = n_trials + len(extra)
    if total - n_reach < 50:
        n_workers = 1
    t0 = time.perf_counter()
    T_cell = None if cell is None else cell.T_world_wobj

    def vetted(done: int, _total: int) -> None:  # progress over all trials, vetted ones first
        if progress is not None:
            progress(done, total)

    def later(done: int, _total: int) -> None:
        if progress is not None:
            progress(n_reach + done, total)

    try:
        results: list[TrialResult] = []
        if n_reach:
            # vetted trials run here: they move the cell's part to where it really lies
            results = run_all(setup, mesh, seeds[:n_reach], 1, reachability, vetted, cell)
        if n_reach < total:
            results += run_all(setup, mesh, seeds[n_reach:] + extra, n_workers, None, later)
    finally:
        if cell is not None:
            cell.move_work_object(T_cell)
    elapsed = time.perf_counter() - t0
    log.info("validated %d trials in %.2f s on %d workers", total, elapsed, n_workers)
    main, proto = results[:n_trials], results[n_trials:]
    report = build_report(
        setup, main, proto, protocol, rows, prediction, paper, elapsed, n_workers, n_reach
    )
    pois = {
        r.key: r.points_wobj[0].copy()
        for r in rows
        if r.points_wobj is not None and len(r.points_wobj) == 1
    }
    return dataclasses.replace(
        report,
        points_of_interest=pois,
        probe_points_wobj=np.array([rp.point.position_m for rp in setup.points], dtype=float),
        error_map=error_map(report.delta_procedure, mesh),
    )


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
