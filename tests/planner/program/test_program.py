"""The measuring program (``planner.program``): one program per plan and controller, executed as
the exported program runs it.

Checked against things not derived from the executor: the export job's safe starts and search
ends (what the writers put in the files), line-plane intersections on the true part, the RAPID
interpreter running the exported module, and the procedures' own runs.
"""

from __future__ import annotations

from pathlib import Path

import msgspec
import numpy as np
import pytest

from calib.errors import InputError
from calib.frames import invert_transform, transform_directions, transform_points
from calib.plan.file import Plan, load_plan
from calib.probing import ProbeResult, SearchCommand
from calib.procedures import procedure_kind
from planner.export import export_files
from planner.export.job import ToolData, build_job
from planner.plan_cell import nominal_T_base_wobj
from planner.program import CONTROLLERS, execute, measuring_program
from planner.program.build import probe_orders
from tests.box_part import BoxProbe
from tests.planner.export.test_export_rapid_adaptive import full_misplacement, rapid_search
from tests.rapid_interp import Machine, _vec

PLANS = Path(__file__).resolve().parents[3] / "assets" / "plans"
STATOR = PLANS / "stator_section_ah.json"
PLATE_FIT = PLANS / "plate_holes_best_fit.json"
PLATE_321 = PLANS / "plate_holes_321.json"


@pytest.mark.reference
def test_a_plan_and_a_controller_give_one_named_program() -> None:
    stator, fit, three = load_plan(STATOR), load_plan(PLATE_FIT), load_plan(PLATE_321)
    assert measuring_program(stator, "rapid").name == "RAPID, adaptive A-H"
    assert measuring_program(stator, "fanuc").name == "TP, nominal A-H"
    assert measuring_program(fit, "fanuc").name == "TP, nominal best fit"
    assert measuring_program(three, None).name == "RAPID, adaptive 3-2-1"
    assert measuring_program(fit, "rapid").name == "RAPID, adaptive best fit"
    assert "nominal frame" in measuring_program(fit, "fanuc").note
    assert measuring_program(stator, "rapid").note == ""
    # an edge search: the RAPID best-fit update takes approach searches only
    edge = next(p for p in stator.points if p.search.kind == "edge")
    with_edge = msgspec.structs.replace(
        fit, points=(*fit.points, msgspec.structs.replace(edge, id="E9", role="fit"))
    )
    prog = measuring_program(with_edge, "rapid")
    assert prog.name == "RAPID, nominal best fit" and "approach searches only" in prog.note
    with pytest.raises(
        InputError,
        match=r"unknown controller \(--format\) '.*'; known: fanuc, krl, rapid, urscript",
    ):
        measuring_program(stator, "kawasaki")


def test_the_adaptive_order_comes_from_the_procedure_itself() -> None:
    plan = load_plan(STATOR)
    role = {p.id: p.role for p in plan.points}
    rapid = measuring_program(plan, "rapid")
    assert [role[i] for i in rapid.probe_order] == [*"ABCDEFGH", "C", "D"]
    assert [s.key for s in rapid.searches if s.recorded][-2:] == ["C2", "D2"]
    no_retake = msgspec.structs.replace(plan.procedure, retake_c_d=False)
    short = measuring_program(msgspec.structs.replace(plan, procedure=no_retake), "rapid")
    assert [role[i] for i in short.probe_order] == list("ABCDEFGH")
    tp = measuring_program(plan, "fanuc")
    assert tp.probe_order == tuple(p.id for p in plan.points)
    assert all(s.frame == "nominal" for s in tp.searches)
    # check walks the moves of every program: plan order and the RAPID order with retakes
    index = {p.id: i for i, p in enumerate(plan.points)}
    assert sorted(probe_orders(plan)) == sorted(
        [list(range(8)), [index[i] for i in rapid.probe_order]]
    )


@pytest.mark.slow
def test_every_writer_names_its_own_program() -> None:
    from planner.export_plan.job import export_program
    from planner.plan_cell import open_cell

    plan = load_plan(STATOR)
    with open_cell(plan, PLANS) as cell:
        for name in CONTROLLERS:
            files = export_program(plan, PLANS, name, cell=cell).files
            text = " ".join(" ".join(files.values()).split())
            assert f"PROGRAM: {measuring_program(plan, name).name}" in text, name


def _planes_probe(plan: Plan, T_true: np.ndarray, log: list[SearchCommand]):  # type: ignore[no-untyped-def]
    """An exact probe on the plan's faces at ``T_true``: an approach ends on the plane of its
    point's face, an edge search where its line crosses the plane of the face it finds."""
    by_id = {p.id: p for p in plan.points}

    def probe(cmd: SearchCommand) -> ProbeResult:
        log.append(cmd)
        p = by_id[cmd.point_id.split("@")[0]]
        normal = p.normal if cmd.kind == "approach" else p.edge_normal
        assert normal is not None
        at = transform_points(T_true, np.asarray(p.position_m))
        n = transform_directions(T_true, np.asarray(normal, dtype=float))
        t = float((at - cmd.start_m) @ n) / float(cmd.direction @ n)
        assert 0.0 <= t <= cmd.length_m
        return ProbeResult(cmd.start_m + t * cmd.direction, travel_m=t)

    return probe


@pytest.mark.reference
@pytest.mark.parametrize("path", [PLATE_FIT, PLATE_321])
@pytest.mark.parametrize("seed", range(3))
def test_a_nominal_program_searches_from_the_exported_safe_starts(path: Path, seed: int) -> None:
    """Each search of the executed nominal program is the exported one (safe start, nominal
    direction, up to the plan's end), and the frame is the procedure's estimate of them."""
    plan = load_plan(path)
    T_nom = nominal_T_base_wobj(plan)
    T_true = T_nom @ full_misplacement(plan, np.random.default_rng(seed))
    prog = measuring_program(plan, "fanuc")
    log: list[SearchCommand] = []
    run = execute(prog, T_nom, _planes_probe(plan, T_true, log))
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    assert [c.point_id for c in log] == [t.point_id for t in job.targets]
    T_wobj_true = invert_transform(T_true)
    expected = {}
    for t, cmd in zip(job.targets, log, strict=True):
        start = transform_points(T_nom, t.safe_start[:3, 3])
        end = transform_points(T_nom, t.face_end[:3, 3])
        assert np.allclose(cmd.start_m, start, atol=1e-12)
        assert np.allclose(cmd.start_m + cmd.length_m * cmd.direction, end, atol=1e-12)
        assert np.allclose(cmd.T_base_wobj_estimate, T_nom)
        # where that line meets the true face, computed here in the true part's frame
        s, d = transform_points(T_wobj_true, start), transform_directions(T_wobj_true, end - start)
        p = next(q for q in plan.points if q.id == t.point_id)
        n = np.asarray(p.normal)
        expected[t.point_id] = transform_points(
            T_true, s + float((np.asarray(p.position_m) - s) @ n) / float(d @ n) * d
        )
    for pid, q in expected.items():
        assert np.abs(np.asarray(run.measured_m[pid]) - q).max() < 1e-12, pid
    kind = procedure_kind(plan.procedure)
    table = {k: v[None] for k, v in expected.items()}
    ref = kind.estimate(plan.role_points(), table, T_nom, plan.procedure)
    assert np.abs(run.T_base_wobj - ref.T_base_wobj).max() < 1e-12


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("retake", [True, False])
def test_the_adaptive_rapid_program_measures_what_the_executed_program_measures(
    seed: int, retake: bool
) -> None:
    """The exported RAPID module, run in the RAPID interpreter on an ideal part, records the
    points and computes the frame the executed program does (1e-6 mm; RAPID's own numbers are
    written with 6+ digits)."""
    plan = load_plan(STATOR)
    plan = msgspec.structs.replace(
        plan, procedure=msgspec.structs.replace(plan.procedure, retake_c_d=retake)
    )
    T_nom = nominal_T_base_wobj(plan)
    T_true = T_nom @ full_misplacement(plan, np.random.default_rng(100 + seed))
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    m = Machine(export_files(job, "rapid")[".mod"], rapid_search(BoxProbe(T_true)))
    m.main()
    prog = measuring_program(plan, "rapid")
    log: list[str] = []
    box = BoxProbe(T_true)

    def probe(cmd: SearchCommand) -> ProbeResult:
        log.append(cmd.point_id)
        return box(cmd)

    run = execute(prog, T_nom, probe)
    assert np.abs(m.wobj_matrix_m("wobjCal")[:3, 3] - run.T_base_wobj[:3, 3]).max() < 1e-9
    # every search the program ran, face approaches included, in the program's order
    assert log == [s.key for s in prog.searches]


@pytest.mark.reference
def test_a_validate_trial_executes_the_program_of_the_chosen_controller() -> None:
    from planner.validate.job import validate_plan

    plan = load_plan(PLATE_FIT)
    report = validate_plan(plan, trials=4, seed=3, workers=1, plan_dir=PLANS, fmt="fanuc")
    assert report.program.startswith("TP, nominal best fit")
    assert report.program_steps[0] == "1. joint move to the safe start of T1"
    assert "Program: TP, nominal best fit" in report.to_markdown()
    # one search per point: no second round, no re-aimed search
    assert {o.point_id: o.searches for o in report.outcomes} == {p.id: 4 for p in plan.points}


def _world_probe(world):  # type: ignore[no-untyped-def]
    """The same ideal part as a :data:`calib.probing.Probe` (what the executor calls)."""

    def probe(cmd: SearchCommand) -> ProbeResult:
        end = cmd.start_m + cmd.length_m * cmd.direction
        hit = world(cmd.start_m, end, cmd.sensor_axis, cmd.kind == "edge")
        if isinstance(hit, str):
            return ProbeResult(None, hit)
        return ProbeResult(np.asarray(hit, dtype=float))

    return probe


@pytest.mark.reference
@pytest.mark.parametrize("path", [PLATE_FIT, PLATE_321])
@pytest.mark.parametrize("seed", range(3))
def test_the_adaptive_rapid_fit_programs_compute_what_the_executor_computes(
    path: Path, seed: int
) -> None:
    """RAPID's best-fit and 3-2-1 programs steer themselves (``Steer``: Gauss-Newton with
    the update's basis as constants): run in the RAPID interpreter on an ideal part misplaced
    at the plan's full bound, every measured point and the final wobjCal equal the executed
    program's (1e-6 mm), and the frame is the true part's (exact measurements)."""
    from calib.plan.measurements import measurements_from_json
    from tests.planner.export.test_krl_program_runs import PlaneWorld

    plan = load_plan(path)
    T_nom = nominal_T_base_wobj(plan)
    T_true = T_nom @ full_misplacement(plan, np.random.default_rng(200 + seed))
    prog = measuring_program(plan, "rapid")
    assert prog.steers_itself and prog.name.startswith("RAPID, adaptive")
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    world = PlaneWorld(plan, T_true)
    m = Machine(export_files(job, "rapid")[".mod"], world)
    m.main()
    assert m.tp[-2].startswith("wobjcal: done"), m.tp
    run = execute(prog, T_nom, _world_probe(world))
    meas = measurements_from_json(m.files["wobjcal_measured.json"], "program")
    slot = {t.point_id: i for i, t in enumerate(job.targets)}
    for pid, q in run.measured_m.items():  # the PERS array (the file has 0.001 mm)
        assert np.abs(_vec(m.globals["measured"][slot[pid]]) / 1000.0 - q).max() < 1e-9, pid
        assert np.abs(np.asarray(meas.points[pid]) / 1000.0 - q).max() < 1e-6, pid
    T_prog = m.wobj_matrix_m("wobjCal")
    assert np.abs(T_prog[:3, 3] - run.T_base_wobj[:3, 3]).max() < 1e-9
    assert np.abs(T_prog[:3, :3] - run.T_base_wobj[:3, :3]).max() < 1e-9
    assert np.abs(run.T_base_wobj - T_true).max() < 1e-9  # exact planes: the true part
    # and it is the frame `wobjcal calibrate` computes from the program's file
    kind = procedure_kind(plan.procedure)
    table = {k: np.asarray(v)[None] for k, v in run.measured_m.items()}
    ref = kind.estimate(plan.role_points(), table, T_nom, plan.procedure)
    assert np.abs(ref.T_base_wobj - T_prog).max() < 1e-9
