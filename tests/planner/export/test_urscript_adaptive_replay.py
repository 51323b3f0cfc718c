"""The exported adaptive URScript program, run in the URScript interpreter against the simulated
part and sensor of one validate trial of the URScript program, measures what that trial
measured and ends with its frame in ``wobj``.

One validate trial executes the measuring program (``planner.program.execute``) with the
simulated sensor on the misplaced real mesh, its noise drawn search by search from the trial's
seed. Here the same sensor, with the same seed, answers the searches the URScript program runs
in :mod:`tests.urscript_interp` (each ``movel`` the program watches the input during is asked
about once, in order): when the program commands the same searches in the same order, in the
same frames, the noise draws line up and every recorded point matches. The program writes its
targets in metres to 9 decimals and its update constants to 12, so an approach's point agrees to
1e-7 m, an edge search's to the simulator's bisection of the edge event
(``edge_tolerance_m``). The trial pattern is
:mod:`tests.planner.validate.test_program_trial_replay`'s.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from calib.frames import rotvec_from_matrix
from planner.export import export_files
from planner.export.job import ExportJob, ToolData, build_job
from planner.export.urscript_layout import slot_table
from planner.program import execute
from tests.planner.validate.test_program_trial_replay import (
    A_H_TOL_M,
    A_H_TOL_RAD,
    PLANS,
    TOL_M,
    _search_callback,
    _trial,
)
from tests.reference_data import plate_case
from tests.urscript_interp import UrMachine

CASES = [
    plate_case("plate_holes_best_fit.json", 1),
    plate_case("plate_holes_321.json", 2),
    ("stator_section_ah.json", 3),
]


def angle_rad(T1: np.ndarray, T2: np.ndarray) -> float:
    """The angle between the rotations of two transforms, rad (accurate near 0, unlike the
    arccos of the trace)."""
    return float(np.linalg.norm(rotvec_from_matrix(T1[:3, :3].T @ T2[:3, :3])))


class Counted:
    """A probe (``SearchCommand -> ProbeResult``) that counts its calls."""

    def __init__(self, probe: Any) -> None:
        self.probe = probe
        self.n = 0

    def __call__(self, cmd: Any) -> Any:
        self.n += 1
        return self.probe(cmd)


def _key(pid: str, take: int) -> str:
    """The executed run's key of a point's ``take``-th measurement (``C#2``: a retake)."""
    return pid if take == 1 else f"{pid}#{take}"


def _measured(m: UrMachine, n_slots: int) -> tuple[np.ndarray, list[float]]:
    """``(n_slots, 3)`` the program's ``measured`` (base, m) and its ``measured_code``."""
    xyz = np.asarray(m.variables["measured"], dtype=float).reshape(n_slots, 3)
    return xyz, list(m.variables["measured_code"])


def _job(plan: Any, T_nom: np.ndarray) -> ExportJob:
    return build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))


@pytest.mark.slow
@pytest.mark.parametrize(("name", "seed"), CASES)
def test_the_urscript_program_replays_a_validate_trial(name: str, seed: int) -> None:
    plan, setup, probe, _T_true = _trial(PLANS / name, "urscript", seed)
    program = setup.program
    assert program.controller.name == "urscript" and program.adaptive, program.name
    T_nom = setup.T_base_wobj_nominal
    trial_probe = Counted(probe())
    run = execute(program, T_nom, trial_probe)
    job = _job(plan, T_nom)
    assert job.program("urscript").steps == program.steps  # the exported program is the trial's
    text = export_files(job, "urscript")[".script"]
    assert f"PROGRAM: {program.name}. ADAPTIVE:" in text.replace("\n  # ", " ")
    m = UrMachine(text, _search_callback(probe())).run()
    assert m.finished and not m.halted, m.messages[-3:]
    table = slot_table(job, program)
    got, codes = _measured(m, len(table))
    assert codes == [0.0] * len(table)
    edges = {p.id for p in plan.points if p.search.kind == "edge"}
    for k, (pid, take) in enumerate(table):
        want = np.asarray(run.measured_m[_key(pid, take)], dtype=float)
        tol = setup.edge_tolerance_m if pid in edges else TOL_M
        assert np.abs(got[k] - want).max() < tol, (pid, take, got[k], want)
    # the program's first searches are the trial's, in its order (A-H: its x-offset run after)
    assert len(m.searches) >= trial_probe.n
    if program.method != "hultman2013":
        assert len(m.searches) == trial_probe.n
    T_prog = m.frame("wobj")
    # the trial's frame, the program's: the same points (an A-H edge point to the simulator's
    # bisection, which F and H pass on to the origin and rotation) and one edge-event offset
    tol_m, tol_rad = (1e-6, 1e-8) if program.method != "hultman2013" else (A_H_TOL_M, A_H_TOL_RAD)
    assert np.abs(T_prog[:3, 3] - run.T_base_wobj[:3, 3]).max() < tol_m
    assert angle_rad(T_prog, run.T_base_wobj) < tol_rad
    assert np.abs(m.frame("wobj_nominal") - T_nom).max() < 1e-9


def failing(search: Any, which: int) -> Any:
    """``search`` whose call number ``which`` (1-based) finds nothing."""
    calls: list[int] = []

    def answer(start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg_flank: bool) -> Any:
        calls.append(1)
        return "ERR_WHLSEARCH" if len(calls) == which else search(start, end, axis, neg_flank)

    return answer


@pytest.mark.parametrize(
    ("name", "which", "failed"),
    [("stator_section_ah.json", 3, "C"), ("stator_section_ah.json", 7, "F"),
     plate_case("plate_holes_best_fit.json", 4, "T4")],
    ids=["ah-approach", "ah-edge-search", "best-fit"],
)  # fmt: skip
def test_a_failed_search_stops_the_program_with_what_was_measured(
    name: str, which: int, failed: str
) -> None:
    """The failed search's point gets its code, the points before it keep their values (the
    trial's), nothing is searched after it, the frame is left as estimated then."""
    plan, setup, probe, _T_true = _trial(PLANS / name, "urscript", 5)
    T_nom = setup.T_base_wobj_nominal
    run = execute(setup.program, T_nom, probe())
    job = _job(plan, T_nom)
    text = export_files(job, "urscript")[".script"]
    m = UrMachine(text, failing(_search_callback(probe()), which)).run()
    assert m.halted
    assert m.searches[-1].search is not None and m.searches[-1].search.answer == "ERR_WHLSEARCH"
    assert len(m.searches) == which  # stopped at once
    assert any(
        msg.startswith(f"wobjcal/1 stop {setup.program.method_label}: point {failed}: code")
        for msg in m.messages
    ), m.messages
    table = slot_table(job, setup.program)
    got, codes = _measured(m, len(table))
    order = [(s.point_id, s.key) for s in setup.program.searches if s.recorded]
    done = [pid for pid, key in order[: [k for _, k in order].index(failed)]]
    edges = {p.id for p in plan.points if p.search.kind == "edge"}
    for k, (pid, take) in enumerate(table):
        if take == 1 and pid in done:
            tol = setup.edge_tolerance_m if pid in edges else TOL_M
            assert codes[k] == 0.0
            assert np.abs(got[k] - run.measured_m[pid]).max() < tol, pid
        elif take == 1 and pid == failed:
            assert codes[k] == 1.0
        else:
            assert codes[k] == -1.0, pid
    assert m.variables[f"meas_{failed}"][0] == 1.0
    assert "done" not in " ".join(m.messages)
