"""Exported URScript programs run in :mod:`tests.urscript_interp` against an ideal sensor.

Every shipped plan (``assets/plans/*.json``) and generated variants of them are exported with
``planner.export.export_files(job, "urscript")`` and run to the end against a part misplaced at
the plan's tolerance. A nominal program's ``meas_<ID>`` must equal what an independent
computation of the point's searches gives (``program_searches`` of
``planner/program/searches.py``: from the safe start along the nominal direction to the target
end; an edge point's edge search from the measured face point); an adaptive program (best fit,
3-2-1, A-H: ``job.program("urscript").adaptive``) must ask the searches that executing its
measuring program (``planner.program.execute``, what ``wobjcal validate`` simulates) asks, keep
the points it measures, and end with its frame in ``wobj``; all to 1e-6 mm (an adaptive
program's later searches to 1e-5 mm, :data:`ADAPTIVE_TOL_M`). The sensor is
:class:`tests.box_part.BoxProbe` where the plan's points lie on that box, else
:class:`PlaneProbe` (each point's nominal face plane moved by the true pose). The plans' A-H
edge-event offset is set to 0 (measured): these ideal sensors report an edge at the edge.

The programs run as exported: the interpreter compiles them as the controller does (block
keywords reserved, argument counts checked), so a parameter named ``end`` or a ``textmsg`` with
three arguments, two bugs the writer once had, fail here (the ``as_exported`` tests).
"""

from __future__ import annotations

import typing
from collections.abc import Callable
from pathlib import Path

import msgspec
import numpy as np
import pytest

from calib.errors import ProbeFailedError, WobjcalError
from calib.frames import (
    invert_transform,
    matrix_from_rotvec,
    random_transform,
    rotvec_from_matrix,
    transform_directions,
    transform_points,
)
from calib.paper.xoffset import xoffset_probe_points
from calib.plan.file import Plan, PlanPoint, Search, load_plan
from calib.probing import ProbeResult, SearchCommand
from calib.procedures import ProcedureRun, ProcedureSettings, method_of, procedure_kind
from planner.export import export_files
from planner.export.job import (
    ExportJob,
    TargetPair,
    ToolData,
    build_job,
    default_sensor_rotation,
)
from planner.export.text import identifier
from planner.export.urscript_layout import result_variable, search_slots, slot_table
from planner.export.urscript_probe import names_of
from planner.plan_cell import nominal_T_base_wobj
from planner.program import execute
from planner.program.model import FACE_APPROACH
from tests.box_part import BoxProbe, distance_to_box
from tests.planner.export.test_export_rapid_adaptive import full_misplacement, rapid_search
from tests.reference_data import plan_cases
from tests.urscript_interp import (
    AT_START,
    Pose,
    SearchFn,
    UrMachine,
    UrRuntimeError,
    UrSyntaxError,
)

REPO = Path(__file__).resolve().parents[3]
PLANS = sorted((REPO / "assets" / "plans").glob("*.json"))
#: :data:`PLANS` as cases, the plate's marked ``reference`` (their mesh is in ``../shared``).
PLAN_CASES = plan_cases(PLANS)
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"
#: 1e-6 mm: the ideal probe and the interpreter are exact up to rounding.
TOL_M = 1e-9
#: 1e-5 mm for an adaptive program: its later searches are commanded in a frame estimated from
#: points measured from targets written to 1e-9 m, which carries that rounding on.
ADAPTIVE_TOL_M = 1e-8
NOT_FOUND = "ERR_WHLSEARCH"


# ------------------------------------------------------------------ ideal sensors
class PlaneProbe:
    """An ideal sensor on the plan's faces, each the nominal face plane moved by the true pose.

    A search is answered on the faces of the point whose nominal or true position lies
    nearest the commanded line (a nominal program commands it in the nominal frame, an
    adaptive one in the frame estimated so far). Approach (``neg_flank``
    False): where the TCP crosses the point's face plane from outside. Edge search: where the
    foot of the sensor axis on the face plane (the face the edge search runs along) crosses the
    plane through the edge point normal to ``edge_normal`` (else the edge direction). Both give
    the commanded TCP at the event, base frame, m, or an error string as ``rapid_search``:
    ``"ERR_SIGSUPSEARCH"`` (at the level at the start) or ``"ERR_WHLSEARCH"`` (not found).

    Args:
        plan: the plan.
        T_base_true: ``(4, 4)`` the true work object in the robot base frame, m.
        T_base_nominal: ``(4, 4)`` the nominal one the program was made for, m.
    """

    def __init__(self, plan: Plan, T_base_true: np.ndarray, T_base_nominal: np.ndarray) -> None:
        self.T_base_true = T_base_true
        # (nominal anchor, true point on the face, true outward normal), base frame
        self.faces: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        # (nominal anchor, face point, face normal, edge point, edge normal), base frame
        self.edges: list[tuple[np.ndarray, ...]] = []
        # the true anchor of each face and edge (the nominal anchor moved by the misplacement)
        self.moved = invert_transform(T_base_nominal)
        for p in plan.points:
            pos, n, s = np.asarray(p.position_m, float), np.asarray(p.normal, float), p.search
            d = None if s.edge_direction is None else np.asarray(s.edge_direction, float)
            face = pos if d is None else pos - s.start_offset_m * d
            true_face = (transform_points(T_base_true, face), transform_directions(T_base_true, n))
            self.faces.append((transform_points(T_base_nominal, face), *true_face))
            if d is not None:
                m = d if p.edge_normal is None else np.asarray(p.edge_normal, float)
                edge = (transform_points(T_base_true, pos), transform_directions(T_base_true, m))
                self.edges.append((transform_points(T_base_nominal, pos), *true_face, *edge))

    def __call__(
        self, start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg_flank: bool
    ) -> object:
        length = float(np.linalg.norm(end - start))
        u = (end - start) / length
        if neg_flank:
            _, face_p, face_n, edge_p, edge_m = min(
                self.edges, key=lambda e: self._off(e[0], start, u)
            )
            return _leave_face(start, u, length, axis, face_p, face_n, edge_p, edge_m)
        _, point, normal = min(self.faces, key=lambda f: self._off(f[0], start, u))
        return _enter_plane(start, u, length, point, normal)

    def _off(self, anchor: np.ndarray, start: np.ndarray, u: np.ndarray) -> float:
        """Distance of the line from the nominal anchor or from the true one."""
        true = transform_points(self.T_base_true @ self.moved, anchor)
        return min(_off_line(anchor, start, u), _off_line(true, start, u))


def _off_line(p: np.ndarray, start: np.ndarray, u: np.ndarray) -> float:
    """Distance of ``p`` from the line ``start + t u``."""
    d = p - start
    return float(np.linalg.norm(d - (d @ u) * u))


def _enter_plane(
    start: np.ndarray, u: np.ndarray, length: float, point: np.ndarray, normal: np.ndarray
) -> object:
    h0 = float((start - point) @ normal)
    if h0 <= 0.0:
        return AT_START
    rate = float(u @ normal)
    if rate >= 0.0 or -h0 / rate > length:
        return NOT_FOUND
    return start - h0 / rate * u


def _leave_face(
    start: np.ndarray,
    u: np.ndarray,
    length: float,
    axis: np.ndarray,
    face_p: np.ndarray,
    face_n: np.ndarray,
    edge_p: np.ndarray,
    edge_m: np.ndarray,
) -> object:
    # foot(t) = q(t) + lam(t) axis on the face plane; g(t) = (foot(t) - edge_p) . edge_m
    a_n = float(axis @ face_n)
    foot0 = start - float((start - face_p) @ face_n) / a_n * axis
    foot_rate = u - float(u @ face_n) / a_n * axis
    g0, g1 = float((foot0 - edge_p) @ edge_m), float(foot_rate @ edge_m)
    if g0 >= 0.0:
        return AT_START
    if g1 <= 0.0 or -g0 / g1 > length:
        return NOT_FOUND
    return start - g0 / g1 * u


def matches_the_box(plan: Plan) -> bool:
    """Every point lies on :data:`tests.box_part` 's box with its normal pointing out."""
    for p in plan.points:
        pos, n = np.asarray(p.position_m), np.asarray(p.normal)
        if abs(distance_to_box(pos)) > 1e-9 or distance_to_box(pos + 1e-3 * n) < 0.999e-3:
            return False
    return True


def ideal_search(plan: Plan, T_base_true: np.ndarray, T_base_nominal: np.ndarray) -> SearchFn:
    """:class:`BoxProbe` when the plan's points lie on the box, else :class:`PlaneProbe`."""
    if matches_the_box(plan):
        return rapid_search(BoxProbe(T_base_true))
    return PlaneProbe(plan, T_base_true, T_base_nominal)


class Recorder:
    """A search callback that records every call ``(start, end, axis, neg_flank)``."""

    def __init__(self, search: SearchFn) -> None:
        self.search = search
        self.calls: list[tuple[np.ndarray, np.ndarray, np.ndarray, bool]] = []

    def __call__(
        self, start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg_flank: bool
    ) -> object:
        self.calls.append((start.copy(), end.copy(), axis.copy(), neg_flank))
        return self.search(start, end, axis, neg_flank)


# ------------------------------------------------------------------ the reference
def _search_once(
    search: SearchFn, start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg_flank: bool
) -> np.ndarray | None:
    answer = search(start, end, axis, neg_flank)
    if isinstance(answer, str):
        assert not isinstance(answer, str) or answer != AT_START, "sensor at its level at start"
        return None
    return np.asarray(answer, float)


def expected_measurement(t: TargetPair, T_nom: np.ndarray, search: SearchFn) -> np.ndarray | None:
    """What the program must measure for ``t`` (base frame, m), or ``None`` (not found).

    Computed from the job alone (as ``program_searches`` says): an approach point searches
    from its safe start to its end; an edge point approaches its face from the safe start to
    the face end, then searches from the measured face point along the nominal direction up to
    the plane through the end normal to that direction. Sensor axis: the target's +z.
    """
    safe = (T_nom @ t.safe_start)[:3, 3]
    end_T = T_nom @ t.T_wobj_end
    if t.kind == "approach":
        return _search_once(search, safe, end_T[:3, 3], end_T[:3, 2], False)
    face_T = T_nom @ t.face_end
    face = _search_once(search, safe, face_T[:3, 3], face_T[:3, 2], False)
    if face is None:
        return None
    start_T = T_nom @ t.T_wobj_start
    d = end_T[:3, 3] - start_T[:3, 3]
    d /= np.linalg.norm(d)
    stop = face + float((end_T[:3, 3] - face) @ d) * d
    return _search_once(search, face, stop, end_T[:3, 2], True)


# ------------------------------------------------------------------ helpers
def export_text(job: ExportJob) -> str:
    """The job's URScript text, or a skip when the export refuses the plan."""
    try:
        return export_files(job, "urscript")[".script"]
    except WobjcalError as exc:  # InputError and the planner's errors derive from it
        pytest.skip(f"the URScript export refuses this plan: {exc}")


def build(
    plan: Plan,
    T_nom: np.ndarray,
    tool: ToolData | None = None,
    rotations: dict[str, np.ndarray] | None = None,
) -> tuple[ExportJob, str]:
    """The export job and its text (skipped when the plan cannot be built or exported)."""
    try:
        job = build_job(plan, T_nom, tool or ToolData(T_flange_tcp=np.eye(4)), rotations)
    except WobjcalError as exc:
        pytest.skip(f"no export job for this plan: {exc}")
    return job, export_text(job)


def measured(machine: UrMachine, t: TargetPair) -> list[float]:
    """``meas_<ID>`` of the target: ``[code, x, y, z]``."""
    value = machine.variables[identifier("meas_" + t.point_id)]
    assert isinstance(value, list) and len(value) == 4, value
    return value


def is_adaptive(job: ExportJob) -> bool:
    """The URScript writer writes ``job``'s adaptive program (its measuring program is
    adaptive: best fit and 3-2-1 steer themselves, A-H with the job's A-H specifics)."""
    program = job.program("urscript")
    return program.steers_itself or (program.adaptive and job.adaptive is not None)


def run_and_compare(job: ExportJob, text: str, search: SearchFn, **options: object) -> UrMachine:
    """Run the program against ``search`` and check every point against the reference."""
    program = Recorder(search)
    machine = UrMachine(text, program, **options).run()  # type: ignore[arg-type]
    assert machine.finished
    if is_adaptive(job):
        compare_adaptive(job, machine, program, search)
        return machine
    assert not machine.halted
    reference = Recorder(search)
    for t in job.targets:
        want = expected_measurement(t, job.T_base_wobj, reference)
        got = measured(machine, t)
        if want is None:
            assert got == [1.0, 0.0, 0.0, 0.0], (t.point_id, got)
        else:
            assert got[0] == 0.0, (t.point_id, got)
            assert np.abs(np.array(got[1:]) - want).max() < TOL_M, (t.point_id, got, want)
    # the program asked exactly the reference's searches, in the same order
    assert len(program.calls) == len(reference.calls)
    for a, b in zip(program.calls, reference.calls, strict=True):
        for x, y in zip(a[:3], b[:3], strict=True):
            assert np.abs(x - y).max() < TOL_M
        assert a[3] == b[3]
    assert [r.search.neg_flank for r in machine.searches] == [c[3] for c in program.calls]  # type: ignore[union-attr]
    return machine


#: A recorded search the reference never ran (the program stopped before it).
NOT_RUN = "not run"


def compare_adaptive(
    job: ExportJob, machine: UrMachine, program: Recorder, search: SearchFn
) -> None:
    """An adaptive program asked the searches, kept the points and ended with the frame of
    its measuring program executed with ``search`` (``planner.program.execute``), to
    :data:`ADAPTIVE_TOL_M`; a failed
    search stopped both there, with the points before it kept."""
    prog = job.program("urscript")
    reference = Recorder(search)
    results: list[tuple[str, np.ndarray | None]] = []

    def probe(cmd: SearchCommand) -> ProbeResult:
        end = cmd.start_m + cmd.length_m * cmd.direction
        answer = reference(cmd.start_m, end, cmd.sensor_axis, cmd.kind == "edge")
        assert not isinstance(answer, str) or answer != AT_START, "sensor at its level at start"
        point = None if isinstance(answer, str) else np.asarray(answer, dtype=float)
        results.append((cmd.point_id, point))
        return ProbeResult(point, str(answer) if point is None else "", travel_m=0.0)

    try:
        run: ProcedureRun | None = execute(prog, job.T_base_wobj, probe)
    except ProbeFailedError:
        run = None
    assert machine.halted == (run is None), machine.messages[-3:]
    # each recorded search's result in the reference, in program order
    expected: list[np.ndarray | str | None] = []
    pending = list(results)
    for step in prog.searches:
        if not step.recorded:
            continue
        if pending and pending[0][0] == step.key + FACE_APPROACH:
            face = pending.pop(0)[1]
            if face is None:  # the approach to the face failed: so did its edge search
                expected.append(None)
                continue
        expected.append(pending.pop(0)[1] if pending else NOT_RUN)
    assert not pending
    got = np.asarray(machine.variables["measured"], dtype=float).reshape(-1, 3)
    codes = machine.variables["measured_code"]
    table = slot_table(job, prog)
    names = dict(
        zip(
            (t.point_id for t in job.targets),
            names_of([t.point_id for t in job.targets]),
            strict=True,
        )
    )
    for want, slot in zip(expected, search_slots(job, prog), strict=True):
        pid, take = table[slot]
        var = machine.variables[result_variable(names[pid], take)]
        if isinstance(want, str):
            assert codes[slot] == -1.0 and var == [-1.0, 0.0, 0.0, 0.0], (pid, take)
        elif want is None:
            assert codes[slot] == 1.0 and var == [1.0, 0.0, 0.0, 0.0], (pid, take)
        else:
            assert codes[slot] == 0.0 and var[0] == 0.0, (pid, take)
            assert np.abs(got[slot] - want).max() < ADAPTIVE_TOL_M, (pid, take, got[slot], want)
            assert np.abs(np.array(var[1:]) - want).max() < ADAPTIVE_TOL_M
    # the program asked the reference's searches, in the same order (then the x-offset run's)
    extra = 0
    settings = prog.settings
    if run is not None and getattr(settings, "xoffset", None) is not None:
        run_x = settings.xoffset
        extra = sum(len(row) for row in xoffset_probe_points(run_x.grid, run_x.layers, run_x.teeth))
    assert len(program.calls) == len(reference.calls) + extra
    for a, b in zip(program.calls, reference.calls, strict=False):
        for x, y in zip(a[:3], b[:3], strict=True):
            assert np.abs(x - y).max() < ADAPTIVE_TOL_M
        assert a[3] == b[3]
    assert [r.search.neg_flank for r in machine.searches] == [c[3] for c in program.calls]  # type: ignore[union-attr]
    if run is not None:
        T = machine.frame("wobj")
        assert np.abs(T[:3, 3] - run.T_base_wobj[:3, 3]).max() < ADAPTIVE_TOL_M
        assert np.linalg.norm(rotvec_from_matrix(T[:3, :3].T @ run.T_base_wobj[:3, :3])) < 1e-8
    assert np.abs(machine.frame("wobj_nominal") - job.T_base_wobj).max() < 1e-8


def load(path: Path) -> Plan:
    """The plan at ``path``; an A-H plan with its edge-event offset measured as 0 (the ideal
    sensors here report an edge at the edge; unset, every face takes the sensor model's)."""
    plan = load_plan(path)
    if plan.method == "hultman2013":
        proc = msgspec.structs.replace(plan.procedure, edge_event_offset_m=0.0)
        plan = msgspec.structs.replace(plan, procedure=proc)
    return plan


def nominal_stator() -> Plan:
    """The stator plan under the best fit: a nominal program (its frame update takes approach
    searches only, the plan has edge searches), for the error paths of a nominal program."""
    plan = SHAPES["procedure_best_fit"](load(STATOR))
    assert not job_of(plan).program("urscript").adaptive
    return plan


def job_of(plan: Plan) -> ExportJob:
    return build_job(plan, nominal_T_base_wobj(plan), ToolData(T_flange_tcp=np.eye(4)))


def slot_points(machine: UrMachine, job: ExportJob) -> tuple[np.ndarray, list[float]]:
    """An adaptive program's ``measured`` (``(slots, 3)``, base, m) and ``measured_code``."""
    got = np.asarray(machine.variables["measured"], dtype=float).reshape(-1, 3)
    return got, list(machine.variables["measured_code"])


def misplaced(plan: Plan, T_nom: np.ndarray, seed: int) -> np.ndarray:
    """``T_base_true`` misplaced exactly at the plan's tolerance (seeded)."""
    return T_nom @ full_misplacement(plan, np.random.default_rng(seed))


def _other_procedure(settings: typing.Any) -> Callable[[Plan], Plan]:
    """The plan under another procedure, each point given its role there (its own when it
    fits, else from the geometry; points without one dropped)."""

    def change(plan: Plan) -> Plan:
        roles = {rp.point.id: rp.role for rp in procedure_kind(settings).assign(plan.role_points())}
        points = [
            msgspec.structs.replace(p, role=roles[p.id]) for p in plan.points if p.id in roles
        ]
        return msgspec.structs.replace(plan, procedure=settings, points=points)

    return change


def _edge_point(p: PlanPoint) -> PlanPoint:
    """``p`` made an edge search along its face, to an edge through ``p``."""
    n = np.asarray(p.normal, float)
    c = np.cross([0.0, 0.0, 1.0] if abs(n[2]) < 0.9 else [1.0, 0.0, 0.0], n)
    x, y, z = (float(v) for v in c / np.linalg.norm(c))
    search = Search(kind="edge", start_offset_m=0.025, overtravel_m=0.03, edge_direction=(x, y, z))
    return msgspec.structs.replace(p, search=search, edge_normal=(x, y, z))


def _with_edges(plan: Plan) -> Plan:
    """Every second point an edge search (plane parts: the stator box has its own edges)."""
    if matches_the_box(plan):
        pytest.skip("the edge variant is for plane parts (the stator box has its own edges)")
    points = [_edge_point(p) if k % 2 else p for k, p in enumerate(plan.points)]
    return msgspec.structs.replace(plan, points=points)


#: Structural variants of a plan: ``{name: plan -> plan}``.
SHAPES: dict[str, Callable[[Plan], Plan]] = {
    "as_shipped": lambda plan: plan,
    **{
        f"procedure_{method_of(cls())}": _other_procedure(cls())
        for cls in typing.get_args(ProcedureSettings)
    },
    "one_point": lambda plan: msgspec.structs.replace(plan, points=plan.points[:1]),
    "edges": _with_edges,
    "no_vias": lambda plan: msgspec.structs.replace(
        plan, points=[p.with_vias([]) for p in plan.points]
    ),
}


def variant(plan: Plan, rng: np.random.Generator) -> Plan:
    """``plan`` with random search speeds, offsets, overtravels and misplacement tolerance.

    Edge points keep their start offset (their edge start must stay on the face)."""
    points = []
    for p in plan.points:
        change: dict[str, float] = {
            "speed_m_s": float(rng.uniform(0.004, 0.03)),
            "overtravel_m": float(rng.uniform(0.004, 0.08)),
        }
        if p.search.kind == "approach":
            change["start_offset_m"] = float(rng.uniform(0.005, 0.08))
        points.append(
            msgspec.structs.replace(p, search=msgspec.structs.replace(p.search, **change))
        )
    tol = msgspec.structs.replace(
        plan.validation.misplacement,
        max_translation_m=float(rng.uniform(0.001, 0.025)),
        max_angle_rad=float(np.radians(rng.uniform(0.2, 3.0))),
    )
    validation = msgspec.structs.replace(plan.validation, misplacement=tol)
    return msgspec.structs.replace(plan, points=points, validation=validation)


def spun_rotations(plan: Plan, rng: np.random.Generator) -> dict[str, np.ndarray]:
    """Sensor orientations turned about the sensor axis by random angles."""
    return {
        p.id: default_sensor_rotation(p.normal, p.search.edge_direction)
        @ matrix_from_rotvec([0.0, 0.0, rng.uniform(-np.pi, np.pi)])
        for p in plan.points
    }


# ------------------------------------------------------------------ the shipped plans
@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("path", PLAN_CASES)
def test_shipped_plan_runs_to_the_end_and_measures_each_point_exactly(
    path: Path, seed: int
) -> None:
    plan = load(path)
    T_nom = nominal_T_base_wobj(plan)
    job, text = build(plan, T_nom)
    machine = run_and_compare(job, text, ideal_search(plan, misplaced(plan, T_nom, seed), T_nom))
    for t in job.targets:
        assert any(
            msg.startswith(f"wobjcal/1 point {t.point_id} 0 ") for msg in machine.messages
        ), t.point_id
    if is_adaptive(job):  # its searches, points and frame: compare_adaptive
        assert not machine.halted and set(slot_points(machine, job)[1]) == {0.0}
        return
    n_edge = sum(t.kind == "edge" for t in job.targets)
    assert len(machine.searches) == len(job.targets) + n_edge  # every point found
    # each point: a joint move to its safe start first, a linear retreat to it last
    safe_starts = [T_nom @ t.safe_start for t in job.targets]
    pose_moves = [m for m in machine.motions if m.kind == "movej" and isinstance(m.target, Pose)]
    assert len(pose_moves) == len(job.targets)
    for mo, T in zip(pose_moves, safe_starts, strict=True):
        assert np.abs(mo.end_T - T).max() < 1e-9  # type: ignore[operator]
    assert np.abs(machine.motions[-1].end_T - safe_starts[-1]).max() < 1e-9  # type: ignore[operator]


@pytest.mark.parametrize("path", PLAN_CASES)
def test_nominal_part_gives_the_plan_points(path: Path) -> None:
    """On the part at its nominal pose every ``meas_<ID>`` is the plan's point (base frame):
    the reference itself checked against the plan (an adaptive program's every slot, the
    retakes too: its frame stays nominal)."""
    plan = load(path)
    T_nom = nominal_T_base_wobj(plan)
    job, text = build(plan, T_nom)
    machine = run_and_compare(job, text, ideal_search(plan, T_nom, T_nom))
    if is_adaptive(job):
        got, codes = slot_points(machine, job)
        for k, (pid, _take) in enumerate(slot_table(job, job.program("urscript"))):
            want = transform_points(T_nom, plan.point(pid).position_m)
            assert codes[k] == 0.0 and np.abs(got[k] - want).max() < TOL_M, pid
        assert np.abs(machine.frame("wobj") - T_nom).max() < 1e-9
        return
    for p, t in zip(plan.points, job.targets, strict=True):
        got = measured(machine, t)
        assert got[0] == 0.0
        assert np.abs(np.array(got[1:]) - transform_points(T_nom, p.position_m)).max() < TOL_M


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(2))
@pytest.mark.parametrize("shape", sorted(SHAPES))
@pytest.mark.parametrize("path", PLAN_CASES)
def test_generated_variants_run_and_measure_exactly(path: Path, shape: str, seed: int) -> None:
    """Other procedures, one point, edge searches, no vias; and random speeds, offsets,
    overtravels (some searches then end before the part: code 1), tolerance, nominal frame,
    tool and sensor spin."""
    rng = np.random.default_rng(1000 + seed)
    try:
        plan = variant(SHAPES[shape](load(path)), rng)
    except WobjcalError as exc:
        pytest.skip(f"{path.stem} {shape}: the plan model refuses it: {exc}")
    T_nom = random_transform(rng, 2.0, np.pi)
    tool = ToolData(T_flange_tcp=random_transform(rng, 0.3, np.pi), mass_kg=2.5)
    job, text = build(plan, T_nom, tool, spun_rotations(plan, rng))
    machine = run_and_compare(job, text, ideal_search(plan, misplaced(plan, T_nom, seed), T_nom))
    assert np.abs(machine.tcp_offset.matrix() - tool.T_flange_tcp).max() < 1e-8
    order = [t.point_id for t in job.targets]
    if is_adaptive(job):  # the points it moved to, in its order, up to where it stopped
        codes = slot_points(machine, job)[1]
        prog = job.program("urscript")
        recorded = [s.point_id for s in prog.searches if s.recorded]
        order = [
            pid
            for pid, k in zip(recorded, search_slots(job, prog), strict=True)
            if codes[k] != -1.0
        ]
    else:
        assert np.abs(machine.frame("wobj") - T_nom).max() < 1e-8
    by_id = {t.point_id: t for t in job.targets}
    want = [q for pid in order for q in by_id[pid].vias_q_rad]
    vias = [m.target for m in machine.motions if m.kind == "movej" and isinstance(m.target, list)]
    assert np.allclose(vias, want, atol=1e-6) or (vias == [] and want == [])


@pytest.mark.slow
def test_the_plane_probe_agrees_with_the_box_probe() -> None:
    """Both ideal sensors answer the stator programs' searches alike (the plane probe is the
    reference for the plans that are not the box): the adaptive A-H one and a nominal one."""
    for plan in (load(STATOR), nominal_stator()):
        T_nom = nominal_T_base_wobj(plan)
        T_true = misplaced(plan, T_nom, 7)
        job, text = build(plan, T_nom)
        a = run_and_compare(job, text, rapid_search(BoxProbe(T_true)))
        b = run_and_compare(job, text, PlaneProbe(plan, T_true, T_nom))
        for t in job.targets:
            assert np.abs(np.array(measured(a, t)) - measured(b, t)).max() < TOL_M
        assert np.abs(a.frame("wobj") - b.frame("wobj")).max() < TOL_M
        if is_adaptive(job):
            assert np.abs(slot_points(a, job)[0] - slot_points(b, job)[0]).max() < TOL_M


@pytest.mark.slow
def test_polling_every_control_cycle_gives_the_same_points() -> None:
    """The event clock is an ideal controller: polling at 125 Hz (CB3) sees the same events."""
    plan = load(STATOR)
    T_nom = nominal_T_base_wobj(plan)
    job, text = build(plan, T_nom)
    search = ideal_search(plan, misplaced(plan, T_nom, 3), T_nom)
    fast = run_and_compare(job, text, search)
    slow = run_and_compare(job, text, search, cycle_s=0.008)
    for t in job.targets:
        assert np.abs(np.array(measured(fast, t)) - measured(slow, t)).max() < TOL_M
    assert np.abs(slot_points(fast, job)[0] - slot_points(slow, job)[0]).max() < TOL_M
    assert abs(slow.clock_s - fast.clock_s) < 0.1  # the cycles add at most one per wait


# ------------------------------------------------------------------ the error paths
def failing_call(search: SearchFn, which: int) -> Recorder:
    """``search`` whose call number ``which`` (1-based) finds nothing."""

    def answer(start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg_flank: bool) -> object:
        n = len(rec.calls)
        return NOT_FOUND if n == which else search(start, end, axis, neg_flank)

    rec = Recorder(answer)
    return rec


#: the nominal stator program's order of the searches: A B C D E F(face, edge) G H(face, edge)
@pytest.mark.parametrize(
    ("which", "point", "edge_search_runs"),
    [(1, "A", None), (6, "F", False), (7, "F", True), (10, "H", True)],
    ids=["approach", "edge-face-approach", "edge-search", "last-edge-search"],
)
def test_a_search_that_finds_nothing_takes_the_error_path(
    which: int, point: str, edge_search_runs: bool | None
) -> None:
    plan = nominal_stator()
    T_nom = nominal_T_base_wobj(plan)
    job, text = build(plan, T_nom)
    search = ideal_search(plan, misplaced(plan, T_nom, 11), T_nom)
    rec = failing_call(search, which)
    machine = UrMachine(text, rec).run()
    assert machine.finished
    failed = machine.searches[which - 1]
    assert failed.search is not None and failed.search.answer == NOT_FOUND
    assert not failed.stopped  # the robot ran the whole search ...
    assert np.abs(failed.stop_m - failed.search.end_m).max() < 1e-12
    after = machine.motions[machine.motions.index(failed) + 1]
    t = next(t for t in job.targets if t.point_id == point)
    assert after.kind == "movel"  # ... then went straight back to the point's safe start
    assert np.abs(after.end_T - T_nom @ t.safe_start).max() < 1e-9  # type: ignore[operator]
    edge_searches = [m for m in machine.searches if m.search and m.search.neg_flank]
    n_edge = sum(t.kind == "edge" for t in job.targets)
    assert len(edge_searches) == n_edge - (edge_search_runs is False)
    assert measured(machine, t) == [1.0, 0.0, 0.0, 0.0]
    assert any(msg == f"wobjcal/1 point {point} 1 0 0 0" for msg in machine.messages)
    for other in job.targets:  # every other point is measured as without the failure
        if other.point_id != point:
            want = expected_measurement(other, T_nom, search)
            assert want is not None
            got = measured(machine, other)
            assert got[0] == 0.0 and np.abs(np.array(got[1:]) - want).max() < TOL_M


def test_input_already_on_at_the_safe_start_gives_code_2_and_no_search() -> None:
    plan = nominal_stator()
    T_nom = nominal_T_base_wobj(plan)
    job, text = build(plan, T_nom)
    d = next(t for t in job.targets if t.point_id == "D")
    d_safe = (T_nom @ d.safe_start)[:3, 3]

    def rest_level(T: np.ndarray) -> bool:
        return bool(np.linalg.norm(T[:3, 3] - d_safe) < 1e-9)

    rec = Recorder(ideal_search(plan, T_nom, T_nom))
    machine = UrMachine(text, rec, rest_level=rest_level).run()
    assert measured(machine, d) == [2.0, 0.0, 0.0, 0.0]
    assert "wobjcal/1 point D 2 0 0 0" in machine.messages
    assert len(rec.calls) == len(job.targets) + 2 - 1  # D's search never started
    assert all(np.linalg.norm(c[0] - d_safe) > 1e-6 for c in rec.calls)


# ------------------------------------------------------------------ the program, as exported
def _stator_text() -> str:
    plan = load_plan(STATOR)
    return build(plan, nominal_T_base_wobj(plan))[1]


def test_as_exported_the_program_compiles() -> None:
    """No block keyword names a variable or a parameter (``run_search``'s goal was once
    ``end``) and every call has the built-in's argument count (the failure message was once a
    three-argument ``textmsg``: now one results line, ``textmsg(line)``)."""
    text = _stator_text()
    UrMachine(text, lambda *a: NOT_FOUND)
    assert "def run_search(goal, want, speed):" in text
    assert "def log_result(name, result):" in text and "    textmsg(line)" in text


def test_as_exported_the_failure_message_says_which_point_and_why() -> None:
    """Every search of a nominal program finds nothing: each point logs ``wobjcal/1 point <ID>
    1 0 0 0`` (the results line ``wobjcal calibrate`` reads) and records code 1 (an adaptive
    program stops at the first: test_urscript_adaptive)."""
    plan = nominal_stator()
    job, text = build(plan, nominal_T_base_wobj(plan))
    machine = UrMachine(text, lambda *a: NOT_FOUND).run()
    assert machine.finished and not machine.halted
    for t in job.targets:
        assert measured(machine, t) == [1.0, 0.0, 0.0, 0.0]
    want = [f"wobjcal/1 point {t.point_id} 1 0 0 0" for t in job.targets]
    assert machine.messages == [f"wobjcal/1 start {job.plan_digest}", *want, "wobjcal/1 end"]


# ------------------------------------------------------------------ the interpreter itself
def _run(body: str, search: SearchFn | None = None, **options: object) -> UrMachine:
    text = (
        "def prog():\n" + "".join("  " + line + "\n" for line in body.strip().split("\n")) + "end\n"
    )
    return UrMachine(text, search or (lambda *a: NOT_FOUND), **options).run()  # type: ignore[arg-type]


def test_scoping_threads_and_values() -> None:
    m = _run(
        """
        a = 1
        lst = [1, 2, 3]
        def f(x, y=10):
          a = a + x
          local b = y
          c = lst
          c[0] = 99
          return b + c[0]
        end
        def g():
          global made = 5
          return made
        end
        counter = 0
        thread count():
          while True:
            counter = counter + 1
            sync()
          end
        end
        r = f(2)
        s = g()
        h = run count()
        sleep(0.1)
        kill h
        n = counter
        sleep(0.1)
        q = p[1, 2, 3, 0, 0, 0]
        q[2] = 7
        ok = (n == counter) and not (1 > 2) and (r == 109) xor False
        """,
        cycle_s=0.01,
    )
    v = m.variables
    assert v["a"] == 3 and v["r"] == 109 and v["s"] == 5 and v["made"] == 5
    assert v["lst"] == [1, 2, 3]  # lists are values
    assert 9 <= v["n"] <= 11 and v["ok"] is True
    assert v["q"] == Pose((1.0, 2.0, 7.0, 0.0, 0.0, 0.0))


def test_pose_functions_follow_the_frames_convention(rng: np.random.Generator) -> None:
    T1, T2 = random_transform(rng, 1.0, np.pi), random_transform(rng, 1.0, np.pi)
    p1, p2 = Pose.from_matrix(T1), Pose.from_matrix(T2)
    m = _run(
        f"""
        a = {p1}
        b = {p2}
        t = pose_trans(a, b)
        i = pose_inv(a)
        s = pose_add(a, b)
        d = pose_sub(b, a)
        back = pose_add(a, d)
        half = interpolate_pose(a, b, 0.5)
        rpy = rotvec2rpy([a[3], a[4], a[5]])
        rv = rpy2rotvec(rpy)
        dist = point_dist(a, b)
        n = norm([3.0, 4.0])
        """
    )
    v = m.variables
    assert np.abs(m.frame("t") - T1 @ T2).max() < 1e-12
    assert np.abs(m.frame("i") - invert_transform(T1)).max() < 1e-12
    R_add = m.frame("s")
    assert np.abs(R_add[:3, :3] - T1[:3, :3] @ T2[:3, :3]).max() < 1e-12
    assert np.abs(R_add[:3, 3] - T1[:3, 3] - T2[:3, 3]).max() < 1e-12
    assert np.abs(m.frame("back") - T2).max() < 1e-12
    assert np.abs(m.frame("half")[:3, 3] - (T1[:3, 3] + T2[:3, 3]) / 2).max() < 1e-12
    assert np.abs(np.array(v["rv"]) - np.array(p1.v[3:])).max() < 1e-9
    assert abs(v["dist"] - np.linalg.norm(T1[:3, 3] - T2[:3, 3])) < 1e-12 and v["n"] == 5.0


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ("x = foo(1)", r"line 2: unknown function foo\(\)"),
        ("for i in range(3):\n  x = i\nend", r"line 2: unknown statement 'for'"),
        ("x = y + 1", r"line 2: variable 'y' is not defined"),
        ("def f(end):\n  return 1\nend", r"line 2: 'end' cannot be a parameter name"),
        ("textmsg(1, 2, 3)", r"line 2: textmsg\(\) takes at most 2 arguments"),
        ("movel(p[0, 0, 0, 0, 0, 0], speed=1)", r"line 2: movel\(\): bad keyword argument"),
        ("if True:\n  x = 1", r"line 1: def has no end"),
        ("break", r"line 2: break outside a loop"),
        ("x = 1\nx", r"line 3: not a statement"),
        ('$ 1 "label"', r"line 2: cannot read"),
    ],
)
def test_what_does_not_compile_names_its_line(body: str, message: str) -> None:
    with pytest.raises(UrSyntaxError, match=message):
        _run(body)


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ("x = 1 / 2", r"line 2: int / int"),
        ("if 1:\n  x = 1\nend", r"line 2: if condition is int"),
        ("x = [1, 2]\ny = x[2]", r"line 3: index 2 out of range"),
        ("x = sqrt(-1.0)", r"line 2: sqrt\(\): sqrt\(-1.0\): outside"),
        ("while True:\n  x = 1\nend", r"line 2: the loop ran 1000 times without waiting"),
        ("movel(p[0, 0, 0, 0, 0, 0])", r"line 2: movel\(\): movel from an unknown TCP"),
        ("x = pose_dist(p[0,0,0,0,0,0], p[1,0,0,0,0,0])", r"line 2: pose_dist\(\): .*not modelled"),
    ],
)
def test_what_fails_at_run_time_names_its_line(body: str, message: str) -> None:
    with pytest.raises(UrRuntimeError, match=message):
        _run(body, spin_limit=1000)


def test_kill_stops_the_motion_of_the_thread_where_it_is() -> None:
    m = _run(
        """
        movej(p[0.2, 0, 0.3, 0, 0, 0])
        thread mover():
          movel(p[0.2, 0.5, 0.3, 0, 0, 0], v=0.1)
        end
        enter_critical
        h = run mover()
        exit_critical
        sleep(2.0)
        kill h
        at = get_actual_tcp_pose()
        join h
        movel(p[0.2, 0, 0.3, 0, 0, 0], v=0.1)
        """
    )
    assert m.variables["at"].v[1] == pytest.approx(0.2, abs=1e-12)
    moved = m.motions[1]
    assert moved.stopped and moved.stop_m[1] == pytest.approx(0.2)  # type: ignore[index]
    assert m.clock_s == pytest.approx(4.0) and m.searches == []  # the input was never read


def test_a_search_made_of_small_blocking_moves() -> None:
    """A loop of short ``movel`` steps reading the input between them is a search too: the
    callback answers each step, the loop stops at the end of the step where it switched."""
    plane_z = 0.0123
    calls: list[bool] = []

    def floor(start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg_flank: bool) -> object:
        calls.append(neg_flank)
        assert np.abs(axis - [0.0, 0.0, -1.0]).max() < 1e-12  # the target's +z looks down
        if start[2] <= plane_z:
            return AT_START
        return (
            NOT_FOUND
            if end[2] > plane_z
            else start + (start[2] - plane_z) / (start[2] - end[2]) * (end - start)
        )

    m = _run(
        """
        movej(p[0.5, 0.1, 0.1, 3.14159265358979, 0, 0])
        step = 0
        while not get_standard_digital_in(0):
          here = get_actual_tcp_pose()
          movel(pose_trans(here, p[0, 0, 0.005, 0, 0, 0]), v=0.05)
          step = step + 1
        end
        at = get_actual_tcp_pose()
        movel(p[0.5, 0.1, 0.1, 3.14159265358979, 0, 0])
        """,
        floor,
    )
    v = m.variables
    assert v["step"] == 18 and v["at"].v[2] == pytest.approx(0.1 - 18 * 0.005)
    assert calls == [False] * 18  # the retreat was never watched: never asked
    assert len(m.searches) == 18
