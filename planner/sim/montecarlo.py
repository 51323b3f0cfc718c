"""Monte Carlo validation of a calibration plan against the simulated sensor, robot and part.

Each trial misplaces the true part by a random rigid motion within the tolerance, runs the
paper's step-by-step A-H procedure (:func:`calib.paper.stator_procedure.run_stator_procedure`) with
a :class:`~planner.sim.probe.SimulatedProbe` (each later search commanded in the WOCS estimated so
far, as on the robot), and fits the same measurements by least squares
(:func:`calib.estimators.best_fit.best_fit`) for comparison. The errors of both frames against the
truth are summarised like Table 1 of the paper by :mod:`planner.sim.report`.

Trials are seeded one by one from ``rng`` (``SeedSequence.spawn``), so a run is repeatable and
does not depend on how trials are split over worker processes. The ray-casting scene is built
once per worker; rays are moved into the part frame instead of moving the mesh.
"""

from __future__ import annotations

import logging
import math
import multiprocessing as mp
import os
import time
from collections import Counter
from collections.abc import Callable, Mapping
from concurrent.futures import ProcessPoolExecutor
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
from planner.parts.stator import StatorGeometry
from planner.parts.stator_mesh import build_stator_mesh
from planner.sim.probe import ReachabilityHook, cell_search_hook
from planner.sim.report import ValidationReport, build_report
from planner.sim.trial import (
    DEFAULT_EDGE_INSET_M,
    SimulationSetup,
    TrialResult,
    TrialRunner,
    default_settings,
    init_worker,
    run_chunk_in_worker,
)

__all__ = [
    "DEFAULT_EDGE_INSET_M",
    "ValidationReport",
    "default_pivot",
    "default_settings",
    "validate",
]

FloatArray = NDArray[np.float64]
log = logging.getLogger(__name__)

PROCEDURES = ("hultman2013",)
#: progress(done_trials, total_trials)
ProgressCallback = Callable[[int, int], None]


def default_pivot(points: Mapping[str, ProbePoint]) -> FloatArray:
    """Centroid of the nominal probe points (wobj, m): the default misplacement pivot."""
    return np.mean([p.position_m for p in points.values()], axis=0)


def validate(
    points: Mapping[str, ProbePoint],
    geometry: StatorGeometry,
    T_base_wobj_nominal: ArrayLike,
    n_trials: int,
    rng: np.random.Generator,
    *,
    sensor: ProximitySensor | None = None,
    robot_error: RobotErrorModel | None = None,
    misplacement: Misplacement | tuple[float, float] | None = None,
    procedure: str = "hultman2013",
    mesh: trimesh.Trimesh | None = None,
    pivot_wobj_m: ArrayLike | None = None,
    settings: Hultman2013 | None = None,
    reachability: ReachabilityHook | None = None,
    cell: Any = None,
    reach_trials: int | None = None,
    edge_inset_m: float = DEFAULT_EDGE_INSET_M,
    edge_tolerance_m: float = 2e-5,
    workers: int | None = None,
    progress: ProgressCallback | None = None,
) -> ValidationReport:
    """Simulate the calibration ``n_trials`` times and summarise the errors like Table 1.

    Args:
        points: nominal probe points A-H (wobj frame), e.g. ``demo_cell.stator_ah_points``.
        geometry: the stator geometry; the true part is its (bulged) mesh.
        T_base_wobj_nominal: ``(4, 4)`` nominal part pose, base frame; the procedure starts here.
        n_trials: number of trials (>= 2).
        rng: source of all randomness; the same seed gives the same report.
        sensor: proximity-sensor model (default :class:`ProximitySensor`).
        robot_error: robot error model (default :class:`RobotErrorModel`).
        misplacement: :class:`Misplacement` or ``(max_translation_m, max_angle_rad)``; default
            the paper's experiment, 20 mm and 3 deg.
        procedure: ``"hultman2013"`` (the paper's A-H procedure).
        mesh: the true part mesh in wobj (default: the stator mesh of ``geometry``).
        pivot_wobj_m: ``(3,)`` misplacement pivot (default: centroid of the points).
        settings: A-H procedure settings; by default the paper's, with the sensor's analytic
            straight-edge offset (:meth:`ProximitySensor.edge_event_offset_m`) as the known
            edge-event offset removed from F and H. Build your own with
            :func:`default_settings` (``default_settings(sensor, beta1_rad=...)``) to keep that
            offset: settings with ``edge_event_offset_m = 0`` leave F and H ~6 mm high.
        reachability: optional hook vetting each commanded search (runs in one process).
        cell: optional :class:`planner.cell.cell.Cell` with the part as its work object; each trial
            moves the work object to the true pose and vets every search with
            ``cell.check_search`` (see :func:`planner.sim.probe.cell_search_hook`), so searches
            that become unreachable or collide because the part moved are counted as failures.
            Runs in one process; the work object is put back at the end.
        reach_trials: with ``reachability`` or ``cell``, vet only the first ``reach_trials``
            trials that way (about 0.2 s a trial in the demo cell) and run the rest without it,
            in parallel; ``None`` vets every trial. Each trial draws the same numbers either
            way, so the statistics do not depend on it.
        edge_inset_m: edge-search track inset towards the face, m.
        edge_tolerance_m: edge bisection tolerance, m.
        workers: worker processes (default: ``min(2, os.cpu_count())``; 1 runs in-process).
        progress: called as ``progress(done, total)`` while trials complete.

    Raises:
        InputError: bad arguments (named in the message).
    """
    if procedure not in PROCEDURES:
        raise InputError(f"procedure must be one of {PROCEDURES}, got {procedure!r}")
    if not isinstance(n_trials, int) or not 2 <= n_trials <= MAX_TRIALS:
        raise ShapeError(f"n_trials must be an integer 2 to {MAX_TRIALS:,}, got {n_trials!r}")
    T_nom = check_transform(T_base_wobj_nominal, "T_base_wobj_nominal")
    check_stator_points(points)
    if misplacement is None:
        misplacement = Misplacement()
    elif isinstance(misplacement, tuple):
        misplacement = Misplacement(
            max_translation_m=misplacement[0], max_angle_rad=misplacement[1]
        )
    robot_error = robot_error or RobotErrorModel()
    sensor = sensor or ProximitySensor()
    pivot = default_pivot(points) if pivot_wobj_m is None else np.asarray(pivot_wobj_m, float)
    setup = SimulationSetup(
        points=dict(points),
        geometry=geometry,
        T_base_wobj_nominal=T_nom,
        sensor=sensor,
        robot_error=robot_error,
        misplacement=misplacement,
        pivot_wobj_m=pivot,
        accuracy_field=robot_error.sample_field(rng),
        settings=settings,
        edge_inset_m=edge_inset_m,
        edge_tolerance_m=edge_tolerance_m,
    )
    part = build_stator_mesh(geometry) if mesh is None else mesh
    seeds = np.random.SeedSequence(int(rng.integers(2**63))).spawn(n_trials)
    n_workers = min(2, os.cpu_count() or 1) if workers is None else max(1, int(workers))
    if cell is not None and reachability is None:
        reachability = cell_search_hook(cell)
    n_reach = 0 if reachability is None else n_trials
    if reach_trials is not None and reachability is not None:
        if int(reach_trials) < 0:
            raise ShapeError(f"reach_trials must be >= 0, got {reach_trials!r}")
        n_reach = min(int(reach_trials), n_trials)
    if n_trials - n_reach < 50:
        n_workers = 1
    t0 = time.perf_counter()
    T_cell = None if cell is None else cell.T_world_wobj

    def vetted(done: int, total: int) -> None:  # progress over all trials, vetted ones first
        if progress is not None:
            progress(done, n_trials)

    def later(done: int, total: int) -> None:
        if progress is not None:
            progress(n_reach + done, n_trials)

    try:
        results = []
        if n_reach:
            # vetted trials run here: they move the cell's part to where it really lies
            results = _run_all(setup, part, seeds[:n_reach], 1, reachability, vetted, cell)
        if n_reach < n_trials:
            results += _run_all(setup, part, seeds[n_reach:], n_workers, None, later)
    finally:
        if cell is not None:
            cell.move_work_object(T_cell)
    elapsed = time.perf_counter() - t0
    log.info("validated %d trials in %.2f s on %d workers", n_trials, elapsed, n_workers)
    failures = Counter(r.failure for r in results if r.failure)
    landings = Counter(item for r in results for item in r.landings)
    return build_report(
        geometry=geometry,
        delta_procedure=np.array([r.delta_procedure for r in results]),
        delta_best_fit=np.array([r.delta_best_fit for r in results]),
        failures=dict(failures),
        landings=dict(landings),
        elapsed_s=elapsed,
        workers=n_workers,
        reach_checked=n_reach,
    )


def _run_all(
    setup: SimulationSetup,
    mesh: trimesh.Trimesh,
    seeds: list[np.random.SeedSequence],
    n_workers: int,
    reach: ReachabilityHook | None,
    progress: ProgressCallback | None,
    cell: Any = None,
) -> list[TrialResult]:
    """Run ``seeds`` in this process (1 worker; the only place a ``reach`` hook or a ``cell``
    is used) or on a process pool, each process with its own :class:`TrialRunner`."""
    total = len(seeds)
    chunk = max(1, min(100, math.ceil(total / (8 * n_workers))))
    chunks = [seeds[i : i + chunk] for i in range(0, total, chunk)]
    out: list[TrialResult] = []
    if n_workers == 1:
        runner = TrialRunner(setup, mesh, cell)
        for c in chunks:
            out.extend(runner.run_chunk(c, reach))
            if progress is not None:
                progress(len(out), total)
        return out
    ctx = mp.get_context("fork") if "fork" in mp.get_all_start_methods() else None
    pool = ProcessPoolExecutor(n_workers, ctx, _init_pool_worker, (setup, mesh))
    try:
        for res in pool.map(run_chunk_in_worker, chunks):
            out.extend(res)
            if progress is not None:
                progress(len(out), total)
    except BaseException:  # Ctrl-C, SIGTERM, an error: no worker left running, no waiting
        procs = list((getattr(pool, "_processes", None) or {}).values())
        for proc in procs:
            proc.kill()
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
    return out


def _init_pool_worker(setup: SimulationSetup, mesh: trimesh.Trimesh) -> None:
    """Pool initializer: die with the parent process (Linux), then :func:`init_worker`.

    Without it a parent killed by SIGTERM or SIGKILL leaves its workers running.
    """
    _die_with_parent()
    init_worker(setup, mesh)


def _die_with_parent() -> None:
    """Ask Linux to SIGKILL this process when its parent dies (``prctl(PR_SET_PDEATHSIG)``)."""
    import ctypes
    import signal
    import sys

    if not sys.platform.startswith("linux"):
        return
    parent = os.getppid()
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)  # PR_SET_PDEATHSIG = 1
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:  # the parent died before the call
        os._exit(1)
