"""The adaptive KUKA KRL programs (best fit, 3-2-1, A-H with its x-offset run), run in the KRL
interpreter (:mod:`tests.krl_interp`) against the simulated sensor of one validate trial of the
KRL program, measure what that trial measured and end with its frame in ``BASE_DATA[10]``.

One validate trial executes the KRL measuring program (``planner.program.execute``) with the
simulated sensor on the misplaced real mesh, its noise drawn search by search from the trial's
seed. Here the same sensor with the same seed answers the searches the exported ``.src``/``.dat``
asks for: when the program commands the same searches in the same order, in the same estimated
frames, the noise draws line up and every recorded point matches (an approach to the written
precision, 1e-7 m; an edge search to the simulator's bisection of the edge event,
``edge_tolerance_m``), and the frame computed on the controller is the trial's (1e-6 m, 1e-8 rad
for best fit and 3-2-1; 5e-5 m and 1e-4 rad for A-H, whose F and H pass the bisection on).
After A-H the x-offset run continues the same trial: its matrix is the one the trial's run computes.

Then what a failure does: a search that finds nothing, or an input already at its level, stops
the adaptive program there (``nResult`` 2, ``nStopAt`` the slot), the points measured before it
kept, the later ones not run (``nFail`` 3), the robot back at the failed point's safe start; a
failed x-offset search stops the run (``nResult`` 4) with the frame calibrated.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import msgspec
import numpy as np
import pytest

from calib.paper.xoffset import slot_target, xoffset_matrix
from calib.plan.file import load_plan
from calib.probing import ProbeResult, SearchCommand
from planner.export import export_files
from planner.export.job import ToolData, build_job
from planner.export.krl_adaptive import measured_slots
from planner.plan_cell import nominal_T_base_wobj
from planner.program import execute
from planner.program.model import MeasuringProgram, SearchStep, UpdateStep
from planner.program.steering import steer
from planner.sim.xoffset import run_xoffset
from tests.krl_interp import KrlMachine, SearchFn
from tests.planner.export.test_export_rapid_adaptive import full_misplacement
from tests.planner.export.test_krl_program_runs import (
    assert_same_frame,
    base_m,
    ideal_part,
    probe_of,
    slot_of,
    written,
)
from tests.planner.validate.test_program_trial_replay import (
    A_H_TOL_M,
    A_H_TOL_RAD,
    _search_callback,
    _trial,
)
from tests.reference_data import plate_case

PLANS = Path(__file__).resolve().parents[3] / "assets" / "plans"
STATOR = PLANS / "stator_section_ah.json"
PLATE_321 = PLANS / "plate_holes_321.json"
#: Agreement of a recorded approach point, metres: the written decimals (1e-6 mm) and better.
TOL_M = 1e-7


def failing_at(search: SearchFn, k: int, answer: str = "ERR_WHLSEARCH") -> SearchFn:
    """``search`` that gives ``answer`` at its ``k``-th call."""
    calls = [0]

    def fn(start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg: bool) -> Any:
        calls[0] += 1
        return answer if calls[0] == k else search(start, end, axis, neg)

    return fn


# ------------------------------------------------------------------ the replay
@pytest.mark.slow
@pytest.mark.parametrize(
    ("name", "seed"),
    [
        plate_case("plate_holes_best_fit.json", 1),
        plate_case("plate_holes_321.json", 2),
        ("stator_section_ah.json", 3),
    ],
)
def test_the_adaptive_krl_program_replays_a_validate_trial(name: str, seed: int) -> None:
    plan, setup, probe, T_true = _trial(PLANS / name, "krl", seed)
    program = setup.program
    assert program.adaptive and program.name.startswith("KRL, adaptive")
    T_nom = setup.T_base_wobj_nominal
    trial = probe()
    run = execute(program, T_nom, trial)
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    files = export_files(job, "krl")
    assert f"PROGRAM: {program.name}. ADAPTIVE:" in files[".src"].replace("\n  ; ", " ")
    m = KrlMachine(files, _search_callback(probe())).run()
    assert m.finished and m.halted is None
    assert m.value("nResult") == 1, (m.value("nResult"), m.ints())
    slots = slot_of(job)
    assert set(m.ints().values()) == {0}  # every slot measured, retakes included
    got = m.measured_m()
    assert set(run.measured_m) == {k for k in slots if slots[k] in got}
    # the frame on the controller is the trial's (A-H: to F and H's bisection)
    tol_m, tol_rad = (1e-6, 1e-8) if program.method != "hultman2013" else (A_H_TOL_M, A_H_TOL_RAD)
    after_edge = _after_an_edge_update(program)
    by_id = {p.id: p for p in plan.points}
    for key, q in run.measured_m.items():
        d = got[slots[key]] - np.asarray(q)
        point = by_id[key.split("#")[0]]
        if point.search.kind == "edge":  # to the simulator's bisection of the edge event
            assert np.abs(d).max() < setup.edge_tolerance_m, (key, d)
        elif key in after_edge:  # in a frame that F's and H's bisection moved a little
            n = run.T_base_wobj[:3, :3] @ np.asarray(point.normal)
            assert abs(float(d @ n)) < TOL_M and np.abs(d).max() < tol_m, (key, d)
        else:
            assert np.abs(d).max() < TOL_M, (key, d)
    assert_same_frame(base_m(m), run.T_base_wobj, tol_m, tol_rad)
    assert np.abs(m.base_m() - base_m(m)).max() < 1e-12  # and $BASE is it
    if setup.xoffset is None:
        assert len(m.search_calls) == len(program.searches)
        return
    # the x-offset run goes on with the trial's sensor, in the frame each calibrated
    px_trial: list[np.ndarray] = []

    def recorded(cmd: SearchCommand) -> ProbeResult:
        res = trial(cmd)
        px_trial.append(np.asarray(res.point_m))
        return res

    run_xoffset(setup.xoffset, recorded, run.T_base_wobj, T_true)
    grid = setup.xoffset.run.grid
    px = np.array([[m.frame_m(v)[:3, 3] for v in row] for row in _rows(m, "xPxMeas")])
    T_wb = np.linalg.inv(run.T_base_wobj)
    px_want = (np.array(px_trial) @ T_wb[:3, :3].T + T_wb[:3, 3]).reshape(px.shape)
    assert len(m.search_calls) == len(program.searches) + px.shape[0] * px.shape[1]
    assert np.abs(px - px_want).max() < A_H_TOL_M
    mx = np.array(_rows(m, "fMxW"), dtype=float) / 1e3
    np.testing.assert_allclose(mx, xoffset_matrix(px, grid), atol=1e-9)  # eq. 14 of its points
    np.testing.assert_allclose(mx, xoffset_matrix(px_want, grid), atol=A_H_TOL_M)  # the trial's


def _after_an_edge_update(program: MeasuringProgram) -> set[str]:
    """The measurement keys (``id``, ``id#2``) of the searches commanded after an update that
    used an edge point."""
    edge_seen = moved = False
    keys: dict[str, int] = {}
    out: set[str] = set()
    for step in program.steps:
        if isinstance(step, SearchStep) and step.recorded:
            keys[step.point_id] = keys.get(step.point_id, 0) + 1
            if moved:
                n = keys[step.point_id]
                out.add(step.point_id if n == 1 else f"{step.point_id}#{n}")
            edge_seen = edge_seen or step.kind == "edge"
        elif isinstance(step, UpdateStep) and edge_seen:
            moved = True
    return out


def _rows(m: KrlMachine, name: str) -> list[list[Any]]:
    """A 2-D array of the data list as rows (KRL indices from 1, row-major)."""
    arr = m.value(name)
    k, n = arr.dims
    return [arr.data[i * n : (i + 1) * n] for i in range(k)]


# ------------------------------------------------------------------ the ideal part
@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize(
    "path", [STATOR, plate_case(PLATE_321), plate_case(PLANS / "plate_holes_best_fit.json")]
)
def test_on_an_ideal_part_the_program_is_the_executed_program(path: Path, seed: int) -> None:
    """Noise-free, the part at the full misplacement: every search the program commands is the
    one the executed program commands (start and end to 1e-6 mm), so the points and frame are
    its own to 1e-9 m; and the plate's frame is the true part's."""
    plan = load_plan(path)
    T_nom = nominal_T_base_wobj(plan)
    T_true = T_nom @ full_misplacement(plan, np.random.default_rng(seed))
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    program = job.program("krl")
    commands: list[SearchCommand] = []
    world = ideal_part(plan, T_true)
    ideal = probe_of(world)

    def recording(cmd: SearchCommand) -> ProbeResult:
        commands.append(cmd)
        return ideal(cmd)

    run = execute(program, T_nom, recording)
    m = KrlMachine(export_files(job, "krl"), world).run()
    assert m.value("nResult") == 1
    calls = m.search_calls[: len(commands)]
    assert len(calls) == len(commands)
    for call, cmd in zip(calls, commands, strict=True):
        assert np.abs(call.start_m - cmd.start_m).max() < 1e-9
        assert np.abs(call.end_m - (cmd.start_m + cmd.length_m * cmd.direction)).max() < 1e-9
    slots, got = slot_of(job), m.measured_m()
    for key, q in run.measured_m.items():
        assert np.abs(got[slots[key]] - np.asarray(q)).max() < 1e-9, key
    assert_same_frame(base_m(m), run.T_base_wobj, 1e-9, 1e-9)
    if program.method != "hultman2013":  # (A-H's F and H take the sensor model's offset)
        assert_same_frame(base_m(m), T_true, 1e-9, 1e-9)


def test_from_measured_edge_starts_and_no_retakes_follow_the_procedure() -> None:
    """A-H with F and H started from the measured E and G (4 mm out) and no retakes: the
    program moves from the safe start straight to that start (no approach to the face), keeps
    8 slots, and ends with the executed program's frame (an input on where the sensor is over
    the part)."""
    plan = load_plan(STATOR)
    proc = msgspec.structs.replace(
        plan.procedure,
        edge_event_offset_m=0.0,
        edge_start_from_measured=True,
        edge_start_offset_m=0.004,
        retake_c_d=False,
    )
    plan = msgspec.structs.replace(plan, procedure=proc)
    T_nom = nominal_T_base_wobj(plan)
    T_true = T_nom @ full_misplacement(plan, np.random.default_rng(5))
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    world = ideal_part(plan, T_true)
    run = execute(job.program("krl"), T_nom, probe_of(world))
    T_wobj_base = np.linalg.inv(T_true)
    sd = plan.validation.sensor.sensing_distance_m

    def sensor(tcp: np.ndarray, axis: np.ndarray) -> bool:
        """On within the sensing distance of the side face, in front of the part."""
        x = T_wobj_base[:3, :3] @ tcp + T_wobj_base[:3, 3]
        return bool(0.0 <= x[0] <= sd and x[2] <= 0.0)

    m = KrlMachine(export_files(job, "krl"), world, sensor=sensor).run()
    assert m.value("nResult") == 1 and len(m.ints()) == 8
    edges = [c for c in m.search_calls if c.neg_flank]
    assert len(edges) == 2 and len(m.search_calls) == 8 + 42  # no approach to F's, H's face
    slots, got = slot_of(job), m.measured_m()
    for key, q in run.measured_m.items():
        assert np.abs(got[slots[key]] - np.asarray(q)).max() < 1e-9, key
    # F starts at E (base) moved 4 mm out along the face normal, in the frame of the moment
    e = got[slots["E"]]
    n_base = base_m(m)[:3, 0]  # (the frame turns after F: compare along the face normal)
    assert abs(float((edges[0].start_m - e) @ n_base) - 0.004) < 1e-4
    assert_same_frame(base_m(m), run.T_base_wobj, 1e-9, 1e-9)
    assert_same_frame(base_m(m), T_true, 1e-9, 1e-9)  # F, H back on the face: the true part


# ------------------------------------------------------------------ failures
#: ``{k: (failing slot, searches run)}`` on the stator's A-H program, whose searches are A, B,
#: C, D, E, F (face, edge), G, H (face, edge), C and D retaken (slots 9, 10).
AH_FAILURES = {1: (1, 1), 3: (3, 3), 6: (6, 6), 7: (6, 7), 10: (8, 10), 11: (9, 11), 12: (10, 12)}


@pytest.mark.parametrize("k", sorted(AH_FAILURES))
def test_a_failed_search_stops_the_a_h_program_keeping_what_was_measured(k: int) -> None:
    plan = load_plan(STATOR)
    T_nom = nominal_T_base_wobj(plan)
    T_true = T_nom @ full_misplacement(plan, np.random.default_rng(3))
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    files = export_files(job, "krl")
    world = ideal_part(plan, T_true)
    full = KrlMachine(files, world).run()
    m = KrlMachine(files, failing_at(world, k)).run()
    slot, n_searches = AH_FAILURES[k]
    assert m.finished and (m.value("nResult"), m.value("nStopAt")) == (2, slot)
    assert len(m.search_calls) == n_searches  # nothing searched after it
    codes = m.ints()
    assert codes == {i: 0 if i < slot else 1 if i == slot else 3 for i in range(1, 11)}
    kept = m.measured_m()
    assert set(kept) == set(range(1, slot))
    for i, x in kept.items():  # what was measured, as the full run measured it
        assert np.abs(x - full.measured_m()[i]).max() < 1e-12
    # the robot went back to the failed point's safe start, in the frame of the moment
    retreat = m.motions[-1]
    target = next(t for t in job.targets if t.point_id == measured_slots(job)[slot - 1][0])
    assert retreat.kind == "LIN" and retreat.where.text.strip() == f"LIN x{target.point_id}_safe"
    safe = retreat.base_m @ written(target.safe_start)
    assert retreat.end_m is not None and np.abs(retreat.end_m - safe).max() < 1e-9


@pytest.mark.reference
@pytest.mark.parametrize("k", [1, 3, 4, 6])
def test_a_failed_search_stops_the_steered_program(k: int) -> None:
    """The 3-2-1 plate: P1 P2 P3 | S1 S2 | T1; the k-th fails: no update after it, the frame
    the estimate of the updates before (:func:`planner.program.steering.steer` of the points
    kept; nominal before the first)."""
    plan = load_plan(PLATE_321)
    T_nom = nominal_T_base_wobj(plan)
    T_true = T_nom @ full_misplacement(plan, np.random.default_rng(4))
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    world = ideal_part(plan, T_true)
    m = KrlMachine(export_files(job, "krl"), failing_at(world, k)).run()
    assert (m.value("nResult"), m.value("nStopAt")) == (2, k)
    assert len(m.search_calls) == k
    assert m.ints() == {i: 0 if i < k else 1 if i == k else 3 for i in range(1, 7)}
    assert set(m.measured_m()) == set(range(1, k))
    program = job.program("krl")
    by_id = {rp.point.id: rp.point for rp in program.points}
    kept = {
        t.point_id: x
        for i, t in enumerate(job.targets, 1)
        if (x := m.measured_m().get(i)) is not None
    }
    T = written(T_nom)
    assert program.pivot_m is not None
    for u in program.updates:
        if set(u.uses) <= set(kept):
            T = steer(
                [by_id[i] for i in u.uses], kept, T, np.asarray(program.pivot_m), program.scale_m
            )
    assert_same_frame(base_m(m), T, 1e-9, 1e-9)
    if k == 4:  # the primary points fixed the plane: the true one
        assert np.abs(base_m(m)[:3, 2] - T_true[:3, 2]).max() < 1e-9


def test_an_input_already_on_at_a_safe_start_stops_the_program() -> None:
    """``nFail = 2`` at B (a part left at its safe start): the program stops there."""
    plan = load_plan(STATOR)
    T_nom = nominal_T_base_wobj(plan)
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    safe_b = (written(T_nom) @ written(job.targets[1].safe_start))[:3, 3]
    m = KrlMachine(
        export_files(job, "krl"),
        ideal_part(plan, T_nom),
        sensor=lambda tcp, axis: bool(np.linalg.norm(tcp - safe_b) < 1e-6),
    ).run()
    assert (m.value("nResult"), m.value("nStopAt")) == (2, 2)
    assert m.ints() == {1: 0, 2: 2, **dict.fromkeys(range(3, 11), 3)}
    assert len(m.search_calls) == 1  # A only


def test_a_failed_x_offset_search_stops_the_run_with_the_frame_calibrated() -> None:
    plan = load_plan(STATOR)
    T_nom = nominal_T_base_wobj(plan)
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    world = ideal_part(plan, T_nom)
    full = KrlMachine(export_files(job, "krl"), world).run()
    m = KrlMachine(export_files(job, "krl"), failing_at(world, 12 + 23)).run()  # level 2, tooth 2
    assert (m.value("nResult"), m.value("nStopAt")) == (4, 23)
    assert len(m.search_calls) == 12 + 23
    assert set(m.ints().values()) == {0}
    assert_same_frame(base_m(m), base_m(full), 1e-12, 1e-12)


def test_slot_target_is_the_papers_target_function() -> None:
    """``SLOT_TARGET(slot, layer, standoff)`` after a run: the hole's y and z, the matrix's x
    plus the standoff, in ``BASE_DATA[10]``: :func:`calib.paper.xoffset.slot_target`."""
    plan = load_plan(STATOR)
    T_nom = nominal_T_base_wobj(plan)
    T_true = T_nom @ full_misplacement(plan, np.random.default_rng(8))
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    m = KrlMachine(export_files(job, "krl"), ideal_part(plan, T_true)).run()
    assert m.value("nResult") == 1
    grid = plan.procedure.xoffset.grid  # type: ignore[union-attr]
    mx = np.array(_rows(m, "fMxW"), dtype=float) / 1e3
    target = m.call("SLOT_TARGET", 40, 6, 5.0)
    want = slot_target(base_m(m), grid, 40, 6, standoff_m=0.005, xoffset=mx)
    got = base_m(m) @ m.frame_m(target)
    np.testing.assert_allclose(got[:3, 3], want[:3, 3], atol=1e-12)
