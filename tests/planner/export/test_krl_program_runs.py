"""The exported KRL program, run in a KRL interpreter (:mod:`tests.krl_interp`) against an ideal
part at a misplaced pose, runs to its end and records what its searches find.

For every shipped plan and generated variants of it (other procedures, fewer points, edge
searches, a tool offset, status and turn): a nominal program's searches are exactly the ones
computed here from the export job (safe start, face end, plan end, edge direction: the searches
of ``program_searches``), and each ``xMeas[i]`` is the point those searches find, to 1e-6 mm;
an adaptive program's searches (each in the frame estimated so far), points and final
``BASE_DATA[10]`` are those of the executed program (:func:`planner.program.execute`, what
``wobjcal validate`` simulates) on the same part. A search that finds nothing, or an input
already at its level, takes the nominal program's error path (the adaptive program's:
:mod:`tests.planner.export.test_krl_adaptive_replay`). The ideal part is
:class:`tests.box_part.BoxProbe` for
plans on the stator box, else :class:`PlaneWorld`.

The interpreter runs KSS's semantics strictly: ``RESUME`` only where the interrupted motion runs
below the routine that declared the interrupt, names of at most 24 characters, unique ignoring
case. The tests at the end pin what the writer once got wrong there: a search ``LIN`` in the
declaring routine, point ids differing only in case, long point ids and plan names.
"""

from __future__ import annotations

import re
import typing
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import msgspec
import numpy as np
import pytest

from calib.errors import WobjcalError
from calib.frames import (
    invert_transform,
    make_transform,
    matrix_from_rotvec,
    matrix_from_tait_bryan_zyx,
    random_transform,
    rotvec_from_matrix,
    tait_bryan_zyx_from_matrix,
    transform_directions,
    transform_points,
)
from calib.plan.file import Plan, PlanPoint, Search, load_plan
from calib.probing import ProbeResult, SearchCommand
from calib.procedures import ProcedureSettings, method_of, procedure_kind
from planner.export import export_files
from planner.export.job import (
    TARGET_KINDS,
    ArmPose,
    ExportJob,
    ToolData,
    build_job,
    default_sensor_rotation,
)
from planner.export.krl_adaptive import measured_slots
from planner.plan_cell import nominal_T_base_wobj
from planner.program import execute
from tests.box_part import BOX_HI, BOX_LO, BoxProbe, distance_to_box
from tests.krl_interp import KrlError, KrlMachine, SearchFn
from tests.planner.export.test_export_rapid_adaptive import full_misplacement, rapid_search
from tests.reference_data import plan_cases

REPO = Path(__file__).resolve().parents[3]
PLANS = sorted((REPO / "assets" / "plans").glob("*.json"))
#: :data:`PLANS` as cases, the plate's marked ``reference`` (their mesh is in ``../shared``).
PLAN_CASES = plan_cases(PLANS)
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"
PLATE = REPO / "assets" / "plans" / "plate_holes_321.json"
PLATE_BEST_FIT = REPO / "assets" / "plans" / "plate_holes_best_fit.json"
TOL_M = 1e-9  # 1e-6 mm
#: An adaptive program against the executed one: its targets written to 1e-6 mm and 1e-6 deg
#: (a nominal frame turned by 1e-8 rad moves a search 1 m away by 1e-8 m), metres and radians.
ADAPTIVE_TOL = 1e-7


# ------------------------------------------------------------------ the ideal part
class PlaneWorld:
    """An ideal noise-free sensor on a plan's part reduced to planes, posed at ``T_base_true``.

    Each point's face is the plane through it with its normal; each edge point's edge is the
    plane through it with its edge normal (the face ends there); both moved by the true pose
    (robot base frame, metres). An approach search (``neg_flank`` False) stops where its line
    first enters a face plane from the outside, an edge search where it first leaves an edge
    plane: the TCP at the switching event, as the controller records it.
    """

    def __init__(self, plan: Plan, T_base_true: np.ndarray) -> None:
        self.faces = [self._plane(T_base_true, p.position_m, p.normal) for p in plan.points]
        self.edges = [
            self._plane(T_base_true, p.position_m, p.edge_normal)
            for p in plan.points
            if p.search.kind == "edge" and p.edge_normal is not None
        ]

    @staticmethod
    def _plane(T: np.ndarray, p: typing.Any, n: typing.Any) -> tuple[np.ndarray, np.ndarray]:
        return transform_points(T, np.asarray(p, float)), transform_directions(T, np.asarray(n))

    def __call__(
        self, start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg_flank: bool
    ) -> np.ndarray | str:
        best = None
        for p, n in self.edges if neg_flank else self.faces:
            d0, d1 = float(n @ (start - p)), float(n @ (end - p))
            crosses = (d0 < 0.0 <= d1) if neg_flank else (d0 > 0.0 >= d1)
            if crosses and (best is None or d0 / (d0 - d1) < best):
                best = d0 / (d0 - d1)
        return "ERR_WHLSEARCH" if best is None else start + best * (end - start)


def on_stator_box(plan: Plan) -> bool:
    """Whether every point lies on a face of :mod:`tests.box_part`'s box with that face's
    outward normal (then :class:`BoxProbe` is the plan's part)."""
    for p in plan.points:
        n, x = np.asarray(p.normal), np.asarray(p.position_m)
        k = int(np.argmax(np.abs(n)))
        bound = BOX_HI[k] if n[k] > 0 else BOX_LO[k]
        inside = np.all(x >= BOX_LO - 1e-12) and np.all(x <= BOX_HI + 1e-12)
        if abs(abs(n[k]) - 1.0) > 1e-12 or abs(x[k] - bound) > 1e-12 or not inside:
            return False
    return True


def ideal_part(plan: Plan, T_base_true: np.ndarray) -> SearchFn:
    """The search callback of the plan's ideal part at ``T_base_true``."""
    if on_stator_box(plan):
        return rapid_search(BoxProbe(T_base_true))
    return PlaneWorld(plan, T_base_true)


def failing(search: SearchFn, k: int) -> SearchFn:
    """``search`` that finds nothing (``"ERR_WHLSEARCH"``) at its ``k``-th call."""
    calls = [0]

    def fn(start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg: bool) -> np.ndarray | str:
        calls[0] += 1
        return "ERR_WHLSEARCH" if calls[0] == k else search(start, end, axis, neg)

    return fn


def probe_of(search: SearchFn) -> typing.Callable[[SearchCommand], ProbeResult]:
    """A probe (``SearchCommand`` -> ``ProbeResult``) answered by a search callback."""

    def probe(cmd: SearchCommand) -> ProbeResult:
        end = cmd.start_m + cmd.length_m * cmd.direction
        res = search(cmd.start_m, end, cmd.sensor_axis, cmd.kind == "edge")
        return ProbeResult(None, res) if isinstance(res, str) else ProbeResult(np.asarray(res))

    return probe


def base_m(m: KrlMachine) -> np.ndarray:
    """``(4, 4)`` ``BASE_DATA[10]``, robot base, metres: the program's work object."""
    return m.frame_m(m.value("BASE_DATA").data[9])


def slot_of(job: ExportJob) -> dict[str, int]:
    """``{measurement key: slot of xMeas}``: plan ids, and ``id#2`` for the A-H retakes."""
    return {
        f"{pid}#2" if retake else pid: i
        for i, (pid, retake) in enumerate(measured_slots(job), start=1)
    }


def assert_same_frame(T: np.ndarray, want: np.ndarray, tol_m: float, tol_rad: float) -> None:
    """Origins within ``tol_m``, rotations within ``tol_rad`` (the angle of the rotation
    between them, from its rotation vector: ``arccos`` of the trace cannot resolve 1e-8)."""
    assert np.abs(T[:3, 3] - want[:3, 3]).max() < tol_m, (T[:3, 3], want[:3, 3])
    angle = float(np.linalg.norm(rotvec_from_matrix(T[:3, :3].T @ want[:3, :3])))
    assert angle < tol_rad, angle


# ------------------------------------------------------------------ the searches, computed here
def written(T: np.ndarray) -> np.ndarray:
    """``T`` (metres) as the program states it: X, Y, Z in mm and A, B, C in degrees, each to
    6 decimals."""
    vals = [*(T[:3, 3] * 1000.0), *np.degrees(tait_bryan_zyx_from_matrix(T[:3, :3]))]
    x, y, z, a, b, c = (float(f"{v:.6f}") for v in vals)
    R = matrix_from_tait_bryan_zyx(np.radians(a), np.radians(b), np.radians(c))
    return make_transform(R, np.array([x, y, z]) / 1000.0)


class Expected:
    """The searches the program runs, computed from the job (robot base, metres): per point an
    approach from the safe start to the plan's end, or for an edge point an approach to the face
    end and then the edge search from the face point found, along the nominal direction, to
    where the plan's end projects on that line.

    Attributes:
        calls: ``(start, end, neg_flank)`` of every search, in order.
        points: ``{i: (3,) point found}`` (1-based, plan order) of the points found.
        codes: ``{i: 0 or 1}``: found, or a search found nothing.
    """

    def __init__(self, job: ExportJob, search: SearchFn) -> None:
        self.calls: list[tuple[np.ndarray, np.ndarray, bool]] = []
        self.points: dict[int, np.ndarray] = {}
        self.codes: dict[int, int] = {}
        self._search = search
        T = written(job.T_base_wobj)
        for i, t in enumerate(job.targets, start=1):
            safe = T @ written(t.safe_start)
            if t.kind == "approach":
                found = self._run(safe[:3, 3], T @ written(t.T_wobj_end), False)
            else:
                face = self._run(safe[:3, 3], T @ written(t.face_end), False)
                found = face if isinstance(face, str) else self._edge(T, t, face)
            if isinstance(found, str):
                self.codes[i] = 1
            else:
                self.codes[i], self.points[i] = 0, found

    def _run(self, start: np.ndarray, goal: np.ndarray, neg: bool) -> np.ndarray | str:
        self.calls.append((start, goal[:3, 3], neg))
        return self._search(start, goal[:3, 3], goal[:3, 2], neg)

    def _edge(self, T: np.ndarray, t: typing.Any, face_m: np.ndarray) -> np.ndarray | str:
        """The edge search from the face point, in the nominal base as the program runs it."""
        end_w = written(t.T_wobj_end)
        d = np.array([float(f"{v:.9f}") for v in t.edge_direction_wobj])
        start_w = transform_points(invert_transform(T), face_m)
        goal_w = end_w.copy()
        goal_w[:3, 3] = start_w + float((end_w[:3, 3] - start_w) @ d) * d
        return self._run(face_m, T @ goal_w, True)


# ------------------------------------------------------------------ plans and runs
def _procedure_variant(settings: typing.Any) -> Callable[[Plan], Plan]:
    """The plan under another procedure, its points given that procedure's roles
    (:meth:`ProcedureKind.assign`: their own when they fit, else from the geometry)."""

    def change(plan: Plan) -> Plan:
        roles = {rp.point.id: rp.role for rp in procedure_kind(settings).assign(plan.role_points())}
        points = [
            msgspec.structs.replace(p, role=roles[p.id]) for p in plan.points if p.id in roles
        ]
        return msgspec.structs.replace(plan, procedure=settings, points=points)

    return change


def _edge_point(p: PlanPoint) -> PlanPoint:
    """``p`` made an edge search along the face, to an edge through ``p`` (sign chosen so that
    the directions written have negative components too)."""
    n = np.asarray(p.normal)
    c = -np.cross(n, [0.0, 0.0, 1.0] if abs(n[2]) < 0.9 else [1.0, 0.0, 0.0])
    c /= np.linalg.norm(c)
    d = (float(c[0]), float(c[1]), float(c[2]))
    search = Search(kind="edge", start_offset_m=0.03, overtravel_m=0.02, edge_direction=d)
    return msgspec.structs.replace(p, search=search, edge_normal=d)


def with_edges(plan: Plan) -> Plan:
    """Every second point an edge search (only on a :class:`PlaneWorld` part: the stator box
    has its own edges)."""
    if on_stator_box(plan):
        pytest.skip("the edge variant is for plane parts (the stator box has its own edges)")
    points = [_edge_point(p) if k % 2 else p for k, p in enumerate(plan.points)]
    return msgspec.structs.replace(plan, points=points)


def _no_vias(plan: Plan) -> Plan:
    return msgspec.structs.replace(plan, points=[p.with_vias([]) for p in plan.points])


#: Plan variants: ``{name: plan -> plan}`` (a variant the plan refuses is skipped).
VARIANTS: dict[str, Callable[[Plan], Plan]] = {
    "as_shipped": lambda plan: plan,
    **{
        f"procedure_{method_of(cls())}": _procedure_variant(cls())
        for cls in typing.get_args(ProcedureSettings)
    },
    "one_point": lambda plan: msgspec.structs.replace(plan, points=plan.points[:1]),
    "three_points": lambda plan: msgspec.structs.replace(plan, points=plan.points[:3]),
    "edges": with_edges,
    "no_vias": _no_vias,
}


def variant_job(path: Path, variant: str) -> tuple[Plan, ExportJob, dict[str, str]]:
    """The plan variant, its export job (nominal frame of the plan, sensor TCP at the flange)
    and its KRL files; skips a variant the plan model or the exporter refuses."""
    try:
        plan = VARIANTS[variant](load_plan(path))
        job = build_job(plan, nominal_T_base_wobj(plan), ToolData(T_flange_tcp=np.eye(4)))
        return plan, job, export_files(job, "krl")
    except WobjcalError as err:
        pytest.skip(f"{path.name} {variant}: {type(err).__name__}: {err}")


def run(files: dict[str, str], search: SearchFn, **kwargs: typing.Any) -> KrlMachine:
    """The program run to its end (no HALT, no error)."""
    m = KrlMachine(files, search, **kwargs).run()
    assert m.finished and m.halted is None
    return m


def assert_runs_as_executed(m: KrlMachine, job: ExportJob, search: SearchFn) -> None:
    """An adaptive program: it ended calibrated, its searches (each commanded in the frame
    estimated so far) are the executed program's on the same part, and so are its points and
    its frame (``BASE_DATA[10]``, also ``$BASE``), to :data:`ADAPTIVE_TOL`."""
    program = job.program("krl")
    assert program.adaptive
    commands: list[SearchCommand] = []
    ideal = probe_of(search)

    def recording(cmd: SearchCommand) -> ProbeResult:
        commands.append(cmd)
        return ideal(cmd)

    run = execute(program, job.T_base_wobj, recording)
    assert m.value("nResult") == 1
    assert set(m.ints().values()) == {0}
    for call, cmd in zip(m.search_calls, commands, strict=False):  # then the x-offset run's
        assert call.neg_flank == (cmd.kind == "edge")
        assert np.abs(call.start_m - cmd.start_m).max() < ADAPTIVE_TOL
        end = cmd.start_m + cmd.length_m * cmd.direction
        assert np.abs(call.end_m - end).max() < ADAPTIVE_TOL
    assert len(m.search_calls) >= len(commands)
    slots, got = slot_of(job), m.measured_m()
    assert set(got) == {slots[k] for k in run.measured_m}
    for key, q in run.measured_m.items():
        assert np.abs(got[slots[key]] - np.asarray(q)).max() < ADAPTIVE_TOL, key
    assert_same_frame(base_m(m), run.T_base_wobj, ADAPTIVE_TOL, ADAPTIVE_TOL)
    assert np.abs(m.base_m() - base_m(m)).max() < 1e-12


def assert_runs_as_computed(m: KrlMachine, job: ExportJob, want: Expected) -> None:
    """The program's searches, results and codes are the ones computed from the job (a
    nominal program)."""
    assert not job.program("krl").adaptive
    assert len(m.search_calls) == len(want.calls)
    for got, (start, end, neg) in zip(m.search_calls, want.calls, strict=True):
        assert got.neg_flank == neg
        assert np.abs(got.start_m - start).max() < TOL_M
        assert np.abs(got.end_m - end).max() < TOL_M
    assert m.ints("nFail") == want.codes
    measured = m.measured_m("xMeas")
    assert set(measured) == set(want.points)
    for i, p in want.points.items():
        assert np.abs(measured[i] - p).max() < TOL_M, (job.targets[i - 1].point_id, measured[i], p)


def assert_on_own_face(plan: Plan, T_true: np.ndarray, measured: dict[int, np.ndarray]) -> None:
    """An approach point lies on its own true face, an edge point (plane parts) on its edge:
    each search found the face it was meant for."""
    box = on_stator_box(plan)
    for i, x in measured.items():
        p = plan.points[i - 1]
        n = p.normal if p.search.kind == "approach" else p.edge_normal
        if p.search.kind == "edge" and box:
            continue  # the box's edge event is where the sensor axis leaves the face
        q = transform_points(T_true, np.asarray(p.position_m))
        assert abs(transform_directions(T_true, np.asarray(n)) @ (x - q)) < TOL_M, p.id


# ------------------------------------------------------------------ tests
@pytest.mark.parametrize("seed", range(2))
@pytest.mark.parametrize("variant", sorted(VARIANTS))
@pytest.mark.parametrize("path", PLAN_CASES)
def test_exported_program_runs_and_measures_what_its_searches_find(
    path: Path, variant: str, seed: int
) -> None:
    """On a part misplaced at the plan's tolerance the program runs to its end, every search
    starts and ends where the job says, every point is found on its own face and recorded in
    ``xMeas`` (robot base) as computed here, to 1e-6 mm; ``$BASE``, ``$TOOL`` and the vias
    are the job's."""
    plan, job, files = variant_job(path, variant)
    T_true = job.T_base_wobj @ full_misplacement(plan, np.random.default_rng(seed))
    m = run(files, ideal_part(plan, T_true))
    program = job.program("krl")
    if program.adaptive:
        assert_runs_as_executed(m, job, ideal_part(plan, T_true))
    else:
        want = Expected(job, ideal_part(plan, T_true))
        assert_runs_as_computed(m, job, want)
        assert want.codes == dict.fromkeys(range(1, len(job.targets) + 1), 0)  # all found
        # the frame it sets, as the job says (to the written precision)
        assert np.abs(m.base_m() - written(job.T_base_wobj)).max() < 1e-12
        # and the robot ends at the last point's safe start
        last_safe = written(job.T_base_wobj) @ written(job.targets[-1].safe_start)
        assert np.abs(m.tcp_m() - last_safe).max() < TOL_M
    measured = {i: x for i, x in m.measured_m().items() if i <= len(job.targets)}
    assert_on_own_face(plan, T_true, measured)
    # the tool it sets, and the vias it passes in the program's order, as the job says
    assert np.abs(m.tool_m() - written(job.tool.T_flange_tcp)).max() < 1e-12
    vias = [mo.axes_deg for mo in m.motions if mo.axes_deg is not None]
    target = {t.point_id: t for t in job.targets}
    want_vias = [v for pid in program.probe_order for v in target[pid].vias_deg("KRL")]
    assert np.allclose(vias, want_vias, atol=1e-4) if want_vias else vias == []


def _with_arms(job: ExportJob) -> ExportJob:
    arm = ArmPose((0.1, -0.2, 0.3, -0.4, 0.5, -0.6), True, True, False)
    targets = tuple(replace(t, arm=dict.fromkeys(TARGET_KINDS, arm)) for t in job.targets)
    return replace(job, targets=targets)


@pytest.mark.parametrize("path", PLAN_CASES)
def test_tool_offset_and_status_turn_change_nothing_measured(path: Path) -> None:
    """A sensor TCP away from the flange and targets with S and T: the same searches and
    points, ``$TOOL`` the tool, and the status and turn reach ``$POS_INT``."""
    plan = load_plan(path)
    T_nom = nominal_T_base_wobj(plan)
    T_true = T_nom @ full_misplacement(plan, np.random.default_rng(7))
    tool = ToolData(T_flange_tcp=make_transform(np.eye(3), [0.0, 0.05, 0.25]))
    job = _with_arms(build_job(plan, T_nom, tool))
    files = export_files(job, "krl")
    assert ",S 2,T 42}" in files[".dat"]
    m = run(files, ideal_part(plan, T_true))
    if job.program("krl").adaptive:
        assert_runs_as_executed(m, job, ideal_part(plan, T_true))
    else:
        assert_runs_as_computed(m, job, Expected(job, ideal_part(plan, T_true)))
    assert np.abs(m.tool_m() - tool.T_flange_tcp).max() < 1e-12
    hit = m.value("xHit")  # $POS_INT carries the status and turn of the search target
    assert (hit.type, hit.f["S"], hit.f["T"]) == ("E6POS", 2, 42)


@pytest.mark.parametrize("adaptive", [False, True], ids=["nominal", "adaptive"])
def test_a_nominal_frame_away_from_the_base_and_turned_sensors(adaptive: bool) -> None:
    """A random nominal frame, sensor orientations and tool: the program's base and targets
    compose with the geometric operator as the job's transforms do (to the written precision):
    the nominal program (edge searches) as computed here, the adaptive 3-2-1 (its frame updates
    with ``INV_POS`` and ``:``) as executed."""
    rng = np.random.default_rng(11)
    plate = load_plan(PLATE, check_files=False)  # the program is written from the plan alone
    plan = plate if adaptive else with_edges(plate)
    T_nom = random_transform(rng, 2.0, np.pi)
    T_true = T_nom @ full_misplacement(plan, rng)
    rotations = {
        p.id: default_sensor_rotation(p.normal, p.search.edge_direction)
        @ matrix_from_rotvec([0.0, 0.0, rng.uniform(-np.pi, np.pi)])
        for p in plan.points
    }
    tool = ToolData(T_flange_tcp=random_transform(rng, 0.3, np.pi))
    job = build_job(plan, T_nom, tool, rotations)
    assert job.program("krl").adaptive == adaptive
    m = run(export_files(job, "krl"), PlaneWorld(plan, T_true))
    if adaptive:
        assert_runs_as_executed(m, job, PlaneWorld(plan, T_true))
        assert_same_frame(base_m(m), T_true, ADAPTIVE_TOL, ADAPTIVE_TOL)  # the true part
    else:
        assert_runs_as_computed(m, job, Expected(job, PlaneWorld(plan, T_true)))
    assert_on_own_face(plan, T_true, m.measured_m())


def stator_nominal() -> Plan:
    """The stator plan under best fit: its KRL program is nominal (the frame update takes
    approach searches only, and F and H are edge searches)."""
    return VARIANTS["procedure_best_fit"](load_plan(STATOR))


#: ``{k: (point that fails, searches run)}`` on the nominal stator program, whose searches are
#: A, B, C, D, E, F (face, then edge), G, H (face, then edge).
FAILURES = {1: (1, 10), 3: (3, 10), 6: (6, 9), 7: (6, 10), 10: (8, 10)}


@pytest.mark.parametrize("k", sorted(FAILURES))
def test_a_search_that_finds_nothing_takes_the_error_path(k: int) -> None:
    """The ``k``-th search finds nothing: that point gets ``nFail = 1`` and no ``xMeas``, an
    edge point whose face approach failed runs no edge search, every other point is measured;
    the robot goes to the end of the failed search and back to the point's safe start."""
    plan = stator_nominal()
    T_nom = nominal_T_base_wobj(plan)
    T_true = T_nom @ full_misplacement(plan, np.random.default_rng(3))
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    assert not job.program("krl").adaptive
    world = ideal_part(plan, T_true)
    m = run(export_files(job, "krl"), failing(world, k))
    point, n_searches = FAILURES[k]
    assert m.ints() == {i: int(i == point) for i in range(1, 9)}
    assert set(m.measured_m()) == set(range(1, 9)) - {point}
    assert len(m.search_calls) == n_searches
    assert_runs_as_computed(m, job, Expected(job, failing(world, k)))
    failed = m.searches[k - 1]
    assert failed.end_m is not None and failed.target_m is not None
    assert np.abs(failed.end_m - failed.target_m).max() < 1e-12  # ran to its end
    retreat = m.motions[m.motions.index(failed) + 1]
    safe = written(job.T_base_wobj) @ written(job.targets[point - 1].safe_start)
    assert retreat.kind == "LIN" and retreat.target_m is not None and not retreat.is_search
    assert np.abs(retreat.target_m - safe).max() < TOL_M


def test_an_input_already_on_at_the_safe_start_skips_the_point() -> None:
    """``nFail = 2``: the sensor already on at a point's safe start (no search for it), or off
    at the face point an edge search starts from (the nominal program goes on)."""
    plan = stator_nominal()
    T_nom = nominal_T_base_wobj(plan)
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    files = export_files(job, "krl")
    world = ideal_part(plan, T_nom)
    safe_b = (written(T_nom) @ written(job.targets[1].safe_start))[:3, 3]
    T_wobj_base = invert_transform(T_nom)

    def sensor(tcp: np.ndarray, axis: np.ndarray) -> bool:
        """On at B's safe start (a part left there), and on the part's faces."""
        on_part = distance_to_box(transform_points(T_wobj_base, tcp)) <= 1e-9
        return bool(on_part or np.linalg.norm(tcp - safe_b) < 1e-6)

    m = run(files, world, sensor=sensor)
    codes = m.ints()
    assert codes[2] == 2 and 2 not in m.measured_m()
    assert all(c == 0 for i, c in codes.items() if i != 2)
    assert len(m.search_calls) == 9  # 8 faces + 2 edge searches, none for B

    m = run(files, world, sensor=lambda tcp, axis: False)  # never on after a plain motion
    codes = m.ints()
    edges = [i for i, t in enumerate(job.targets, start=1) if t.kind == "edge"]
    assert [codes[i] for i in edges] == [2, 2] and set(m.measured_m()).isdisjoint(edges)
    assert all(c == 0 for i, c in codes.items() if i not in edges)
    assert not any(c.neg_flank for c in m.search_calls)  # no edge search started


# ------------------------------------------------------------------ the interpreter itself
def krl(body: str, decls: str = "", routines: str = "", dat: str = "") -> dict[str, str]:
    """A module ``T`` whose main program has ``decls`` and ``body``."""
    src = f"DEF T()\n{decls}\n{body}\nEND\n{routines}\n"
    return {".src": src, ".dat": f"DEFDAT T\n{dat}\nENDDAT\n"}


def nothing(start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg: bool) -> str:
    return "ERR_WHLSEARCH"


def test_interpreter_arithmetic_priorities_and_control_flow() -> None:
    body = """
  i = 7/2
  r = 7/2.0 + 2*-1.5
  b = (1 < 2) AND NOT (3 > 4)
  FOR k = 10 TO 1 STEP -3
    n = n + k
  ENDFOR
  WHILE n < 100
    n = n*2
  ENDWHILE
  LOOP
    n = n - 1
    IF n == 150 THEN
      EXIT
    ENDIF
  ENDLOOP
  REPEAT
    c = c + 1
  UNTIL c >= 3
  SWITCH c
    CASE 1, 2
      s = 'H10'
    CASE 3
      s = ADD(c, 4)
      TWICE(s)
    DEFAULT
      s = -1
  ENDSWITCH"""
    routines = """
DEFFCT INT ADD(a:IN, b:IN)
  DECL INT a, b
  RETURN a + b
ENDFCT

DEF TWICE(v:OUT)
  DECL INT v
  v = 2*v
END"""
    dat = "DECL INT i\nDECL REAL r\nDECL BOOL b\nDECL INT n=0\nDECL INT c=0\nDECL INT s"
    m = KrlMachine(krl(body, "  DECL INT k", routines, dat), nothing).run()
    assert (m.value("i"), m.value("r"), m.value("b")) == (3, 0.5, True)
    assert (m.value("n"), m.value("c"), m.value("s")) == (150, 3, 14)


def test_interpreter_geometric_operator_and_inv_pos_match_calib_frames() -> None:
    rng = np.random.default_rng(5)
    Ta, Tb = random_transform(rng, 1.0, np.pi), random_transform(rng, 1.0, np.pi)

    def agg(T: np.ndarray) -> str:
        vals = [*(T[:3, 3] * 1000.0), *np.degrees(tait_bryan_zyx_from_matrix(T[:3, :3]))]
        return "{" + ",".join(f"{k} {v:.12f}" for k, v in zip("XYZABC", vals)) + "}"

    dat = (
        f"DECL FRAME a={agg(Ta)}\nDECL E6POS b={agg(Tb)[:-1]},S 6,T 1}}\nDECL E6POS c\nDECL FRAME d"
    )
    m = KrlMachine(krl("  c = a:b\n  d = INV_POS(a):c", dat=dat), nothing).run()
    assert np.abs(m.frame_m("c") - Ta @ Tb).max() < 1e-12
    assert np.abs(m.frame_m("d") - Tb).max() < 1e-12
    c = m.value("c")
    assert (c.type, c.f["S"], c.f["T"]) == ("E6POS", 6, 1)  # the type of the right operand


def test_interpreter_resume_goes_back_to_the_declaring_level() -> None:
    """The structure KSS accepts: the interrupt declared in the caller, the search motion in a
    subprogram; RESUME ends the subprogram and goes on after its call, the robot where the
    input switched (``$POS_INT``, in the current base)."""
    body = """
  $BASE = {X 100, Y 0, Z 0, A 90, B 0, C 0}
  INTERRUPT DECL 5 WHEN $IN[1] DO STOPPED()
  PTP {X 0, Y 0, Z 50, A 0, B 0, C 0}
  INTERRUPT ON 5
  GO()
  INTERRUPT OFF 5
  after = TRUE"""
    routines = """
DEF GO()
  LIN {X 0, Y 0, Z -50, A 0, B 0, C 0}
  WAIT SEC 0
  reached = TRUE
END

DEF STOPPED()
  BRAKE F
  hit = $POS_INT
  RESUME
END"""
    dat = "DECL BOOL after=FALSE\nDECL BOOL reached=FALSE\nDECL E6POS hit"

    def table(start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg: bool) -> np.ndarray:
        return start + 0.25 * (end - start)  # the table at a quarter of the way

    m = KrlMachine(krl(body, routines=routines, dat=dat), table).run()
    assert m.value("after") and not m.value("reached")
    assert np.abs(m.frame_m("hit")[:3, 3] - [0.0, 0.0, 0.025]).max() < 1e-12
    tcp = m.tcp_m()
    assert tcp is not None and np.abs(tcp[:3, 3] - [0.1, 0.0, 0.025]).max() < 1e-12
    assert m.motions[-1].interrupts == [5]


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ("  CIRC {X 1}, {X 2}", "CIRC is not supported"),
        ("  FOO BAR", "unknown statement"),
        ("  i = j", "J is invalid"),
        ("  i = 1\n  DECL INT k", "declaration after the first statement"),
        ("  $IN[1] = TRUE", "write-protected"),
        ("  b = 1 < 2 AND 3 > 2", "AND needs BOOL operands"),
        ("  i = 1.5:2", "must be a FRAME"),
        ("  LIN {X 1}", "TCP pose is unknown"),
    ],
)
def test_interpreter_errors_name_the_line(body: str, message: str) -> None:
    files = krl(body, dat="DECL INT i\nDECL INT j\nDECL BOOL b")
    with pytest.raises(KrlError, match=message) as err:
        KrlMachine(files, nothing).run()
    assert err.value.where is not None and err.value.where.number >= 2


# ------------------------------------------------------------------ the writer's KRL, strictly
def _stator_files() -> tuple[Plan, dict[str, str]]:
    plan = load_plan(STATOR)
    job = build_job(plan, nominal_T_base_wobj(plan), ToolData(T_flange_tcp=np.eye(4)))
    return plan, export_files(job, "krl")


def test_the_search_routines_resume_as_krl_allows() -> None:
    """SEARCH_RISE/SEARCH_FALL declare the interrupt and run the search ``LIN`` one level
    below, in SEARCH_MOVE: HIT_20/HIT_21's RESUME ends SEARCH_MOVE where the input switched
    and the program goes on in the search routine, here four levels below the main program
    (the adaptive A-H program's MEASURE_ADAPT, x<ID>_probe, PROBE_PX). (The writer once ran the
    ``LIN`` in the declaring routine: KSS stops with "impermissible program structure for
    RESUME".)"""
    plan, files = _stator_files()
    m = run(files, ideal_part(plan, nominal_T_base_wobj(plan)))
    assert len(m.searches) == 12 + 2 * 21  # A-H with C and D retaken, the x-offset run
    for s in m.searches:
        assert s.where.text.strip() == "LIN xTo" and s.interrupts in ([20], [21])
        assert s.end_m is not None and s.target_m is not None
        hit = s.events[-1]
        assert not isinstance(hit, str) and np.abs(s.end_m[:3, 3] - hit).max() < 1e-12
        assert np.abs(s.end_m[:3, 3] - s.target_m[:3, 3]).max() > 1e-3  # stopped on the way


def test_negative_edge_directions_are_written_in_parentheses() -> None:
    """``fDot*(-0.5)``, never ``fDot*-0.5`` (a sign right after ``*``, which KRL may refuse)."""
    plan = with_edges(load_plan(PLATE, check_files=False))
    job = build_job(plan, nominal_T_base_wobj(plan), ToolData(T_flange_tcp=np.eye(4)))
    src = export_files(job, "krl")[".src"]
    assert "*(-" in src and not re.search(r"\*\s*-", src)


def test_no_routine_parameter_shadows_module_data() -> None:
    """A routine's parameters and local data are not also names of the module's data list
    (KRL allows it, but which one a statement means is then a question)."""
    _, files = _stator_files()
    module, local = _krl_names(files)
    params = re.findall(r"^DEF(?:FCT \w+)? \w+\((.*)\)", files[".src"], re.M)
    names = local + [a.split(":")[0] for ps in params for a in ps.split(",") if a]
    assert names and not {n.upper() for n in names} & {n.upper() for n in module}


def _renamed(plan: Plan, ids: list[str]) -> Plan:
    """``plan`` with its first points renamed ``ids``."""
    points = [msgspec.structs.replace(p, id=i) for p, i in zip(plan.points, ids)]
    return msgspec.structs.replace(plan, points=points + plan.points[len(ids) :])


def _krl_names(files: dict[str, str]) -> tuple[list[str], list[str]]:
    """The names the module declares: the data list's and the routines' (``DEF`` and
    ``DEFFCT``: one scope), and the routines' parameters and local data (each routine's
    own)."""
    dat, src = files[".dat"], files[".src"]
    module = re.findall(r"^(?:DEFDAT|DECL \w+|SIGNAL) (\w+)", dat, re.M)
    module += re.findall(r"^DEF (\w+)", src, re.M)[1:]  # the main DEF is the DEFDAT's name
    module += re.findall(r"^DEFFCT \w+ (\w+)", src, re.M)
    local = [
        re.sub(r"\[.*", "", name).strip()
        for decl in re.findall(r"^  DECL \w+ (.*)$", src, re.M)
        for name in decl.split(",")
    ]
    return module, local


def assert_legal_names(files: dict[str, str]) -> list[str]:
    """At most 24 characters each, the module's unique ignoring case; returns them."""
    module, local = _krl_names(files)
    assert all(len(n) <= 24 for n in module + local), module + local
    assert len({n.upper() for n in module}) == len(module), module
    return module


@pytest.mark.parametrize(
    ("change", "names"),
    [
        pytest.param(
            lambda plan: _renamed(plan, ["P1", "p1"]),
            ["xP1_start", "xp1_2_start"],
            id="ids_differing_in_case",
        ),
        pytest.param(
            lambda plan: _renamed(plan, ["Point_number_one_long"]),
            ["xPoint_number_one_start"],
            id="long_point_id",
        ),
        pytest.param(
            lambda plan: _renamed(plan, ["Point_number_one_long", "POINT_NUMBER_ONE_LONGER"]),
            ["xPoint_number_one_start", "xPOINT_NUMBER_ON_2_start"],
            id="long_ids_cut_alike",
        ),
        pytest.param(
            lambda plan: msgspec.structs.replace(plan, name="plate holes three two one"),
            ["WobjcalPlateHolesThreeTw"],
            id="long_plan_name",
        ),
    ],
)
def test_names_are_legal_krl(change: Callable[[Plan], Plan], names: list[str]) -> None:
    """Point ids differing only in case get different KRL names (KRL is case-insensitive);
    ids over 17 characters (``x<id>_start``, ``x<id>_probe``) and plan names whose words join
    to over 17 characters (``Wobjcal<Words>``) are cut to KRL's 24 characters. The plan model
    accepts all of them; the (adaptive best fit) program compiles and measures as executed."""
    plan = load_plan(PLATE_BEST_FIT, check_files=False)
    plan = change(msgspec.structs.replace(plan, points=plan.points[:3]))
    job = build_job(plan, nominal_T_base_wobj(plan), ToolData(T_flange_tcp=np.eye(4)))
    assert job.program("krl").adaptive
    files = export_files(job, "krl")
    m = run(files, PlaneWorld(plan, job.T_base_wobj))
    assert_runs_as_executed(m, job, PlaneWorld(plan, job.T_base_wobj))
    assert set(names) <= set(assert_legal_names(files))
    assert {f"{n[: -len('_start')]}_probe" for n in names if n.endswith("_start")} <= set(
        assert_legal_names(files)
    )


def test_random_long_ids_and_names_make_legal_krl() -> None:
    """Point ids of up to 32 characters (the plan's limit) differing in case or only after
    their 17th character, with vias, and a long plan name: the module compiles, runs and
    measures every point as computed."""
    rng = np.random.default_rng(23)
    plan = with_edges(load_plan(PLATE, check_files=False))
    stem = "".join(rng.choice(list("abcXYZ_09"), 16))
    ids = [f"{stem}{k}" for k in range(3)] + [f"{stem}0".upper(), f"{stem}0".lower(), "S" * 32]
    plan = _renamed(plan, ids[: len(plan.points)])
    plan = msgspec.structs.replace(plan, name="a very long plan name " * 3)
    job = build_job(plan, nominal_T_base_wobj(plan), ToolData(T_flange_tcp=np.eye(4)))
    files = export_files(job, "krl")
    T_true = job.T_base_wobj @ full_misplacement(plan, rng)
    m = run(files, PlaneWorld(plan, T_true))
    assert_runs_as_computed(m, job, Expected(job, PlaneWorld(plan, T_true)))
    per_point = [3 + (t.kind == "edge") + len(t.vias_q_rad) for t in job.targets]
    assert len(assert_legal_names(files)) == 13 + 5 + sum(per_point)  # data, routines, targets
