"""The adaptive A-H URScript program, run in :mod:`tests.urscript_interp` against an ideal part,
does what :func:`calib.paper.stator_procedure.run_stator_procedure` does (every variant of its
settings); its x-offset run gives the matrix and the slot targets of
:mod:`calib.paper.xoffset`; and the writer refuses a program whose steps the procedure does not
take. The replay against a validate trial is in
``tests/planner/export/test_urscript_adaptive_replay.py``.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import msgspec
import numpy as np
import pytest

from calib.frames import invert_transform, transform_directions, transform_points
from calib.paper.stator_procedure import run_stator_procedure
from calib.paper.xoffset import slot_target, xoffset_matrix
from calib.plan.file import Plan, load_plan
from calib.procedures.hultman2013 import points_by_role
from planner.export import export_files
from planner.export.job import ExportJob, ToolData, build_job
from planner.export.urscript_layout import slot_table
from planner.plan_cell import nominal_T_base_wobj
from planner.program.model import SearchStep
from tests.box_part import BoxProbe, distance_to_box
from tests.planner.export.test_export_rapid_adaptive import full_misplacement, rapid_search
from tests.planner.export.test_export_rapid_xoffset import affine_face
from tests.planner.export.test_urscript_adaptive_replay import angle_rad
from tests.reference_data import plate_case
from tests.urscript_interp import (
    Pose,
    SearchFn,
    UrMachine,
    UrRuntimeError,
    _assigned,
    _declared,
)

PLAN = Path(__file__).resolve().parents[3] / "assets" / "plans" / "stator_section_ah.json"
VARIANTS: dict[str, dict[str, Any]] = {
    "plan": {},
    "from_measured": {"edge_start_from_measured": True, "edge_start_offset_m": 0.004},
    "event_offset": {"edge_event_offset_m": 0.002},
    "no_retake": {"retake_c_d": False},
}
#: The A-H searches before the x-offset run: A B C D E, F (face, edge), G, H (face, edge), C2, D2.
N_AH = 12


def _plan(**settings: Any) -> Plan:
    """The shipped stator plan; the box's ideal sensor reports an edge at the edge, so the
    plan says so (offset 0, measured), else every face takes the sensor model's 6.3 mm."""
    plan = load_plan(PLAN)
    proc = msgspec.structs.replace(plan.procedure, **{"edge_event_offset_m": 0.0, **settings})
    return msgspec.structs.replace(plan, procedure=proc)


def _job(plan: Plan) -> ExportJob:
    return build_job(plan, nominal_T_base_wobj(plan), ToolData(T_flange_tcp=np.eye(4)))


def on_at_measured_start(search: SearchFn, T_base_true: np.ndarray, reach_m: float) -> SearchFn:
    """``search``, with a sensor that sees the face from up to ``reach_m`` outside it: a
    motion that ends that close to the part without entering it switches the input on at its
    end (the plan's assumption for an edge search started ``edge_start_offset_m`` outside the
    face at a measured point, as for RAPID's ``SearchL \\NegFlank`` from there)."""
    T_true_base = invert_transform(T_base_true)

    def answer(start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg_flank: bool) -> Any:
        got = search(start, end, axis, neg_flank)
        if neg_flank or not isinstance(got, str) or got == "ERR_SIGSUPSEARCH":
            return got
        gap = distance_to_box(transform_points(T_true_base, end))
        return end.copy() if 0.0 < gap <= reach_m + 1e-9 else got

    return answer


@pytest.mark.parametrize("seed", range(2))
@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_program_frame_equals_the_procedure(seed: int, variant: str) -> None:
    plan = _plan(**VARIANTS[variant])
    T_nom = nominal_T_base_wobj(plan)
    T_true = T_nom @ full_misplacement(plan, np.random.default_rng(seed))
    job = _job(plan)
    program = job.program("urscript")
    assert program.adaptive and program.name == "URScript, adaptive A-H"
    text = export_files(job, "urscript")[".script"]
    search = rapid_search(BoxProbe(T_true))
    if variant == "from_measured":
        assert "def measure_F(start_base):" in text and "meas_F = measure_F(point_of(4))" in text
        search = on_at_measured_start(search, T_true, 0.004)
    m = UrMachine(text, search).run()
    assert m.finished and not m.halted, m.messages[-3:]
    assert any(msg.startswith("wobjcal: A-H done") for msg in m.messages), m.messages
    T_prog = m.frame("wobj")
    ref = run_stator_procedure(
        points_by_role(plan.role_points()), T_nom, BoxProbe(T_true), plan.procedure
    )
    assert np.abs(T_prog[:3, 3] - ref.T_base_wobj[:3, 3]).max() < 1e-9
    assert angle_rad(T_prog, ref.T_base_wobj) < 1e-9
    if variant != "event_offset":  # both found the true part (noise-free: exact)
        assert np.abs(T_prog[:3, 3] - T_true[:3, 3]).max() < 1e-9
    # every measurement is the procedure's (retakes in slots of their own)
    table = slot_table(job, program)
    got = np.asarray(m.variables["measured"]).reshape(-1, 3)
    assert m.variables["measured_code"] == [0.0] * len(table)
    role = {p.id: p.role for p in plan.points}
    for k, (pid, take) in enumerate(table):
        key = role[pid] + ("" if take == 1 else str(take))
        assert np.abs(got[k] - ref.measured_m[key]).max() < 1e-9, key
    n_searches = len(m.searches) - 2 * 21  # the x-offset run: 21 teeth at two levels
    # from_measured: no approach to the face before F and H, but the move to the measured
    # start is watched (the sensor must be on there)
    assert n_searches == N_AH - (2 if variant == "no_retake" else 0)
    # every approach search starts at least the sensing distance outside the true part; an
    # edge search on its face (from the measured face point) or off it by the start offset
    sd = plan.validation.sensor.sensing_distance_m
    off = VARIANTS[variant].get("edge_start_offset_m", 0.0)
    T_true_base = invert_transform(T_true)
    for mo in m.searches[:n_searches]:
        dist = distance_to_box(transform_points(T_true_base, mo.start_m))  # type: ignore[arg-type]
        assert mo.search is not None
        if mo.search.neg_flank:
            assert abs(dist - off) < 1e-9, dist
        elif mo.kind == "movel" and mo.thread == "main":  # probe_from's move to the start
            assert variant == "from_measured" and dist > sd
        else:
            assert dist > sd, dist


def test_a_failed_search_stops_the_procedure_with_what_was_measured() -> None:
    plan = _plan()
    T_nom = nominal_T_base_wobj(plan)
    search = rapid_search(BoxProbe(T_nom))
    calls: list[int] = []

    def failing(start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg_flank: bool) -> Any:
        calls.append(1)
        return "ERR_WHLSEARCH" if len(calls) == 3 else search(start, end, axis, neg_flank)

    job = _job(plan)
    before = UrMachine(export_files(job, "urscript")[".script"], search).run()
    m = UrMachine(export_files(job, "urscript")[".script"], failing).run()
    assert m.halted and len(calls) == 3  # nothing searched after C failed
    assert m.messages[-1].startswith("wobjcal/1 stop A-H: point C: code"), m.messages
    assert m.variables["measured_code"] == [0.0, 0.0, 1.0] + [-1.0] * 7
    got = np.asarray(m.variables["measured"]).reshape(-1, 3)
    want = np.asarray(before.variables["measured"]).reshape(-1, 3)
    assert np.abs(got[:2] - want[:2]).max() < 1e-12 and not got[2:].any()
    assert m.variables["meas_C"][0] == 1.0 and m.variables["meas_D"][0] == -1.0
    # the robot went back to C's safe start (probe's retreat) before the program stopped
    assert m.motions[-1].kind == "movel" and m.motions[-1].thread == "main"


def test_x_offset_matrix_and_slot_targets_match_the_python_of_eq_14() -> None:
    """The A-H run on the nominal box, then the x-offset run on an affine bulge of the side
    face: eq. 14 reproduces it exactly, as :func:`calib.paper.xoffset.xoffset_matrix` does."""
    plan = _plan()
    T = nominal_T_base_wobj(plan)
    c, a, b = 0.0004, -0.0003, 0.002
    box, bulge = rapid_search(BoxProbe(T)), affine_face(T, c, a, b)
    calls: list[int] = []

    def search(start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg_flank: bool) -> Any:
        calls.append(1)
        return (box if len(calls) <= N_AH else bulge)(start, end, axis, neg_flank)

    job = _job(plan)
    m = UrMachine(export_files(job, "urscript")[".script"], search).run()
    assert m.finished and not m.halted, m.messages[-3:]
    assert np.abs(m.frame("wobj") - T).max() < 1e-9  # the nominal box: the nominal frame
    run = plan.procedure.xoffset  # type: ignore[union-attr]
    grid = run.grid
    px = np.asarray(m.variables["px_meas"]).reshape(2, 21, 3)
    assert np.allclose(px[..., 0], c + a * px[..., 1] + b * px[..., 2], atol=1e-9)
    mx = np.asarray(m.variables["mx_w"], float).reshape(grid.n_layers, grid.n_slots)
    mx_python = xoffset_matrix(px, grid)
    np.testing.assert_allclose(mx, mx_python, atol=1e-9)
    yy, zz = np.meshgrid(grid.slot_y_m, grid.layer_z_m)
    np.testing.assert_allclose(mx, c + a * yy + b * zz, atol=1e-9)
    # the paper's target function: slot 40, layer 6, 5 mm out, in wobj
    target = m.call("slot_target", 40, 6, 0.005)
    assert isinstance(target, Pose)
    T_t = slot_target(T, grid, 40, 6, standoff_m=0.005, xoffset=mx_python)
    np.testing.assert_allclose(transform_points(T, target.position_m), T_t[:3, 3], atol=1e-9)
    # searched along -x of the work object, from 20 mm out, with D's orientation
    xo = [mo for mo in m.searches][N_AH:]
    assert len(xo) == 42
    for mo in xo:
        assert mo.search is not None and mo.start_m is not None
        d = transform_directions(invert_transform(T), mo.search.end_m - mo.search.start_m)
        np.testing.assert_allclose(d / np.linalg.norm(d), [-1, 0, 0], atol=1e-9)
        start = transform_points(invert_transform(T), mo.start_m)
        assert start[0] - (c + a * start[1] + b * start[2]) > 0.019


def test_a_failed_x_offset_search_stops_the_program_with_its_name() -> None:
    plan = _plan()
    T = nominal_T_base_wobj(plan)
    box = rapid_search(BoxProbe(T))
    calls: list[int] = []

    def search(start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg_flank: bool) -> Any:
        calls.append(1)
        return box(start, end, axis, neg_flank) if len(calls) <= N_AH else "ERR_WHLSEARCH"

    m = UrMachine(export_files(_job(plan), "urscript")[".script"], search).run()
    assert m.halted and len(calls) == N_AH + 1
    assert m.messages[-1] == "wobjcal/1 stop A-H: x-offset point PX1_1 not found"
    assert np.abs(m.frame("wobj") - T).max() < 1e-9  # the calibrated frame is kept


def test_the_writer_refuses_steps_the_procedure_does_not_take() -> None:
    """The main body follows the program's steps: a program that searches D before C, or
    D before the update after C, or that ends before the procedure's last update, is not
    written."""
    job = _job(_plan())
    program = job.program("urscript")
    steps = list(program.steps)
    k = next(i for i, s in enumerate(steps) if isinstance(s, SearchStep) and s.key == "C")
    # steps[k - 1 : k + 4]: move to C, search C, update, move to D, search D
    swapped = steps[: k - 1] + steps[k + 2 : k + 4] + steps[k - 1 : k + 2] + steps[k + 4 :]
    early = steps[: k + 1] + steps[k + 2 : k + 4] + [steps[k + 1]] + steps[k + 4 :]
    for bad, why in ((swapped, "the A-H procedure"), (early, "before the procedure's update")):
        wrong = replace(program, steps=tuple(bad))
        with pytest.raises(ValueError, match=why):
            export_files(replace(job, programs={**job.programs, "urscript": wrong}), "urscript")
    short = replace(program, steps=tuple(steps[:-1]))  # no FrameStep: no last update
    with pytest.raises(ValueError, match="ends before the procedure's last update"):
        export_files(replace(job, programs={**job.programs, "urscript": short}), "urscript")


def test_call_computes_a_function_and_refuses_one_that_moves() -> None:
    m = UrMachine(
        "def prog():\n"
        "  k = 2.0\n"
        "  def f(x):\n"
        "    return [to_str(x * k), str_len(to_str(x))]\n"
        "  end\n"
        "  def g():\n"
        "    movel(p[0, 0, 0, 0, 0, 0])\n"
        "  end\n"
        "end\n",
        lambda *a: "ERR_WHLSEARCH",
    ).run()
    assert m.call("f", 1.5) == ["3.0", 3]
    with pytest.raises(UrRuntimeError, match="unknown TCP"):
        m.call("g")
    with pytest.raises(KeyError):
        m.call("h")


@pytest.mark.parametrize(
    "variant",
    [
        plate_case("plate_holes_best_fit.json"),
        plate_case("plate_holes_321.json"),
        "stator",
        "stator_from_measured",
    ],
)
def test_every_global_a_function_assigns_is_declared_global(variant: str) -> None:
    """The URScript manual binds a name a function assigns, without ``global`` or ``local``, to
    the global of that name when there is one (the interpreter does so); read strictly, a
    variable assigned in a function is local unless declared ``global``. The programs declare
    ``global`` for every global a function or thread assigns, so they mean the same either way,
    and no function's local shares a global's name."""
    if variant.startswith("stator"):
        plan = _plan(**(VARIANTS["from_measured"] if variant.endswith("measured") else {}))
    else:
        plan = load_plan(PLAN.parent / variant)
    job = _job(plan)
    assert job.program("urscript").adaptive
    prog = UrMachine(export_files(job, "urscript")[".script"], lambda *a: "ERR_WHLSEARCH").program
    for f in prog.functions.values():
        assigned = _assigned(f.body)
        undeclared = (assigned & prog.globals) - _declared(f.body, "global")
        assert not undeclared, (f.name, sorted(undeclared))
