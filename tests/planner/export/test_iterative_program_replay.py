"""The iterative best fit (``calib.procedures.Iterative``), exported for every controller and run
in that language's interpreter against the simulated sensor of one validate trial of the
controller's program, measures what the trial measured, and its frame is the trial's.

No controller re-runs the procedure's rounds: every controller's program is nominal (each
search once, in plan order, in the nominal work object) and ``wobjcal calibrate`` computes the
frame, the procedure's :meth:`~calib.procedures.base.ProcedureKind.estimate` of the recorded
points (the fit of each point's last measurement). The trial (``planner.program.execute``) runs
that program with the simulated sensor, its noise drawn search by search from the trial's seed;
the same sensor, with the same seed, answers the searches of the exported text
(:mod:`tests.planner.validate.test_program_trial_replay`'s pattern). The plan is the plate best-fit
plan with its
procedure switched to ``Iterative()`` (a best-fit plan runs it unchanged), written to a
temporary plan file (its mesh reference made absolute, the same mesh) for the trial to load.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import msgspec
import numpy as np
import pytest

from calib.plan.file import load_plan, save_plan
from calib.procedures import Iterative
from planner.export import export_files
from planner.export.job import ExportJob, ToolData, build_job
from planner.export.text import identifier
from planner.program import CONTROLLERS, execute
from tests.fanuc_interp import TPMachine
from tests.krl_interp import KrlMachine
from tests.planner.export.test_fanuc_program_replay import assert_replays_trial, tp_text
from tests.planner.export.test_urscript_adaptive_replay import Counted
from tests.planner.validate.test_program_trial_replay import PLANS, _search_callback, _trial
from tests.rapid_interp import Machine, _vec
from tests.urscript_interp import UrMachine

#: every test here runs a shipped plate plan, whose mesh is in ../shared/reference
pytestmark = pytest.mark.reference

PLATE_FIT = PLANS / "plate_holes_best_fit.json"
#: The trial's seed (misplacement and noise).
SEED = 6

#: Runs the program of a job in its interpreter with a search callback: ``(n, 3)`` the points
#: it recorded, robot base, m, in ``job.targets`` order (every result code checked: measured).
Runner = Callable[[ExportJob, Any], np.ndarray]


@pytest.fixture(scope="module")
def iterative_plan(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The plate best-fit plan running the iterative best fit, as a plan file."""
    plan = load_plan(PLATE_FIT)
    mesh = (PLATE_FIT.parent / plan.work_object.mesh).resolve()
    part = msgspec.structs.replace(plan.work_object, mesh=str(mesh))
    plan = msgspec.structs.replace(plan, procedure=Iterative(), work_object=part)
    return save_plan(plan, tmp_path_factory.mktemp("iterative") / PLATE_FIT.name)


def _rapid(job: ExportJob, search: Any) -> np.ndarray:
    m = Machine(export_files(job, "rapid")[".mod"], search)
    m.main()
    n = len(job.targets)
    assert [m.globals["measuredOk"][k] for k in range(n)] == [True] * n
    return np.array([_vec(m.globals["measured"][k]) / 1000.0 for k in range(n)])


def _krl(job: ExportJob, search: Any) -> np.ndarray:
    m = KrlMachine(export_files(job, "krl"), search).run()
    assert m.finished and m.halted is None
    n = len(job.targets)
    assert m.ints("nFail") == dict.fromkeys(range(1, n + 1), 0)
    got = m.measured_m("xMeas")
    return np.array([got[i] for i in range(1, n + 1)])


def _urscript(job: ExportJob, search: Any) -> np.ndarray:
    m = UrMachine(export_files(job, "urscript")[".script"], search).run()
    assert m.finished and not m.halted, m.messages[-3:]
    meas = [np.asarray(m.variables[identifier("meas_" + t.point_id)]) for t in job.targets]
    assert [float(v[0]) for v in meas] == [0.0] * len(meas)  # [code, x, y, z], code 0: measured
    return np.array([v[1:] for v in meas], dtype=float)


def _fanuc(job: ExportJob, search: Any) -> np.ndarray:
    job, text = tp_text(job)
    tp = TPMachine(text, search).run()
    n = len(job.targets)
    assert tp.codes(n) == [0] * n
    return tp.recorded_base_m(n)


def _counting(search: Any) -> tuple[Any, list[int]]:
    """``search`` (an interpreter's callback) and the list it appends 1 to at every call."""
    calls: list[int] = []

    def counted(start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg_flank: bool) -> Any:
        calls.append(1)
        return search(start, end, axis, neg_flank)

    return counted, calls


RUNNERS: dict[str, Runner] = {"rapid": _rapid, "krl": _krl, "urscript": _urscript, "fanuc": _fanuc}


@pytest.mark.parametrize("fmt", list(RUNNERS))
def test_the_iterative_program_replays_a_validate_trial(iterative_plan: Path, fmt: str) -> None:
    plan, setup, probe, _T_true = _trial(iterative_plan, fmt, SEED)
    program = setup.program
    assert program.method == "iterative"
    assert program.name == f"{CONTROLLERS[fmt].label}, nominal iterative best fit", program.name
    T_nom = setup.T_base_wobj_nominal
    trial = Counted(probe())
    run = execute(program, T_nom, trial)
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    assert job.program(fmt).steps == program.steps  # the exported program is the trial's
    search, calls = _counting(_search_callback(probe()))
    got = RUNNERS[fmt](job, search)
    assert len(calls) == trial.n == len(plan.points)  # one search per point, as the trial's
    assert_replays_trial(plan, setup, job, got, run)
