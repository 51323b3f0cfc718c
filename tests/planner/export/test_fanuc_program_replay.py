"""The exported FANUC TP program, run in the TP interpreter (:mod:`tests.fanuc_interp`) against
the simulated part and sensor of one validate trial of the TP program, runs the trial's searches
and records its points, and the procedure's frame of those points is the trial's.

FANUC runs every procedure in the nominal frame (``measuring_program(plan, "fanuc")``: the TP
writer computes no frame update, as the program's header says); ``wobjcal calibrate`` computes
the frame from the points the program leaves in ``PR[11]...`` (user frame, mm), converted to
the robot base with the ``PR[1]`` values the program writes. One validate trial executes that
measuring program (``planner.program.execute``) with the simulated sensor on the misplaced real
mesh, its noise drawn search by search from the trial's seed; here the same sensor, with the
same seed, answers each skip motion of the ``.ls`` (the trial pattern of
:mod:`tests.planner.validate.test_program_trial_replay`). When the program commands the same
searches in the same
order the noise draws line up and every recorded point matches.

Precision: the program writes positions and constants to 6 decimals of mm and deg (1e-9 m,
about 2e-8 rad), so a search's start and end, and an approach's point, agree to 1e-7 m (on
these assets to better than 1e-9 m). An edge search's point agrees to the simulator's bisection
of the edge event (``edge_tolerance_m``): its coarse scan takes ``ceil(length / scan_step)``
steps, and the stator's edge runs (142.5 mm: 57 steps of 2.5 mm) get 57 or 58 as the last bit
of the length decides, so the program's search (its end computed from written values) and the
trial's bisect different brackets of the same event (about 9 um apart here). The frame of an A-H
layout, whose F and H are edge points, is held to 1e-6 m plus how far the procedure's estimate
moves when each edge point moves by that tolerance along its search.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any

import numpy as np
import pytest

from calib.plan.file import Plan, load_plan
from calib.probing import ProbeResult, SearchCommand
from calib.procedures import ProcedureRun, procedure_kind
from planner.export import export_files
from planner.export.job import ExportJob, ToolData, build_job
from planner.program import execute
from tests.fanuc_interp import AT_START, TPError, TPMachine
from tests.planner.export.test_export_fanuc import with_arms
from tests.planner.export.test_urscript_adaptive_replay import angle_rad
from tests.planner.validate.test_program_trial_replay import PLANS, TOL_M, _search_callback, _trial
from tests.reference_data import plate_case

CASES = [
    plate_case("plate_holes_best_fit.json", 1),
    plate_case("plate_holes_321.json", 2),
    ("stator_section_ah.json", 3),
]
#: Agreement of the frame of the recorded points with the trial's: m, rad.
FRAME_TOL_M, FRAME_TOL_RAD = 1e-6, 1e-8


class Recorded:
    """A probe (``SearchCommand -> ProbeResult``) that keeps every command it ran and its
    result."""

    def __init__(self, probe: Any) -> None:
        self.probe = probe
        self.commands: list[SearchCommand] = []
        self.results: list[ProbeResult] = []

    def __call__(self, cmd: SearchCommand) -> ProbeResult:
        result: ProbeResult = self.probe(cmd)
        self.commands.append(cmd)
        self.results.append(result)
        return result


def tp_text(job: ExportJob) -> tuple[ExportJob, str]:
    """``job`` with a configuration at every target (the interpreter moves the TCP, not the
    joints: any ``CONFIG`` will do) and its ``.ls`` text."""
    job = with_arms(job)
    return job, export_files(job, "fanuc")[".ls"]


def comments(text: str) -> str:
    """The ``!`` comment lines of a TP program's ``/MN`` as one text (their wrapping undone)."""
    rows = re.findall(r"^ *\d+:  !(.*) ;$", text, re.M)
    return " ".join(" ".join(rows).split())


def assert_same_searches(tp: TPMachine, trial: Recorded, edge_tolerance_m: float) -> None:
    """Every skip motion of ``tp`` asked the sensor, and they are the ``trial``'s searches, in
    order: the same kind, start and end (:data:`TOL_M`) and sensor axis, and the same answer
    (an edge search's to ``edge_tolerance_m``)."""
    assert len(tp.searches) == len(trial.commands)
    for s, cmd, res in zip(tp.searches, trial.commands, trial.results, strict=True):
        assert s["answer"] is not None, cmd.point_id  # the input was never already at the level
        assert s["on"] == (cmd.kind == "approach"), cmd.point_id
        end = cmd.start_m + cmd.length_m * cmd.direction
        assert np.abs(s["start"] - cmd.start_m).max() < TOL_M, cmd.point_id
        assert np.abs(s["end"] - end).max() < TOL_M, cmd.point_id
        assert np.abs(s["axis"] - cmd.sensor_axis).max() < 1e-7, cmd.point_id
        assert res.point_m is not None and not isinstance(s["answer"], str), cmd.point_id
        tol = TOL_M if cmd.kind == "approach" else edge_tolerance_m
        assert np.abs(s["answer"] - res.point_m).max() < tol, cmd.point_id


def assert_replays_trial(
    plan: Plan, setup: Any, job: ExportJob, got: np.ndarray, run: ProcedureRun
) -> None:
    """A nominal program's recorded points (``got``: ``(n, 3)`` in ``job.targets`` order, robot
    base, m) are those of the trial ``run`` (every point measured once: an approach to
    :data:`TOL_M`, an edge search to ``edge_tolerance_m``), and the procedure's estimate of them
    is the trial's frame (module docstring)."""
    T_nom = setup.T_base_wobj_nominal
    ids = [t.point_id for t in job.targets]
    assert [s.key for s in setup.program.searches if s.recorded] == ids  # each once, in order
    edges = {p.id for p in plan.points if p.search.kind == "edge"}
    table: dict[str, np.ndarray] = {}
    for k, pid in enumerate(ids):
        want = np.asarray(run.measured_m[pid], dtype=float).reshape(-1, 3)[0]
        tol = setup.edge_tolerance_m if pid in edges else TOL_M
        assert np.abs(got[k] - want).max() < tol, (pid, got[k], want)
        table[pid] = got[k][None]
    kind = procedure_kind(setup.program.method)
    T = kind.estimate(list(setup.points), table, T_nom, setup.settings).T_base_wobj
    tol_m, tol_rad = edge_slack(plan, setup, table, edges, T)
    assert np.abs(T[:3, 3] - run.T_base_wobj[:3, 3]).max() < FRAME_TOL_M + tol_m
    assert angle_rad(T, run.T_base_wobj) < FRAME_TOL_RAD + tol_rad


def edge_slack(
    plan: Plan, setup: Any, table: Mapping[str, np.ndarray], edges: set[str], T: np.ndarray
) -> tuple[float, float]:
    """``(m, rad)``: the sum over the edge points of how far the procedure's estimate ``T`` of
    ``table`` moves when that point moves by ``edge_tolerance_m`` along its (nominal) search:
    a bound on what the simulator's bisection of the edge events passes on to the frame."""
    T_nom = setup.T_base_wobj_nominal
    kind = procedure_kind(setup.program.method)
    by_id = {p.id: p for p in plan.points}
    slack_m = slack_rad = 0.0
    for pid in sorted(edges):
        d = SearchCommand.from_point(by_id[pid].to_probe_point(), T_nom).direction
        moved = {**table, pid: table[pid] + setup.edge_tolerance_m * d}
        T_moved = kind.estimate(list(setup.points), moved, T_nom, setup.settings).T_base_wobj
        slack_m += float(np.abs(T_moved[:3, 3] - T[:3, 3]).max())
        slack_rad += angle_rad(T_moved, T)
    return slack_m, slack_rad


@pytest.mark.parametrize(("name", "seed"), CASES)
def test_the_tp_program_replays_a_validate_trial(name: str, seed: int) -> None:
    plan, setup, probe, _T_true = _trial(PLANS / name, "fanuc", seed)
    program = setup.program
    assert program.controller.name == "fanuc" and not program.adaptive, program.name
    T_nom = setup.T_base_wobj_nominal
    trial = Recorded(probe())
    run = execute(program, T_nom, trial)
    job, text = tp_text(build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4))))
    assert job.program("fanuc").steps == program.steps  # the exported program is the trial's
    assert f"PROGRAM: {program.name}. NOMINAL FRAME:" in comments(text)
    tp = TPMachine(text, _search_callback(probe())).run()
    n = len(job.targets)
    assert tp.codes(n) == [0] * n
    assert len(tp.joint_moves_deg) == sum(len(p.via_points) for p in plan.points)
    assert_same_searches(tp, trial, setup.edge_tolerance_m)
    assert_replays_trial(plan, setup, job, tp.recorded_base_m(n), run)


@pytest.mark.reference
def test_the_interpreter_runs_skip_motions_as_the_controller() -> None:
    """The oracle's own semantics: a skip motion whose input switches on the way stops there
    and records it; one that sees no change reaches its target and jumps to its label (code 1;
    the next point still runs: the program is nominal); one whose input was already at the
    condition's level as it began fires at once (no motion: the start is recorded, code 0, as on
    the controller); an answer off the commanded line is refused."""
    plan = load_plan(PLANS / "plate_holes_321.json")
    job, text = tp_text(build_job(plan, np.eye(4), ToolData(T_flange_tcp=np.eye(4))))
    answers = {2: "ERR_WHLSEARCH", 3: AT_START}
    asked: list[tuple[np.ndarray, np.ndarray]] = []

    def search(start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg_flank: bool) -> Any:
        asked.append((start, end))
        assert not neg_flank  # every point of the plan is an approach
        return answers.get(len(asked), start + 0.25 * (end - start))

    tp = TPMachine(text, search).run()
    n = len(job.targets)
    assert tp.codes(n) == [0, 1, 0, 0, 0, 0]
    assert [s["found"] for s in tp.searches] == [True, False, True, True, True, True]
    got = tp.recorded_base_m(n)
    (s1, e1), _, (s3, _) = asked[:3]
    assert np.abs(got[0] - (s1 + 0.25 * (e1 - s1))).max() < 1e-12
    assert np.isnan(got[1]).all()
    assert np.abs(got[2] - s3).max() < 1e-12
    safe3 = job.T_base_wobj @ job.targets[2].safe_start
    assert np.abs(s3 - safe3[:3, 3]).max() < 1e-9  # after the failed point: its own safe start
    with pytest.raises(TPError, match="off the commanded line"):
        TPMachine(text, lambda s, e, a, f: s + 0.25 * (e - s) + [0.0, 0.0, 1e-8]).run()
