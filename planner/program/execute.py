"""Execute a measuring program against a probe: what a validate trial and the prediction run.

:func:`execute` runs a :class:`~planner.program.model.MeasuringProgram` the way its controller
does, against any :data:`calib.probing.Probe` (the simulated sensor on the misplaced part, the
ideal part of the linearisation):

- a **nominal** program measures every point once, in program order, commanded in the nominal
  work object, and the frame is the procedure's :meth:`~calib.procedures.base.ProcedureKind.
  estimate` of the recorded points (what ``wobjcal calibrate`` computes from the program's
  results file);
- an **adaptive** program that steers itself (best fit, 3-2-1: its update steps name the points
  they fit, :mod:`planner.program.steering`) runs its steps: each search in the estimate so far,
  each update between them; the frame is the last update's;
- the adaptive A-H program is the procedure's own step-by-step run
  (:meth:`~calib.procedures.base.ProcedureKind.run`), each search commanded in the frame the
  program estimated so far (the RAPID module is proven equal to it in
  ``tests/planner/export/test_export_rapid_adaptive.py`` and
  ``tests/planner/program/test_program.py``).

Either way every search goes through :class:`ProgramProbe`, which runs it as the exported program
does (:mod:`planner.program.searches`): from the point's safe start, an edge point first
approaching the face its edge search runs along and then searching from the measured face point.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from calib.errors import ProbeFailedError
from calib.frames import check_transform, invert_transform, transform_points
from calib.probing import Probe, ProbePoint, ProbeResult, SearchCommand
from calib.procedures import ProcedureRun, RolePoint, procedure_kind
from planner.program.model import (
    FACE_APPROACH,
    MeasuringProgram,
    SearchStep,
    UpdateStep,
    search_keys,
)
from planner.program.safety import SafetySpec
from planner.program.searches import program_searches
from planner.program.steering import steer

FloatArray = NDArray[np.float64]


@dataclass
class ProgramProbe:
    """A probe that runs each search a procedure commands as the exported program runs it.

    The procedure commands a search from the plan's start (:meth:`SearchCommand.from_point` in
    its estimate); the program starts it at the point's safe start in that estimate, and an
    edge point approaches its face first (key ``"<key>@face"``) and runs the edge search from
    the measured face point up to where the plan's search ends. An edge search the procedure
    starts elsewhere (from an earlier measurement) is run from there, as commanded.

    Args:
        probe: the probe that runs the searches (simulated sensor, ideal part).
        points: the plan's points with their roles.
        safety: the misplacement tolerance the safe starts are computed for.
    """

    probe: Probe
    points: Sequence[RolePoint]
    safety: SafetySpec
    _keys: Mapping[str, str] = field(init=False, repr=False)
    _by_id: Mapping[str, ProbePoint] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self._keys = search_keys(self.points)
        self._by_id = {rp.point.id: rp.point for rp in self.points}

    def __call__(self, cmd: SearchCommand) -> ProbeResult:
        """Run ``cmd`` as the program does; the result is that of its last (recorded) search."""
        point = self._by_id.get(self._keys.get(cmd.point_id, ""))
        if point is None:  # not a plan point (e.g. the x-offset run): as commanded
            return self.probe(cmd)
        T = np.asarray(cmd.T_base_wobj_estimate, dtype=np.float64)
        plan_start = T[:3, :3] @ _plan_start_wobj(point) + T[:3, 3]
        moved = not bool(np.all(np.abs(np.asarray(cmd.start_m) - plan_start) <= 1e-9))
        if moved and point.search.kind == "edge":  # an edge search from an earlier point
            measured = transform_points(invert_transform(T), np.asarray(cmd.start_m))
            searches = program_searches(point, T, self.safety, measured_start_wobj=measured)
            return self.probe(replace(searches[1].command, point_id=cmd.point_id))
        return self.run_point(point, cmd.point_id, T)

    def run_point(self, point: ProbePoint, key: str, T: FloatArray) -> ProbeResult:
        """Run the program's searches of ``point`` (search key ``key``) from its safe start in
        the estimate ``T`` ``(4, 4)`` (base frame, m): what :meth:`__call__` runs for a
        command from the plan's start, and what a steered program runs at each search step."""
        built = _searches_in_wobj(point, self.safety)
        if point.search.kind == "approach":
            return self.probe(_moved(built[0], T, key))
        face = self.probe(_moved(built[0], T, key + FACE_APPROACH))
        if face.point_m is None:
            return ProbeResult(None, f"approach to the face: {face.reason}")
        edge = _moved(built[1], T, key)
        start = np.asarray(face.point_m, dtype=np.float64)
        end = edge.start_m + edge.length_m * edge.direction
        run = float((end - start) @ edge.direction)
        if run <= 0.0:
            return ProbeResult(None, "the measured face point lies past the end of the edge search")
        return self.probe(replace(edge, start_m=start, length_m=run))


@lru_cache(maxsize=4096)
def _searches_in_wobj(point: ProbePoint, safety: SafetySpec) -> tuple[SearchCommand, ...]:
    """The program's searches of ``point`` built in the wobj frame (the estimate ``I``)."""
    return tuple(s.command for s in program_searches(point, np.eye(4), safety))


@lru_cache(maxsize=4096)
def _plan_start_wobj(point: ProbePoint) -> FloatArray:
    """``(3,)`` where the plan's search of ``point`` starts, wobj frame, m."""
    return SearchCommand.from_point(point, np.eye(4)).start_m


def _moved(cmd: SearchCommand, T: FloatArray, point_id: str) -> SearchCommand:
    """``cmd`` (built in the frame ``I``) as built in the frame ``T``, named ``point_id``:
    every point and direction moved by ``T`` (each by its own product: one product of all
    five can differ in the last bit), and ``T`` its estimate."""
    R, t = T[:3, :3], T[:3, 3]
    stop = None if cmd.stop_normal is None else R @ cmd.stop_normal
    return SearchCommand(
        point_id=point_id,
        kind=cmd.kind,
        start_m=R @ cmd.start_m + t,
        direction=R @ cmd.direction,
        length_m=cmd.length_m,
        sensor_axis=R @ cmd.sensor_axis,
        T_base_wobj_estimate=T @ cmd.T_base_wobj_estimate,
        nominal_m=R @ cmd.nominal_m + t,
        stop_normal=stop,
    )


def execute(
    program: MeasuringProgram, T_base_wobj_nominal: FloatArray, probe: Probe
) -> ProcedureRun:
    """Run ``program`` with ``probe`` (see the module docstring) and compute its frame with
    the program's procedure settings.

    Args:
        program: the program.
        T_base_wobj_nominal: ``(4, 4)`` the nominal work object, base frame.
        probe: runs one search.

    Raises:
        ProbeFailedError: a search failed (the program stops there).
        InputError: the recorded points define no frame.
    """
    kind = procedure_kind(program.method)
    points, settings = program.points, program.settings
    run_as_program = ProgramProbe(probe, points, program.safety)
    if program.steers_itself:
        return _run_steered(program, T_base_wobj_nominal, run_as_program)
    if program.adaptive:
        return kind.run(list(points), T_base_wobj_nominal, run_as_program, settings)
    by_id = {rp.point.id: rp.point for rp in points}
    measured: dict[str, FloatArray] = {}
    for step in program.searches:
        if not step.recorded:
            continue  # run inside its edge search's step by ProgramProbe
        cmd = SearchCommand.from_point(by_id[step.point_id], T_base_wobj_nominal)
        res = run_as_program(replace(cmd, point_id=step.key))
        if res.point_m is None:
            raise ProbeFailedError(step.key, res.reason or "no reason given")
        q = np.asarray(res.point_m, dtype=np.float64)
        prev = measured.get(step.point_id)
        measured[step.point_id] = q[None] if prev is None else np.vstack([prev, q])
    return kind.estimate(list(points), measured, T_base_wobj_nominal, settings)


def _run_steered(
    program: MeasuringProgram, T_base_wobj: FloatArray, probe: ProgramProbe
) -> ProcedureRun:
    """A program that steers itself: each search in the estimate so far, each update
    (:func:`planner.program.steering.steer`) from the points it names; the frame is the last
    update's."""
    assert program.pivot_m is not None  # set with every update that fits points
    by_id = {rp.point.id: rp.point for rp in program.points}
    pivot = program.pivot_m
    T = check_transform(T_base_wobj, "T_base_wobj").copy()  # each update's result is one too
    measured: dict[str, FloatArray] = {}
    for step in program.steps:
        if isinstance(step, SearchStep) and step.recorded:  # from the plan's start, in T
            res = probe.run_point(by_id[step.point_id], step.key, T)
            if res.point_m is None:
                raise ProbeFailedError(step.key, res.reason or "no reason given")
            measured[step.point_id] = np.asarray(res.point_m, dtype=np.float64)
        elif isinstance(step, UpdateStep) and step.uses:
            pts = [by_id[i] for i in step.uses]
            T = steer(pts, measured, T, pivot, program.scale_m, checked=True)
    return ProcedureRun(T, tuple(measured), measured)
