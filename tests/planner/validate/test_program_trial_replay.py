"""The exported text of a program, run in an interpreter of its language against the simulated
part and sensor of one validate trial, measures what that trial measured and gives its frame.

One validate trial executes the measuring program (``planner.program.execute``) with the
simulated sensor on the misplaced real mesh, its noise drawn search by search from the trial's
seed. Here the same sensor, with the same seed, answers the searches the RAPID module and the
KRL program ask for in their interpreters: when the programs command the same searches in the
same order, the noise draws line up and every recorded point matches. The programs write their
targets in millimetres to 4 decimals (RAPID) or 6 (KRL), so an approach's point agrees to the
written precision (1e-4 mm), an edge search's to the simulator's bisection of the edge event
(0.02 mm, ``edge_tolerance_m``), not to the float (RAPID ``num`` is single precision on a real
controller anyway).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from calib.plan.file import load_plan
from calib.probing import SearchCommand
from calib.procedures import procedure_kind
from planner.export import export_files
from planner.export.job import ToolData, build_job
from planner.program import execute
from planner.sim.trial import TrialRunner
from planner.validate.job import check_simulatable, simulation_setup, work_object_mesh
from tests.krl_interp import KrlMachine
from tests.rapid_interp import Machine, _vec
from tests.reference_data import plate_case

PLANS = Path(__file__).resolve().parents[3] / "assets" / "plans"
#: Agreement of a recorded point, metres: the programs' written decimals (0.0001 mm).
TOL_M = 1e-7
#: Agreement of an A-H frame, metres and radians: F and H agree to the simulator's bisection of
#: the edge event (``edge_tolerance_m``, 0.02 mm) and pass it on to the origin and rotation
#: (over seeds 3, 7, 11: at most 0.009 mm and 1.7e-5 rad); a 0.1 mm error fails it.
A_H_TOL_M, A_H_TOL_RAD = 5e-5, 1e-4


def _trial(
    path: Path, fmt: str, seed: int, edge_tolerance_m: float | None = None
) -> tuple[Any, Any, Any, np.ndarray]:
    """The plan, the trial's setup, a maker of its simulated probe, and the true pose.

    ``edge_tolerance_m`` bisects the edge events finer than the setup's (``None``: its own)."""
    plan = load_plan(path)
    models = check_simulatable(plan)
    mesh = work_object_mesh(plan, PLANS, models)
    setup = simulation_setup(plan, models, mesh, fmt)
    runner = TrialRunner(setup, mesh)
    T_nom = setup.T_base_wobj_nominal
    T_true = T_nom @ setup.misplacement.sample(np.random.default_rng(seed), setup.pivot_wobj_m)

    def probe() -> Any:  # the same noise, search by search, every time
        return runner.simulator(
            runner.caster,
            T_true,
            np.random.default_rng(1000 + seed),
            sensor=setup.sensor,
            robot_error=setup.robot_error,
            faces=setup.faces,
            edge_inset_m=setup.edge_inset_m,
            edge_tolerance_m=edge_tolerance_m or setup.edge_tolerance_m,
        )

    return plan, setup, probe, T_true


def _search_callback(probe: Any) -> Any:
    """An interpreter's search callback answered by the simulated sensor."""

    def search(start, end, axis, neg_flank):  # type: ignore[no-untyped-def]
        length = float(np.linalg.norm(end - start))
        cmd = SearchCommand(
            point_id="",
            kind="edge" if neg_flank else "approach",
            start_m=np.asarray(start, float),
            direction=(end - start) / length,
            length_m=length,
            sensor_axis=np.asarray(axis, float),
            T_base_wobj_estimate=np.eye(4),
            nominal_m=np.asarray(start, float),
        )
        res = probe(cmd)
        if res.point_m is None:
            return "ERR_SIGSUPSEARCH" if "at start" in res.reason else "ERR_WHLSEARCH"
        return res.point_m

    return search


@pytest.mark.slow
@pytest.mark.parametrize(
    ("name", "seed"),
    [
        plate_case("plate_holes_best_fit.json", 1),
        plate_case("plate_holes_321.json", 2),
        ("stator_section_ah.json", 3),
    ],
)
def test_the_rapid_module_replays_a_validate_trial(name: str, seed: int) -> None:
    plan, setup, probe, _T_true = _trial(PLANS / name, "rapid", seed)
    T_nom = setup.T_base_wobj_nominal
    run = execute(setup.program, T_nom, probe())
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    m = Machine(export_files(job, "rapid")[".mod"], _search_callback(probe()))
    m.main()
    slot = {t.point_id: i for i, t in enumerate(job.targets)}
    last = {k.split("#")[0]: v for k, v in run.measured_m.items()}  # the retakes last
    for pid, q in last.items():
        if pid in slot:
            got = _vec(m.globals["measured"][slot[pid]]) / 1000.0
            if setup.program.method == "hultman2013" and pid in ("C", "D"):
                continue  # the A-H module keeps the retakes in slots of their own
            edge = next(p for p in plan.points if p.id == pid).search.kind == "edge"
            tol = setup.edge_tolerance_m if edge else TOL_M
            assert np.abs(got - q).max() < tol, (pid, got, q)
    T_prog = m.wobj_matrix_m("wobjCal")
    # the trial's frame, the module's: the same points (an A-H edge point to the simulator's
    # bisection, which F and H pass on to the origin and rotation) and one edge-event offset
    tol_m, tol_rad = (
        (1e-6, 1e-8) if setup.program.method != "hultman2013" else (A_H_TOL_M, A_H_TOL_RAD)
    )
    assert np.abs(T_prog[:3, 3] - run.T_base_wobj[:3, 3]).max() < tol_m
    dR = T_prog[:3, :3].T @ run.T_base_wobj[:3, :3]
    assert np.arccos(np.clip((np.trace(dR) - 1.0) / 2.0, -1.0, 1.0)) < tol_rad


@pytest.mark.reference
@pytest.mark.parametrize("name", ["plate_holes_best_fit.json", "plate_holes_321.json"])
def test_the_krl_program_replays_a_validate_trial(name: str) -> None:
    """The nominal KRL program, its searches answered by the simulated sensor of a trial of the
    KRL program: the same points, and the procedure's frame of them is the trial's."""
    plan, setup, probe, _T_true = _trial(PLANS / name, "krl", 4)
    T_nom = setup.T_base_wobj_nominal
    run = execute(setup.program, T_nom, probe())
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    m = KrlMachine(export_files(job, "krl"), _search_callback(probe())).run()
    got = m.measured_m("xMeas")
    for i, t in enumerate(job.targets, start=1):
        q = np.asarray(run.measured_m[t.point_id]).reshape(-1, 3)[0]
        assert np.abs(got[i] - q).max() < TOL_M, (t.point_id, got[i], q)
    kind = procedure_kind(setup.program.method)
    table = {t.point_id: got[i][None] for i, t in enumerate(job.targets, start=1)}
    ref = kind.estimate(list(setup.points), table, T_nom, setup.settings)
    assert np.abs(ref.T_base_wobj[:3, 3] - run.T_base_wobj[:3, 3]).max() < 1e-6
