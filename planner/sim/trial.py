"""One Monte Carlo trial, and the per-process state the trials share (see
:func:`planner.sim.montecarlo.simulate`; the worker processes: :mod:`planner.sim.trial_pool`).

A worker process holds one :class:`~planner.sim.setup.SimulationSetup` and one ray caster of
the part (:func:`init_worker`); each trial draws its own misplacement and noise from its own
seed (:meth:`TrialRunner.run_trial`), so results do not depend on which process runs which
trial. A trial executes the plan's measuring program (:func:`planner.program.execute.execute`:
the program a controller runs, nominal or adaptive) with the simulator registered for the plan's
sensor, so every procedure validates the same way and as the robot runs it; then
the best fit of the same measurements fed as the procedure is fed
(:class:`calib.procedures.comparison.FedFit`), and the x-offset run when the plan has one.

A trial that stops at a failed search keeps the search and its reason
(:class:`~planner.sim.search_events.SearchFailure`, :func:`search_failure`): the words the
procedure reports, the kind and pair of the search's event, so that the report counts the
failures by kind without reading their words.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import trimesh
from numpy.typing import NDArray

from calib.errors import InputError, ProbeFailedError
from calib.frames import motion_between
from calib.probing import SearchCommand
from calib.procedures.comparison import FedFit
from planner.program.execute import execute
from planner.program.model import FACE_APPROACH
from planner.reasons import Reason
from planner.sim.raycast import MeshRayCaster
from planner.sim.search_events import ProbeEvent, ReachabilityHook, SearchFailure, search_group
from planner.sim.sensors import sensor_kind
from planner.sim.setup import DEFAULT_EDGE_INSET_M, SimulationSetup
from planner.sim.xoffset import run_xoffset

__all__ = [
    "DEFAULT_EDGE_INSET_M",
    "SimulationSetup",
    "TrialResult",
    "TrialRunner",
    "init_worker",
    "run_chunk_in_worker",
    "search_failure",
]

FloatArray = NDArray[np.float64]
#: A trial's seed, or ``(noise seed, position seed)`` for the paper's protocol.
TrialSeed = np.random.SeedSequence | tuple[np.random.SeedSequence, np.random.SeedSequence]


@dataclass(frozen=True)
class TrialResult:
    """One trial.

    Attributes:
        failure: ``""``, ``"<search>: <reason>"`` (``str(failed_search)``), or ``"procedure:
            <why>"`` when the measurements define no frame.
        searched: the id of every search run, in order.
        events: the searches that failed or landed off their face (or partly).
        delta_procedure: ``(6,)`` procedure frame error ``(dx, dy, dz, rx, ry, rz)`` in the true
            wobj axes (m, rad); NaN on failure.
        delta_best_fit: ``(6,)`` the same for the best fit of the same measurements.
        xoffset_x_m: ``(H,)`` x errors of the slot targets with the x-offset matrix (true wobj
            axes, m), or ``None`` without an x-offset run (NaN when it failed).
        xoffset_failure: ``""``, ``"<search>: <reason>"`` of a failed x-offset run, or
            the ``<why>`` of an x-offset run refused as bad input.
        failed_search: the search the calibration stopped at, with its reason and kind;
            ``None`` when it did not stop at a search (it calibrated, or its measurements
            define no frame).
        xoffset_failed_search: the same for the x-offset run.
    """

    failure: str
    searched: tuple[str, ...]
    events: tuple[ProbeEvent, ...]
    delta_procedure: FloatArray
    delta_best_fit: FloatArray
    xoffset_x_m: FloatArray | None = None
    xoffset_failure: str = ""
    failed_search: SearchFailure | None = None
    xoffset_failed_search: SearchFailure | None = None

    @property
    def landings(self) -> tuple[str, ...]:
        """``"<search>: <landing>"`` of the approaches that landed off their face (or partly)."""
        return tuple(f"{search_group(e.point_id)}: {e.landing}" for e in self.events if e.landing)


class TrialRunner:
    """Runs trials of one setup: holds the part's ray caster (built once).

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
        self.simulator = sensor_kind(setup.sensor).load()
        self.fed_fit = FedFit([rp.point for rp in setup.points], setup.edge_offset_m)
        self.cell = cell

    def run_trial(self, seed: TrialSeed, reach: ReachabilityHook | None) -> TrialResult:
        """One simulated calibration with its own misplacement and noise from ``seed``.

        ``seed`` may be a pair ``(noise, position)``: the misplacement is then drawn from the
        position seed, so trials that share it see the same part pose (the paper's protocol).

        A hook that vets many paths at once (a ``many`` method: the cell's
        :class:`~planner.sim.search_events.ProgramSearchHook`) is asked after the trial, about
        every path the trial ran, in one call; only when it refuses one is the trial run again
        with the hook asked search by search, to stop where the robot would. A hook's pass
        changes nothing in a trial (it draws no noise and records no event), so the result is
        the one the hook asked search by search gives. Anything raised on the way (by the
        trial run without the hook, or by ``many``) runs the trial again search by search too:
        it then raises, or fails the trial, where the robot's run would.
        """
        many = getattr(reach, "many", None)
        if reach is None or many is None:
            return self._run(seed, reach)
        asked = _PathsRun()
        try:
            result = self._run(seed, asked)
            passed = all(why is None for why in many(asked.commands))
        except Exception:  # the search-by-search run below says what it is
            passed = False
        return result if passed else self._run(seed, reach)

    def _run(self, seed: TrialSeed, reach: ReachabilityHook | None) -> TrialResult:
        """:meth:`run_trial` with ``reach`` asked search by search."""
        setup = self.setup
        noise_seed, position_seed = seed if isinstance(seed, tuple) else (seed, None)
        rng = np.random.default_rng(noise_seed)
        pos_rng = rng if position_seed is None else np.random.default_rng(position_seed)
        T_nom = setup.T_base_wobj_nominal
        T_true = T_nom @ setup.misplacement.sample(pos_rng, setup.pivot_wobj_m)
        tcp_error = (
            setup.robot_error.sample_tcp_error_m(rng) if setup.robot_error.tcp_sigma_m else None
        )
        if self.cell is not None and reach is not None:  # the cell's part goes where it really is
            self.cell.move_work_object(self.cell.T_world_base @ T_true)
        probe = self.simulator(
            self.caster,
            T_true,
            rng,
            sensor=setup.sensor,
            robot_error=setup.robot_error,
            accuracy_field=setup.accuracy_field,
            faces=setup.faces,
            tcp_error_m=tcp_error,
            reachability=reach,
            edge_inset_m=setup.edge_inset_m,
            edge_tolerance_m=setup.edge_tolerance_m,
        )
        nan6 = np.full(6, np.nan)
        failure = xfail = ""
        failed: SearchFailure | None = None
        xfailed: SearchFailure | None = None
        d_proc = d_fit = nan6
        x_err: FloatArray | None = None
        try:
            run = execute(setup.program, T_nom, probe)
            d_proc = motion_between(T_true, run.T_base_wobj)
            d_fit = motion_between(T_true, self.fed_fit(run).T_base_wobj)
        except ProbeFailedError as exc:
            failed = search_failure(exc, probe.events)
            failure = str(failed)
            d_proc = d_fit = nan6
        except InputError as exc:  # degenerate measurements: a failed calibration, not a crash
            failure = f"procedure: {exc}"
            d_proc = d_fit = nan6
        if setup.xoffset is not None:
            x_err = np.full(setup.xoffset.targets_wobj[..., 0].size, np.nan)
            if not failure:
                try:
                    x_err = run_xoffset(setup.xoffset, probe, run.T_base_wobj, T_true)[:, 0]
                except ProbeFailedError as exc:
                    xfailed = search_failure(exc, probe.events)
                    xfail = str(xfailed)
                except InputError as exc:
                    xfail = str(exc)  # said as "x-offset <why>" (planner.sim.summary)
        searched = tuple(e.point_id for e in probe.events)
        notable = tuple(e for e in probe.events if e.cause is not None or e.landing is not None)
        return TrialResult(failure, searched, notable, d_proc, d_fit, x_err, xfail, failed, xfailed)

    def run_chunk(
        self, seeds: list[TrialSeed], reach: ReachabilityHook | None = None
    ) -> list[TrialResult]:
        """Trials of ``seeds`` in order."""
        return [self.run_trial(s, reach) for s in seeds]


class _PathsRun:
    """A reachability hook that passes every path and keeps them (:meth:`TrialRunner.run_trial`
    asks the real hook about all of them at once afterwards)."""

    def __init__(self) -> None:
        self.commands: list[SearchCommand] = []

    def __call__(self, command: SearchCommand) -> None:
        self.commands.append(command)

    def many(self, commands: Sequence[SearchCommand]) -> list[None]:
        self.commands.extend(commands)
        return [None] * len(commands)


def search_failure(exc: ProbeFailedError, events: Sequence[ProbeEvent]) -> SearchFailure:
    """The search ``exc`` names and why it failed, with the kind of its event.

    Every program and procedure stops at its first failed search, so a search the simulated
    sensor failed is the last event (an edge point's approach to its face, ``"F@face"``, stands
    for its edge search ``"F"``): the reason keeps that event's kind and pair (``search`` from
    the sensor, the cell's from the reachability hook) in the words the procedure reports
    (``exc.reason``: the event's, or the program's around them, ``"approach to the face:
    ..."``). A search the program or the procedure refused before running it (a measured start
    past the search's end) has no failed event: a ``search`` reason.
    """
    words = exc.reason or "no reason given"
    last = events[-1] if events else None
    ran = last is not None and last.point_id in (exc.point_id, exc.point_id + FACE_APPROACH)
    if last is None or last.cause is None or not ran:
        return SearchFailure(exc.point_id, Reason("search", words))
    return SearchFailure(exc.point_id, dataclasses.replace(last.cause, text=words, note=""))


#: The runner of a worker process (set by :func:`init_worker`, the pool's initializer).
_PROCESS_RUNNER: list[TrialRunner] = []


def init_worker(setup: SimulationSetup, mesh: trimesh.Trimesh) -> None:
    """Process-pool initializer: build this process's :class:`TrialRunner` (no cell)."""
    _PROCESS_RUNNER[:] = [TrialRunner(setup, mesh)]


def run_chunk_in_worker(seeds: list[TrialSeed]) -> list[TrialResult]:
    """Run ``seeds`` on this worker process's runner (see :func:`init_worker`)."""
    return _PROCESS_RUNNER[0].run_chunk(seeds)
